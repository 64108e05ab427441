#include "diffusion/diffusion_operator.hpp"

#include <Eigen/LU>
#include <cmath>

#include "core/parallel.hpp"

namespace cosph {

template <int D>
double anisotropic_pair_factor(const Mat<D>& diffusion_inverse, double inverse_sqrt_det,
                               const Vec<D>& e) {
  const double q = e.dot(diffusion_inverse * e);
  return inverse_sqrt_det * std::pow(q, -0.5 * (D + 2));
}

template <int D>
std::vector<double> diffusion_pair_weights(const std::vector<Vec<D>>& positions,
                                           const std::vector<double>& volumes,
                                           const NeighbourList& neighbours, const Kernel& kernel,
                                           const Domain<D>& domain,
                                           const std::vector<Mat<D>>& diffusion_tensor,
                                           const std::vector<Mat<D>>& B) {
  std::vector<double> weights(neighbours.pair_count());
  const bool corrected = !B.empty();
  parallel_for_each_index(positions.size(), [&](std::size_t i) {
    for (std::size_t k = neighbours.offset[i]; k < neighbours.offset[i + 1]; ++k) {
      const Index j = neighbours.index[k];
      const Vec<D> rij = domain.displacement(positions[i], positions[j]);
      const double r = rij.norm();
      const Vec<D> e = rij / r;
      const Mat<D> Dij = 0.5 * (diffusion_tensor[i] + diffusion_tensor[j]);
      const double g = anisotropic_pair_factor<D>(Dij.inverse(), 1.0 / std::sqrt(Dij.determinant()), e);
      const double correction = corrected ? 0.5 * e.dot((B[i] + B[j]) * e) : 1.0;
      weights[k] = 2.0 * volumes[j] * (-kernel.derivative(r) / r) * g * correction;
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

#define COSPH_INSTANTIATE(D)                                                                   \
  template double anisotropic_pair_factor<D>(const Mat<D>&, double, const Vec<D>&);          \
  template std::vector<double> diffusion_pair_weights<D>(                                     \
      const std::vector<Vec<D>>&, const std::vector<double>&, const NeighbourList&,           \
      const Kernel&, const Domain<D>&, const std::vector<Mat<D>>&, const std::vector<Mat<D>>&);
COSPH_INSTANTIATE(2)
COSPH_INSTANTIATE(3)

}  // namespace cosph
