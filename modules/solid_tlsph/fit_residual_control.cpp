#include "solid_tlsph/fit_residual_control.hpp"

#include <Eigen/Eigenvalues>

#include "core/error.hpp"
#include "core/parallel.hpp"

namespace cosph {

namespace {

// p(s) = (s, s_a s_b for a <= b), the quadratic part zero where the fit is linear.
template <int D>
typename FitResidualControl<D>::Basis basis(const Vec<D>& s, bool quadratic) {
  typename FitResidualControl<D>::Basis p = FitResidualControl<D>::Basis::Zero();
  int row = D;
  for (int a = 0; a < D; ++a) {
    p[a] = s[a];
    for (int b = a; b < D; ++b) p[row++] = quadratic ? s[a] * s[b] : 0.0;
  }
  return p;
}

}  // namespace

template <int D>
FitResidualControl<D>::FitResidualControl(const std::vector<Vec<D>>& X,
                                          const std::vector<double>& volume,
                                          const ReferencePairs<D>& pairs, const Kernel& kernel,
                                          double kappa_mu)
    : pairs_(pairs) {
  const NeighbourList& nl = pairs.neighbours;
  const std::size_t n = X.size(), count = nl.pair_count();
  const double h = kernel.smoothing_length();
  omega_.resize(count);
  p_.resize(count);
  y_.resize(count);
  residual_.assign(count, Vec<D>::Zero());
  p_sum_.assign(n, Basis::Zero());
  coefficient_.assign(n, 0.0);
  parallel_for_each_index(n, [&](std::size_t i) {
    const bool quadratic = !pairs.quadratic.empty() && pairs.quadratic[i];
    const int m = quadratic ? kBasis : D;
    Eigen::Matrix<double, kBasis, kBasis> M = Eigen::Matrix<double, kBasis, kBasis>::Zero();
    double spread = 0.0;
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
      const Index j = nl.index[k];
      const Vec<D> X_ij = X[j] - X[i];
      const double r = X_ij.norm();
      omega_[k] = -volume[j] * kernel.derivative(r) / r;
      p_[k] = basis<D>(X_ij / h, quadratic);
      M.noalias() += omega_[k] * p_[k] * p_[k].transpose();
      p_sum_[i] += omega_[k] * p_[k];
      spread += omega_[k] * X_ij.squaredNorm();
    }
    // The fit's own moment matrix (the correction already refused a singular one: this
    // particle then has the linear fit, whose D x D block is invertible).
    Eigen::Matrix<double, kBasis, kBasis> inverse = Eigen::Matrix<double, kBasis, kBasis>::Zero();
    const Eigen::MatrixXd block = M.topLeftCorner(m, m);
    inverse.topLeftCorner(m, m) = block.ldlt().solve(Eigen::MatrixXd::Identity(m, m));
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k)
      y_[k] = inverse * (omega_[k] * p_[k]);
    coefficient_[i] = spread > 0.0 ? 2.0 * kappa_mu * volume[i] / spread : 0.0;
  });
}

template <int D>
void FitResidualControl<D>::update_residuals(const std::vector<Vec<D>>& u) {
  const NeighbourList& nl = pairs_.neighbours;
  parallel_for_each_index(u.size(), [&](std::size_t i) {
    Eigen::Matrix<double, kBasis, D> a = Eigen::Matrix<double, kBasis, D>::Zero();
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k)
      a.noalias() += y_[k] * (u[nl.index[k]] - u[i]).transpose();
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k)
      residual_[k] = (u[nl.index[k]] - u[i]) - a.transpose() * p_[k];
  });
}

template <int D>
Vec<D> FitResidualControl<D>::force(std::size_t k) const {
  const NeighbourList& nl = pairs_.neighbours;
  Vec<D> f = Vec<D>::Zero();
  for (std::size_t q = nl.offset[k]; q < nl.offset[k + 1]; ++q) {
    const Index i = nl.index[q];
    const std::size_t back = pairs_.reverse_pair[q];  // pair (i, k)
    f += coefficient_[k] * omega_[q] * residual_[q] -
         coefficient_[i] * omega_[back] * residual_[back];
  }
  return f;
}

template <int D>
double FitResidualControl<D>::energy() const {
  const NeighbourList& nl = pairs_.neighbours;
  return deterministic_sum(nl.particle_count(), 0.0, [&](std::size_t i) {
    double sum = 0.0;
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k)
      sum += omega_[k] * residual_[k].squaredNorm();
    return 0.5 * coefficient_[i] * sum;
  });
}

template <int D>
double FitResidualControl<D>::column_sum(std::size_t i, std::size_t pair) const {
  return coefficient_[i] * (omega_[pair] - p_sum_[i].dot(y_[pair]));
}

template <int D>
double FitResidualControl<D>::stiffness(std::size_t i, std::size_t a, std::size_t b) const {
  const NeighbourList& nl = pairs_.neighbours;
  const std::size_t first = nl.offset[i];
  if (a == 0 && b == 0) {
    double sum = 0.0;
    for (std::size_t k = first; k < nl.offset[i + 1]; ++k) sum += column_sum(i, k);
    return sum;
  }
  if (a == 0) return -column_sum(i, first + b - 1);
  if (b == 0) return -column_sum(i, first + a - 1);
  const std::size_t ka = first + a - 1, kb = first + b - 1;
  return coefficient_[i] * ((a == b ? omega_[ka] : 0.0) - omega_[ka] * p_[ka].dot(y_[kb]));
}

template class FitResidualControl<2>;
template class FitResidualControl<3>;

}  // namespace cosph
