#include "operators/diffusion_operator.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/parallel.hpp"

namespace cosph {

template <int D>
double anisotropic_pair_factor(const Mat<D>& diffusion_inverse, double inverse_sqrt_det,
                               const Vec<D>& e) {
  const double q = e.dot(diffusion_inverse * e);
  // q^(-(d+2)/2) without pow(): q^-2 in 2D, q^-2.5 in 3D.
  if constexpr (D == 2)
    return inverse_sqrt_det / (q * q);
  else
    return inverse_sqrt_det / (q * q * std::sqrt(q));
}

template <int D>
Mat<D> diffusion_second_moment(std::size_t i, const std::vector<Vec<D>>& positions,
                               const std::vector<double>& volumes, const NeighbourList& neighbours,
                               const Kernel& kernel, const Domain<D>& domain, const Mat<D>& A) {
  const Mat<D> A_inverse = A.inverse();
  const double inverse_sqrt_det = 1.0 / std::sqrt(A.determinant());
  Mat<D> S = Mat<D>::Zero();
  for (Index j : neighbours.of(i)) {
    const Vec<D> rij = domain.displacement(positions[i], positions[j]);
    const double r = rij.norm();
    const Vec<D> e = rij / r;
    const double g = anisotropic_pair_factor<D>(A_inverse, inverse_sqrt_det, e);
    S += volumes[j] * (-kernel.derivative(r) * r) * g * e * e.transpose();
  }
  return S;
}

template <int D>
std::vector<double> diffusion_pair_weights(const std::vector<Vec<D>>& positions,
                                           const std::vector<double>& volumes,
                                           const NeighbourList& neighbours, const Kernel& kernel,
                                           const Domain<D>& domain,
                                           const std::vector<Mat<D>>& diffusion_tensor,
                                           bool corrected) {
  const std::size_t n = positions.size();
  std::vector<Mat<D>> A = diffusion_tensor;
  if (corrected) {
    // Near a free boundary the moment is deficient along the normal (half of it on a face, more
    // at corners) and the calibration would inflate A without bound; there the missing pairs *are*
    // the zero-flux condition. So A is kept within a factor kMaxCorrection of D, in D's own
    // metric: interior particles are calibrated exactly, boundary ones partly.
    constexpr double kMaxCorrection = 1.5;
    parallel_for_each_index(n, [&](std::size_t i) {
      const Mat<D>& target = diffusion_tensor[i];
      const Eigen::SelfAdjointEigenSolver<Mat<D>> eigen(target);
      const Mat<D> root = eigen.operatorSqrt(), inverse_root = eigen.operatorInverseSqrt();
      const double scale = target.norm();
      Mat<D> a = target;
      for (int iteration = 0; iteration < 30; ++iteration) {
        const Mat<D> S =
            diffusion_second_moment<D>(i, positions, volumes, neighbours, kernel, domain, a);
        const Mat<D> residual = target - S;
        if (residual.norm() < 1e-10 * scale || !(S.trace() > 0.0)) break;
        a += (a.trace() / S.trace()) * residual;
        // Clamp the eigenvalues of D^-1/2 A D^-1/2 to [1/k, k].
        const Mat<D> m = inverse_root * (0.5 * (a + a.transpose())) * inverse_root;
        const Eigen::SelfAdjointEigenSolver<Mat<D>> em(m);
        const Vec<D> clamped =
            em.eigenvalues().cwiseMax(1.0 / kMaxCorrection).cwiseMin(kMaxCorrection);
        a = root * (em.eigenvectors() * clamped.asDiagonal() * em.eigenvectors().transpose()) *
            root;
      }
      A[i] = a;
    });
  }
  std::vector<double> weights(neighbours.pair_count());
  parallel_for_each_index(n, [&](std::size_t i) {
    for (std::size_t k = neighbours.offset[i]; k < neighbours.offset[i + 1]; ++k) {
      const Index j = neighbours.index[k];
      const Vec<D> rij = domain.displacement(positions[i], positions[j]);
      const double r = rij.norm();
      const Mat<D> Aij = 0.5 * (A[i] + A[j]);
      const double g =
          anisotropic_pair_factor<D>(Aij.inverse(), 1.0 / std::sqrt(Aij.determinant()), rij / r);
      weights[k] = 2.0 * volumes[j] * (-kernel.derivative(r) / r) * g;
    }
  });
  return weights;
}

void apply_diffusion(const NeighbourList& neighbours, const std::vector<double>& weights,
                     const std::vector<double>& c, std::vector<double>& rate) {
  rate.resize(c.size());
  parallel_for_each_index(c.size(), [&](std::size_t i) {
    double sum = 0.0;
    const double ci = c[i];
    for (std::size_t k = neighbours.offset[i]; k < neighbours.offset[i + 1]; ++k)
      sum += weights[k] * (c[neighbours.index[k]] - ci);
    rate[i] = sum;
  });
}

template <int D>
void ExplicitDiffusion<D>::setup(const std::vector<Vec<D>>& positions,
                                 const std::vector<double>& volumes,
                                 const NeighbourList& neighbours, const Kernel& kernel,
                                 const Domain<D>& domain,
                                 const std::vector<Mat<D>>& diffusion_tensor, bool corrected,
                                 double time_step_factor, Limit limit) {
  neighbours_ = &neighbours;
  weights_ = diffusion_pair_weights<D>(positions, volumes, neighbours, kernel, domain,
                                       diffusion_tensor, corrected);
  double max_trace = 0.0;
  for (const auto& t : diffusion_tensor) max_trace = std::max(max_trace, t.trace());
  const double h = kernel.smoothing_length();
  const double paper = time_step_factor * h * h / (D * max_trace);
  if (limit == Limit::Monotone) {
    double row_max = 0.0;
    for (std::size_t i = 0; i < positions.size(); ++i) {
      double row = 0.0;
      for (std::size_t k = neighbours.offset[i]; k < neighbours.offset[i + 1]; ++k)
        row += weights_[k];
      row_max = std::max(row_max, row);
    }
    stable_dt_ = row_max > 0.0 ? std::min(paper, 1.0 / row_max) : paper;
  } else {
    const double lambda = spectral_radius();
    stable_dt_ = lambda > 0.0 ? std::min(paper, 0.9 * 2.0 / lambda) : paper;
  }
}

template <int D>
double ExplicitDiffusion<D>::spectral_radius() const {
  // The operator is V^-1 S with S symmetric negative semi-definite (V_i w_ij = V_j w_ji), so its
  // eigenvalues are real and <= 0; power iteration from a fixed alternating start (rich in the
  // shortest modes, which carry the largest eigenvalues) converges to the largest magnitude.
  const std::size_t n = neighbours_->particle_count();
  if (n == 0) return 0.0;
  std::vector<double> v(n), w;
  for (std::size_t i = 0; i < n; ++i) v[i] = (i % 2 ? 1.0 : -1.0) * (1.0 + 0.01 * double(i % 7));
  double lambda = 0.0;
  for (int iteration = 0; iteration < 300; ++iteration) {
    apply_diffusion(*neighbours_, weights_, v, w);
    double norm_v = 0.0, norm_w = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      norm_v += v[i] * v[i];
      norm_w += w[i] * w[i];
    }
    if (norm_w == 0.0) return 0.0;
    lambda = std::sqrt(norm_w / norm_v);
    const double scale = 1.0 / std::sqrt(norm_w);
    for (std::size_t i = 0; i < n; ++i) v[i] = w[i] * scale;
  }
  return lambda;
}

