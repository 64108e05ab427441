#include "solid_tlsph/newton_solver.hpp"

#include <dlfcn.h>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <cmath>

#include "core/scoped_seconds.hpp"

namespace cosph {

namespace {

constexpr int kLineSearchTrials = 4;

// OpenBLAS, under CHOLMOD's dense kernels, splits each product over its own threads (one per core
// by default, whatever --threads says), and the split changes the rounding: Land's beam tip moved
// by 8e-12 relative between one and two BLAS threads. A fixed count keeps the solution
// independent of the machine and of --threads; two halve the factorisation on a 2-core machine
// (OpenBLAS's partition of a product over a fixed number of threads is itself deterministic: no
// shared sums). The factorisation runs alone (the particle loops wait for it), so these threads do
// not compete with the pool's. Looked up at run time: the BLAS behind CHOLMOD may not be OpenBLAS.
constexpr int kBlasThreads = 2;

void fix_blas_threads() {
  static const bool done = [] {
    using SetThreads = void (*)(int);
    if (void* symbol = dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))
      reinterpret_cast<SetThreads>(symbol)(kBlasThreads);
    return true;
  }();
  (void)done;
}

double norm_or_infinity(const Eigen::VectorXd& r) {
  const double n = r.norm();
  return std::isfinite(n) ? n : INFINITY;
}

}  // namespace

// CHOLMOD's supernodal Cholesky factorises the fronts with dense BLAS kernels; it is analysed
// once, on first use. A tangent that is not positive definite (a body near a limit point, or a
// trial state far from equilibrium) is factorised with a diagonal shift K + mu I, mu growing from
// 1e-4 of the mean diagonal: the shifted solve still gives a descent direction for the energy,
// which the quasi-Newton pairs then correct toward the true tangent. (A simplicial LDL^T of the
// indefinite K, tried first, took 40 s where the Cholesky takes 1.1 s at 13,600 unknowns.)
struct NewtonSolver::Factorisation {
  using Matrix = Eigen::SparseMatrix<double>;
  static constexpr int kShiftTrials = 5;
  Eigen::CholmodSupernodalLLT<Matrix, Eigen::Lower> cholesky;
  bool analysed = false;

  Factorisation() { fix_blas_threads(); }

  // Returns the number of shifted attempts (0: K itself), or -1 when none factorised.
  int factorise(const Matrix& K) {
    if (!analysed) {
      cholesky.cholmod().print = 0;  // a failed attempt is handled here, not printed
      cholesky.analyzePattern(K);
      analysed = true;
    }
    cholesky.setShift(0.0);
    cholesky.factorize(K);
    if (cholesky.info() == Eigen::Success) return 0;
    const double mean_diagonal = K.diagonal().cwiseAbs().mean();
    double mu = 1e-4 * mean_diagonal;
    for (int attempt = 1; attempt <= kShiftTrials; ++attempt, mu *= 10.0) {
      cholesky.setShift(mu);
      cholesky.factorize(K);
      if (cholesky.info() == Eigen::Success) return attempt;
    }
    return -1;
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& r) const { return cholesky.solve(r); }
};

NewtonSolver::NewtonSolver() : factorisation_(std::make_unique<Factorisation>()) {}
NewtonSolver::~NewtonSolver() = default;
NewtonSolver::NewtonSolver(NewtonSolver&&) noexcept = default;
NewtonSolver& NewtonSolver::operator=(NewtonSolver&&) noexcept = default;

// The quasi-Newton direction H r of L-BFGS (two-loop recursion) whose initial inverse is the
// factorised tangent: the pairs (s, y) of the iterations since the last factorisation correct
// K0^-1 toward the current tangent, so that most iterations cost a residual and two triangular
// solves instead of an assembly and a factorisation (Matthies & Strang 1979).
Eigen::VectorXd NewtonSolver::direction(const Eigen::VectorXd& r) {
  Eigen::VectorXd q = r;
  std::vector<double> a(history_.size());
  for (std::size_t k = history_.size(); k-- > 0;) {
    a[k] = history_[k].rho * history_[k].s.dot(q);
    q -= a[k] * history_[k].y;
  }
  Eigen::VectorXd z;
  {
    const ScopedSeconds timer(triangular_solve_seconds_);
    z = factorisation_->solve(q);
  }
  for (std::size_t k = 0; k < history_.size(); ++k) {
    const double b = history_[k].rho * history_[k].y.dot(z);
    z += (a[k] - b) * history_[k].s;
  }
  return z;
}

