// Linear kernel-gradient correction (seed 001 eq. 35; seed 000 eqs. 16-17):
//   B_i = ( sum_j V_j (r_j - r_i) (x) grad_i W_ij )^-1,
// with grad_i W_ij = dW/dr (r_i - r_j)/|r_i - r_j|. The corrected gradient of a field phi,
//   grad phi_i = B_i^T sum_j V_j (phi_j - phi_i) grad_i W_ij,
// is exact for linear phi at every particle that has enough neighbours, boundaries included.
#pragma once

#include <vector>

#include "core/types.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/domain.hpp"
#include "neighbour/neighbour_list.hpp"

namespace cosph {

// Fills B (one matrix per particle). Throws RuntimeError naming the first particle (index and
// position) whose moment matrix is singular, e.g. an isolated particle or collinear neighbours.
template <int D>
void compute_correction_matrices(const std::vector<Vec<D>>& positions,
                                 const std::vector<double>& volumes,
                                 const NeighbourList& neighbours, const Kernel& kernel,
                                 const Domain<D>& domain, std::vector<Mat<D>>& B);

// Corrected gradient of a scalar field (for tests and diagnostics).
template <int D>
void corrected_gradient(const std::vector<Vec<D>>& positions, const std::vector<double>& volumes,
                        const NeighbourList& neighbours, const Kernel& kernel,
                        const Domain<D>& domain, const std::vector<Mat<D>>& B,
                        const std::vector<double>& phi, std::vector<Vec<D>>& gradient);

}  // namespace cosph