template <int D>
const std::vector<double>& ExplicitDiffusion<D>::rate(const std::vector<double>& c) {
  apply_diffusion(*neighbours_, weights_, c, rate_);
  return rate_;
}

template <int D>
void ExplicitDiffusion<D>::step(std::vector<double>& c, double dt) {
  apply_diffusion(*neighbours_, weights_, c, rate_);
  parallel_for_each_index(c.size(), [&](std::size_t i) { c[i] += dt * rate_[i]; });
}

template class ExplicitDiffusion<2>;
template class ExplicitDiffusion<3>;

#define COSPH_INSTANTIATE(D)                                                                       \
  template double anisotropic_pair_factor<D>(const Mat<D>&, double, const Vec<D>&);                \
  template std::vector<double> diffusion_pair_weights<D>(                                          \
      const std::vector<Vec<D>>&, const std::vector<double>&, const NeighbourList&, const Kernel&, \
      const Domain<D>&, const std::vector<Mat<D>>&, bool);                                         \
  template Mat<D> diffusion_second_moment<D>(std::size_t, const std::vector<Vec<D>>&,              \
                                             const std::vector<double>&, const NeighbourList&,     \
                                             const Kernel&, const Domain<D>&, const Mat<D>&);
COSPH_INSTANTIATE(2)
COSPH_INSTANTIATE(3)

}  // namespace cosph