// Line search on the slope s(alpha) = step . R(x + alpha step), the derivative of the energy
// along the step for a conservative load (s(0) = step . K step): a residual-norm merit rejects
// the good steps of a flexible body, whose rotations leave large axial residuals after a
// linearised step that the next iteration removes. A step that inverts a particle (non-finite R)
// is halved. On success x, r, norm and scale hold the accepted point.
bool NewtonSolver::line_search(const Eigen::VectorXd& step, const Residual& residual, Iterate& at,
                               NewtonOutcome& outcome) {
  const double s0 = step.dot(at.r);
  trial_.r.resize(at.r.size());
  double alpha = 1.0, previous_alpha = 0.0, previous_slope = s0;
  for (int trial_count = 0; trial_count < kLineSearchTrials; ++trial_count) {
    trial_.x = at.x + alpha * step;
    evaluate(residual, trial_, outcome);
    if (!std::isfinite(trial_.norm)) {
      alpha *= 0.5;
      continue;
    }
    const double slope = step.dot(trial_.r);
    const bool last = trial_count + 1 == kLineSearchTrials;
    if (!(s0 > 0.0) || std::abs(slope) <= 0.5 * std::abs(s0) || last) {
      std::swap(at, trial_);
      return true;
    }
    // Secant on the slope between the last two trials, kept within (0.1, 1) of the step.
    const double next = alpha - slope * (alpha - previous_alpha) / (slope - previous_slope);
    previous_alpha = alpha;
    previous_slope = slope;
    alpha = std::isfinite(next) ? std::clamp(next, 0.1, 1.0) : 0.5 * alpha;
  }
  return false;
}

// Fills r, scale and norm of the iterate at its x.
void NewtonSolver::evaluate(const Residual& residual, Iterate& at, NewtonOutcome& outcome) {
  {
    const ScopedSeconds timer(residual_seconds_);
    at.scale = residual(at.x, at.r);
  }
  ++outcome.residual_evaluations;
  at.norm = norm_or_infinity(at.r);
}

int NewtonSolver::factorise(const Eigen::SparseMatrix<double>& K) {
  int shifts;
  {
    const ScopedSeconds timer(factorisation_seconds_);
    shifts = factorisation_->factorise(K);
  }
  history_.clear();
  factorised_ = shifts >= 0;
  return shifts;
}

bool NewtonSolver::refresh_tangent(const Eigen::VectorXd& x, const Tangent& tangent,
                                   NewtonOutcome& outcome) {
  const int shifts = factorise(tangent(x));
  ++outcome.factorisations;
  if (shifts > 0) ++outcome.shifted_factorisations;
  return shifts >= 0;
}

bool NewtonSolver::adopt_tangent(const Eigen::SparseMatrix<double>& K) {
  kept_ = factorise(K) >= 0;
  return kept_;
}

NewtonOutcome NewtonSolver::solve(Eigen::VectorXd& x, const Residual& residual,
                                  const Tangent& tangent, const NewtonSettings& settings) {
  NewtonOutcome outcome;
  Iterate at;
  at.x = x;
  at.r.resize(x.size());
  evaluate(residual, at, outcome);
  auto converged = [&] { return at.norm == 0.0 || at.norm <= settings.tolerance * at.scale; };
  history_.clear();
  bool stale = !kept_;  // no factorisation to start from
  while (!converged() && std::isfinite(at.norm) && outcome.iterations < settings.max_iterations) {
    if (stale) {
      if (!refresh_tangent(at.x, tangent, outcome)) break;
      stale = false;
    }
    ++outcome.iterations;
    const Eigen::VectorXd step = direction(at.r);
    const Eigen::VectorXd previous_x = at.x, previous_r = at.r;
    const double previous_norm = at.norm;
    if (!line_search(step, residual, at, outcome)) {
      if (history_.empty()) break;  // a fresh tangent's step failed too
      stale = true;
      continue;
    }
    // y = -(R_new - R_old) ~ K s: a pair with positive curvature joins the history.
    HistoryPair pair{at.x - previous_x, previous_r - at.r, 0.0};
    const double sy = pair.s.dot(pair.y);
    if (sy > 1e-12 * pair.s.norm() * pair.y.norm()) {
      pair.rho = 1.0 / sy;
      history_.push_back(std::move(pair));
    }
    // A fresh tangent where the lagged one stops paying: the residual grew by more than the
    // settings' ratio, or the history is full.
    if (at.norm > settings.refresh_ratio * previous_norm ||
        static_cast<int>(history_.size()) >= settings.history)
      stale = true;
  }
  x = at.x;
  outcome.converged = converged();
  // A failed solve's factorisation may be of a state far from any equilibrium.
  kept_ = outcome.converged && factorised_;
  outcome.relative_residual = at.scale > 0.0 ? at.norm / at.scale : at.norm;
  return outcome;
}

}  // namespace cosph
