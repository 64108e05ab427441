#include "kernels/kernel_correction.hpp"

#include <Eigen/LU>
#include <sstream>

#include "core/error.hpp"
#include "core/parallel.hpp"

namespace cosph {

template <int D>
void compute_correction_matrices(const std::vector<Vec<D>>& positions,
                                 const std::vector<double>& volumes,
                                 const NeighbourList& neighbours, const Kernel& kernel,
                                 const Domain<D>& domain, std::vector<Mat<D>>& B) {
  const std::size_t n = positions.size();
  B.resize(n);
  // The moment matrix is the identity in the continuum; a determinant this small means the
  // neighbourhood spans fewer than D directions.
  constexpr double singular_threshold = 1e-8;
  std::vector<char> singular(n, 0);
  parallel_for_each_index(n, [&](std::size_t i) {
    Mat<D> moment = Mat<D>::Zero();
    for (Index j : neighbours.of(i)) {
      const Vec<D> rij = domain.displacement(positions[i], positions[j]);
      const double r = rij.norm();
      const Vec<D> grad = kernel.derivative(r) * rij / r;
      moment -= volumes[j] * rij * grad.transpose();  // (r_j - r_i) (x) grad_i W_ij
    }
    bool invertible = false;
    Mat<D> inverse;
    moment.computeInverseWithCheck(inverse, invertible, singular_threshold);
    if (invertible && std::abs(moment.determinant()) > singular_threshold)
      B[i] = inverse;
    else
      singular[i] = 1;
  });
  for (std::size_t i = 0; i < n; ++i)
    if (singular[i]) {
      std::ostringstream msg;
      msg << "kernel correction matrix is singular at particle " << i << " (position "
          << positions[i].transpose() << ", " << neighbours.of(i).size()
          << " neighbours): the particle is isolated or its neighbours do not span " << D
          << " dimensions";
      throw RuntimeError(msg.str());
    }
}

template <int D>
void corrected_gradient(const std::vector<Vec<D>>& positions, const std::vector<double>& volumes,
                        const NeighbourList& neighbours, const Kernel& kernel,
                        const Domain<D>& domain, const std::vector<Mat<D>>& B,
                        const std::vector<double>& phi, std::vector<Vec<D>>& gradient) {
  gradient.resize(positions.size());
  parallel_for_each_index(positions.size(), [&](std::size_t i) {
    Vec<D> g = Vec<D>::Zero();
    for (Index j : neighbours.of(i)) {
      const Vec<D> rij = domain.displacement(positions[i], positions[j]);
      const double r = rij.norm();
      g += volumes[j] * (phi[j] - phi[i]) * kernel.derivative(r) * rij / r;
    }
    gradient[i] = B[i].transpose() * g;
  });
}

#define COSPH_INSTANTIATE(D)                                                                       \
  template void compute_correction_matrices<D>(                                                    \
      const std::vector<Vec<D>>&, const std::vector<double>&, const NeighbourList&, const Kernel&, \
      const Domain<D>&, std::vector<Mat<D>>&);                                                     \
  template void corrected_gradient<D>(const std::vector<Vec<D>>&, const std::vector<double>&,      \
                                      const NeighbourList&, const Kernel&, const Domain<D>&,       \
                                      const std::vector<Mat<D>>&, const std::vector<double>&,      \
                                      std::vector<Vec<D>>&);
COSPH_INSTANTIATE(2)
COSPH_INSTANTIATE(3)

}  // namespace cosph
