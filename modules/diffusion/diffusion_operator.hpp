// The SPH diffusion operator on fixed particles, as precomputed pair weights:
//   (div(D grad c))_i  ~=  sum_j w_ij (c_j - c_i).
// Derivation (docs/ARCHITECTURE.md, "Diffusion operator"): Brookshaw's Laplacian
//   2 sum_j V_j (c_j - c_i) (-W'(r_ij)/r_ij)
// integrates the Taylor expansion of c against the second moment  int -r W'(r) e(x)e dV = I.
// For an anisotropic tensor D the pair is weighted by the angular factor
//   g(e) = det(D)^(-1/2) (e . D^-1 e)^(-(d+2)/2),
// which satisfies  d <g(e) e(x)e>_sphere = D  exactly (it is the angular part of a Gaussian with
// covariance D), so the continuum operator is D : grad grad c with strictly positive weights —
// unlike the Espanol-Revenga form, whose weights turn negative for strong anisotropy, and unlike
// the 1/(e . D^-1 e) weight of Tran-Duc et al., which is exact only along D's principal axes.
// Kernel correction (seed 001 section 4.2.1, seed 000 eqs. 16-17) multiplies each pair by
// e . (B_i + B_j)/2 e: on a deficient or perturbed neighbourhood the discrete second moment is
// B^-1 instead of I, and this factor restores it along the pair direction. The symmetric pair
// average keeps V_i w_ij = V_j w_ji, so the total amount sum_i V_i c_i is conserved exactly.
#pragma once

#include <vector>

#include "core/types.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/domain.hpp"
#include "neighbour/neighbour_list.hpp"

namespace cosph {

// Angular weight g(e) for the (pair-averaged) diffusion tensor; e is a unit vector.
template <int D>
double anisotropic_pair_factor(const Mat<D>& diffusion_inverse, double inverse_sqrt_det,
                               const Vec<D>& e);

// Pair weights aligned with `neighbours` (CSR). `B` may be empty (no kernel correction).
template <int D>
std::vector<double> diffusion_pair_weights(const std::vector<Vec<D>>& positions,
                                           const std::vector<double>& volumes,
                                           const NeighbourList& neighbours, const Kernel& kernel,
                                           const Domain<D>& domain,
                                           const std::vector<Mat<D>>& diffusion_tensor,
                                           const std::vector<Mat<D>>& B);

// rate_i = sum_j w_ij (c_j - c_i). Gather loop: each particle writes only its own rate.
void apply_diffusion(const NeighbourList& neighbours, const std::vector<double>& weights,
                     const std::vector<double>& c, std::vector<double>& rate);

}  // namespace cosph
