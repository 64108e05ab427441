#include "solid_tlsph/tlsph_operators.hpp"

#include "core/parallel.hpp"
#include "kernels/kernel_correction.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {

template <int D>
ReferencePairs<D> build_reference_pairs(const std::vector<Vec<D>>& X,
                                        const std::vector<double>& volume, const Kernel& kernel,
                                        bool hourglass) {
  ReferencePairs<D> pairs;
  const Domain<D> free_space;  // a solid body is never periodic
  pairs.neighbours = build_inner_list<D>(X, kernel.support_radius(), free_space);
  compute_correction_matrices<D>(X, volume, pairs.neighbours, kernel, free_space, pairs.correction);
  const auto& nl = pairs.neighbours;
  pairs.weighted_gradient.resize(nl.pair_count());
  pairs.gradient_sum.resize(X.size());
  if (hourglass) pairs.hourglass_weight.resize(nl.pair_count());
  parallel_for_each_index(X.size(), [&](std::size_t i) {
    Vec<D> sum = Vec<D>::Zero();
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
      const Index j = nl.index[k];
      const Vec<D> r = X[i] - X[j];
      const double distance = r.norm();
      const Vec<D> w = volume[j] * kernel.derivative(distance) / distance * r;
      pairs.weighted_gradient[k] = w;
      sum += w;
      if (hourglass)
        pairs.hourglass_weight[k] = volume[j] * kernel.value(distance) / (distance * distance);
    }
    pairs.gradient_sum[i] = sum;
  });
  return pairs;
}

template <int D>
void deformation_gradients(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& u,
                           std::vector<Mat<D>>& F) {
  const auto& nl = pairs.neighbours;
  parallel_for_each_index(u.size(), [&](std::size_t i) {
    Mat<D> G = Mat<D>::Zero();
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k)
      G.noalias() += (u[nl.index[k]] - u[i]) * pairs.weighted_gradient[k].transpose();
    F[i] = Mat<D>::Identity() + G * pairs.correction[i];
  });
}

template <int D>
Vec<D> artificial_viscosity(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& x,
                            const std::vector<Vec<D>>& v, const std::vector<double>& density,
                            const std::vector<Mat<D>>& G, const ViscosityParameters& p,
                            std::size_t i) {
  const auto& nl = pairs.neighbours;
  const double h = p.smoothing_length;
  Vec<D> sum = Vec<D>::Zero();
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
    const Index j = nl.index[k];
    const Vec<D> r = x[i] - x[j];
    const double phi = h * (v[i] - v[j]).dot(r) / (r.squaredNorm() + 0.01 * h * h);
    if (phi >= 0.0) continue;
    const double q =
        0.25 * (density[i] + density[j]) * (-p.alpha * p.sound_speed * phi + p.beta * phi * phi);
    sum.noalias() -= q * ((G[i] + G[j]) * pairs.weighted_gradient[k]);
  }
  return sum;
}

template <int D>
Vec<D> hourglass_force(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& X,
                       const std::vector<Vec<D>>& x, const std::vector<Mat<D>>& F, double stiffness,
                       std::size_t i) {
  const auto& nl = pairs.neighbours;
  Vec<D> sum = Vec<D>::Zero();
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
    const Index j = nl.index[k];
    const Vec<D> X_ij = X[j] - X[i];
    const Vec<D> x_ij = x[j] - x[i];
    const double length = x_ij.norm();
    if (!(length > 0.0)) continue;
    const Vec<D> e = x_ij / length;
    // eps from i: F_i X_ij - x_ij; from j (X_ji = -X_ij, x_ji = -x_ij): -(F_j X_ij - x_ij),
    // projected on x_ji = -x_ij: the same sign convention, so both add.
    const double delta = (F[i] * X_ij - x_ij).dot(e) + (F[j] * X_ij - x_ij).dot(e);
    sum.noalias() -= (0.5 * stiffness * pairs.hourglass_weight[k] * delta) * e;
  }
  return sum;
}

#define COSPH_INSTANTIATE_TLSPH(D)                                                                \
  template ReferencePairs<D> build_reference_pairs<D>(                                            \
      const std::vector<Vec<D>>&, const std::vector<double>&, const Kernel&, bool);               \
  template void deformation_gradients<D>(const ReferencePairs<D>&, const std::vector<Vec<D>>&,    \
                                         std::vector<Mat<D>>&);                                   \
  template Vec<D> artificial_viscosity<D>(const ReferencePairs<D>&, const std::vector<Vec<D>>&,   \
                                          const std::vector<Vec<D>>&, const std::vector<double>&, \
                                          const std::vector<Mat<D>>&, const ViscosityParameters&, \
                                          std::size_t);                                           \
  template Vec<D> hourglass_force<D>(const ReferencePairs<D>&, const std::vector<Vec<D>>&,        \
                                     const std::vector<Vec<D>>&, const std::vector<Mat<D>>&,      \
                                     double, std::size_t);
COSPH_INSTANTIATE_TLSPH(2)
COSPH_INSTANTIATE_TLSPH(3)

}  // namespace cosph
