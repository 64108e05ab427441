// The discrete operators of total-Lagrangian SPH (seed 001 eqs. 35-39, seed 000 eqs. 16-20), on
// pairs fixed in the reference configuration. Everything that does not change in a
// total-Lagrangian body (neighbours, weighted kernel gradients, correction matrices) is computed
// once; a step is then two gathers over the same pairs.
//
// Notation: X reference positions, u displacements, x = X + u. For particle i and neighbour j,
// w_ij = V_j grad_i W(|X_i - X_j|) (reference kernel gradient times the neighbour's volume) and
// B_i = (sum_j (X_j - X_i) (x) w_ij)^-1 (framework/kernels/kernel_correction.hpp).
//   Deformation gradient (seed 001 eq. 39 with the sign erratum):
//     F_i = I + (sum_j (u_j - u_i) w_ij^T) B_i,      exact for affine displacements.
//   Momentum (seed 001 eqs. 37-38):
//     rho0_i a_i = sum_j (P_i B_i^T + P_j B_j^T) w_ij.
// The pair force is antisymmetric, so linear momentum is conserved to round-off; and because
// particle i's term uses the very vectors B_i^T w_ij that built F_i, the total torque is
// -sum_i V_i eps : (F_i P_i^T), which vanishes for any objective law (F P^T = J sigma symmetric):
// angular momentum is conserved to round-off too (tests/unit/solid_tlsph_test).
#pragma once

#include <vector>

#include "core/types.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/neighbour_list.hpp"

namespace cosph {

template <int D>
struct ReferencePairs {
  NeighbourList neighbours;               // in the reference configuration, self excluded
  std::vector<Vec<D>> weighted_gradient;  // w_ij, one per pair
  std::vector<Vec<D>> gradient_sum;       // sum_j w_ij, one per particle
  std::vector<Mat<D>> correction;         // B_i
  // Only with hourglass control: V_j W_ij / |X_ij|^2 per pair.
  std::vector<double> hourglass_weight;
};

// Builds the pairs. Throws RuntimeError naming the particle whose correction matrix is singular.
template <int D>
ReferencePairs<D> build_reference_pairs(const std::vector<Vec<D>>& X,
                                        const std::vector<double>& volume, const Kernel& kernel,
                                        bool hourglass);

// F_i from the displacements.
template <int D>
void deformation_gradients(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& u,
                           std::vector<Mat<D>>& F);

// rho0_i a_i = sum_j (T_i + T_j) w_ij for per-particle "stress times correction" T = P B^T, i.e.
// the averaged-stress divergence; returns the force density (the caller divides by rho0).
template <int D>
Vec<D> pair_stress_divergence(const ReferencePairs<D>& pairs, const std::vector<Mat<D>>& T,
                              std::size_t i) {
  const auto nb = pairs.neighbours.of(i);
  const std::size_t start = pairs.neighbours.offset[i];
  Vec<D> sum = T[i] * pairs.gradient_sum[i];
  for (std::size_t k = 0; k < nb.size(); ++k)
    sum.noalias() += T[nb[k]] * pairs.weighted_gradient[start + k];
  return sum;
}

// Artificial viscosity of seed 000 (eqs. 19-20) in total-Lagrangian form: each pair's viscous
// pressure q_ij = rho_ij (-alpha c phi_ij + beta phi_ij^2) / 2 (phi_ij < 0: approaching pairs
// only) acts through the Piola transform J F^-T of both particles, like a pressure would:
//   rho0_i a_i += -sum_j q_ij (G_i + G_j) w_ij,   G = J F^-T B^T.
// Antisymmetric pair forces: linear momentum is conserved. Returns the force density.
struct ViscosityParameters {
  double alpha, beta, sound_speed, smoothing_length;
};
template <int D>
Vec<D> artificial_viscosity(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& x,
                            const std::vector<Vec<D>>& v, const std::vector<double>& density,
                            const std::vector<Mat<D>>& G, const ViscosityParameters& p,
                            std::size_t i);

// Ganzenmueller's (2015) hourglass control. With X_ij = X_j - X_i, x_ij = x_j - x_i, the error of
// the pair's separation predicted by F_i is eps_ij = F_i X_ij - x_ij and its projection along the
// pair delta_ij = eps_ij . x_ij / |x_ij|. The pair force is central and antisymmetric:
//   rho0_i a_i += -(coefficient E / 2) sum_j (V_j W_ij / |X_ij|^2) (delta_ij + delta_ji)
//   x_ij/|x_ij|
// (with delta_ji measured by F_j), so both momenta are conserved. Returns the force density.
template <int D>
Vec<D> hourglass_force(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& X,
                       const std::vector<Vec<D>>& x, const std::vector<Mat<D>>& F, double stiffness,
                       std::size_t i);

}  // namespace cosph
