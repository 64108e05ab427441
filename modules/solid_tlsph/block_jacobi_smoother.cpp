#include "solid_tlsph/block_jacobi_smoother.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>

namespace cosph {

namespace {

constexpr int kPowerIterations = 12;

// The inverses of K's diagonal blocks (read from its lower triangle).
std::vector<Eigen::MatrixXd> inverse_blocks(const Eigen::SparseMatrix<double>& K,
                                            const std::vector<Eigen::Index>& block_start) {
  std::vector<Eigen::MatrixXd> inverse(block_start.size() - 1);
  for (std::size_t b = 0; b + 1 < block_start.size(); ++b) {
    const Eigen::Index first = block_start[b], n = block_start[b + 1] - first;
    Eigen::MatrixXd B(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = 0; j <= i; ++j) B(i, j) = B(j, i) = K.coeff(first + i, first + j);
    const Eigen::LLT<Eigen::MatrixXd> llt(B);
    if (llt.info() == Eigen::Success) {
      inverse[b] = llt.solve(Eigen::MatrixXd::Identity(n, n));
    } else {
      const Eigen::VectorXd d = B.diagonal().cwiseAbs().cwiseMax(1e-300);
      inverse[b] = d.cwiseInverse().asDiagonal();
    }
  }
  return inverse;
}

void apply_blocks(const std::vector<Eigen::MatrixXd>& inverse,
                  const std::vector<Eigen::Index>& block_start, Eigen::VectorXd& v) {
  for (std::size_t b = 0; b < inverse.size(); ++b) {
    const Eigen::Index first = block_start[b], n = block_start[b + 1] - first;
    v.segment(first, n) = (inverse[b] * v.segment(first, n)).eval();
  }
}

// The largest eigenvalue of B^-1 K by power iteration from a fixed scrambled start (every mode
// present, the same on every run).
double largest_eigenvalue(const Eigen::SparseMatrix<double>& K,
                          const std::vector<Eigen::MatrixXd>& inverse,
                          const std::vector<Eigen::Index>& block_start) {
  Eigen::VectorXd v(K.rows());
  std::uint32_t state = 2463534242u;
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    state ^= state << 13, state ^= state >> 17, state ^= state << 5;  // xorshift32
    v[k] = double(state) / 4294967296.0 - 0.5;
  }
  double lambda = 0.0;
  for (int it = 0; it < kPowerIterations && v.norm() > 0.0; ++it) {
    v.normalize();
    Eigen::VectorXd w = K.selfadjointView<Eigen::Lower>() * v;
    apply_blocks(inverse, block_start, w);
    lambda = w.norm();
    v = w;
  }
  return lambda;
}

}  // namespace

SmoothingOutcome smooth_block_jacobi(Eigen::VectorXd& x, Eigen::VectorXd r, double scale,
                                     const NewtonSolver::Residual& residual,
                                     const Eigen::SparseMatrix<double>& K,
                                     const std::vector<Eigen::Index>& block_start, int sweeps) {
  SmoothingOutcome outcome;
  const auto relative = [](double norm, double s) { return s > 0.0 ? norm / s : norm; };
  double best_norm = r.norm();
  outcome.initial_residual = outcome.final_residual = relative(best_norm, scale);
  if (sweeps <= 0 || !std::isfinite(best_norm) || best_norm == 0.0) return outcome;
  const auto inverse = inverse_blocks(K, block_start);
  const double lambda = largest_eigenvalue(K, inverse, block_start);
  if (!(lambda > 0.0) || !std::isfinite(lambda)) return outcome;
  const double omega = 1.0 / lambda, initial_norm = best_norm;
  Eigen::VectorXd best = x;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    apply_blocks(inverse, block_start, r);
    x += omega * r;
    scale = residual(x, r);
    ++outcome.sweeps;
    const double norm = r.norm();
    if (!std::isfinite(norm) || norm > 10.0 * initial_norm) break;
    if (norm < best_norm) {
      best_norm = norm;
      best = x;
      outcome.final_residual = relative(norm, scale);
    }
  }
  x = best;
  return outcome;
}

}  // namespace cosph
