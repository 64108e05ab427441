#include "solid_tlsph/newton_solver.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>

namespace cosph {

namespace {

constexpr int kLineSearchTrials = 4;

double norm_or_infinity(const Eigen::VectorXd& r) {
  const double n = r.norm();
  return std::isfinite(n) ? n : INFINITY;
}

}  // namespace

// CHOLMOD's supernodal Cholesky factorises the fronts with dense BLAS kernels; the simplicial
// LDL^T takes over for a tangent that is not positive definite (a body near a limit point), and
// each is analysed once, on first use.
struct NewtonSolver::Factorisation {
  using Matrix = Eigen::SparseMatrix<double>;
  Eigen::CholmodSupernodalLLT<Matrix, Eigen::Lower> cholesky;
  Eigen::SimplicialLDLT<Matrix, Eigen::Lower> ldlt;
  bool cholesky_analysed = false, ldlt_analysed = false, use_ldlt = false;

  bool factorise(const Matrix& K) {
    if (!cholesky_analysed) {
      cholesky.analyzePattern(K);
      cholesky_analysed = true;
    }
    cholesky.factorize(K);
    use_ldlt = cholesky.info() != Eigen::Success;
    if (!use_ldlt) return true;
    if (!ldlt_analysed) {
      ldlt.analyzePattern(K);
      ldlt_analysed = true;
    }
    ldlt.factorize(K);
    return ldlt.info() == Eigen::Success;
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& r) const {
    return use_ldlt ? Eigen::VectorXd(ldlt.solve(r)) : Eigen::VectorXd(cholesky.solve(r));
  }
};

NewtonSolver::NewtonSolver() : factorisation_(std::make_unique<Factorisation>()) {}
NewtonSolver::~NewtonSolver() = default;
NewtonSolver::NewtonSolver(NewtonSolver&&) noexcept = default;
NewtonSolver& NewtonSolver::operator=(NewtonSolver&&) noexcept = default;

NewtonOutcome NewtonSolver::solve(Eigen::VectorXd& x, const Residual& residual,
                                  const Tangent& tangent, const NewtonSettings& settings) {
  NewtonOutcome outcome;
  Eigen::VectorXd r(x.size()), trial_r(x.size()), trial(x.size()), step(x.size());
  double scale = residual(x, r);
  ++outcome.residual_evaluations;
  double norm = norm_or_infinity(r);
  auto converged = [&] { return norm == 0.0 || norm <= settings.tolerance * scale; };
  while (!converged() && std::isfinite(norm) && outcome.iterations < settings.max_iterations) {
    const Eigen::SparseMatrix<double> K = tangent(x);
    const auto start = std::chrono::steady_clock::now();
    const bool factorised = factorisation_->factorise(K);
    factorisation_seconds_ +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    ++outcome.iterations;
    if (!factorised) break;
    step = factorisation_->solve(r);
    // Line search on the slope s(alpha) = step . R(x + alpha step), the derivative of the
    // energy along the step for a conservative load (s(0) = step . K step): a residual-norm
    // merit rejects the good steps of a flexible body, whose rotations leave large axial
    // residuals after a linearised step that the next iteration removes. A step that inverts a
    // particle (non-finite R) is halved.
    const double s0 = step.dot(r);
    double alpha = 1.0, previous_alpha = 0.0, previous_slope = s0;
    bool accepted = false;
    for (int trial_count = 0; trial_count < kLineSearchTrials; ++trial_count) {
      trial = x + alpha * step;
      const double trial_scale = residual(trial, trial_r);
      ++outcome.residual_evaluations;
      const double trial_norm = norm_or_infinity(trial_r);
      if (!std::isfinite(trial_norm)) {
        alpha *= 0.5;
        continue;
      }
      const double slope = step.dot(trial_r);
      const bool last = trial_count + 1 == kLineSearchTrials;
      if (!(s0 > 0.0) || std::abs(slope) <= 0.5 * std::abs(s0) || last) {
        x.swap(trial);
        r.swap(trial_r);
        norm = trial_norm;
        scale = trial_scale;
        accepted = true;
        break;
      }
      // Secant on the slope between the last two trials, kept within (0.1, 1) of the step.
      const double next = alpha - slope * (alpha - previous_alpha) / (slope - previous_slope);
      previous_alpha = alpha;
      previous_slope = slope;
      alpha = std::isfinite(next) ? std::clamp(next, 0.1, 1.0) : 0.5 * alpha;
    }
    if (!accepted) break;
  }
  outcome.converged = converged();
  outcome.relative_residual = scale > 0.0 ? norm / scale : norm;
  return outcome;
}

}  // namespace cosph
