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
// Kernel correction. On a finite particle set the discrete second moment of the pair weights,
//   S_i = 1/2 sum_j w_ij r_ij (x) r_ij,
// differs from D: by a few percent on a lattice (only a few pair directions sample g), and by up
// to half near free boundaries. Seed 001 corrects the first moment with the matrix B (eq. 35);
// here the same idea is applied to the moment the Laplacian needs: each particle gets the tensor
// A_i for which its weights, built with g_A instead of g_D, reproduce S_i = D_i exactly (a few
// fixed-point iterations A += (D - S(A)) tr A / tr S, once, at start-up; particles do not move).
// Near free boundaries the correction is bounded (see diffusion_operator.cpp).
// Pairs use (A_i + A_j)/2, which keeps V_i w_ij = V_j w_ji and so conserves sum_i V_i c_i exactly;
// in the interior of a regular lattice all A_i agree and the operator is exact for quadratic c.
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

// Pair weights aligned with `neighbours` (CSR), from each particle's diffusion tensor; with
// `corrected` the tensors are first calibrated as described above.
template <int D>
std::vector<double> diffusion_pair_weights(const std::vector<Vec<D>>& positions,
                                           const std::vector<double>& volumes,
                                           const NeighbourList& neighbours, const Kernel& kernel,
                                           const Domain<D>& domain,
                                           const std::vector<Mat<D>>& diffusion_tensor,
                                           bool corrected);

// The discrete second moment S_i of particle i's weights built from the tensor A (see above).
template <int D>
Mat<D> diffusion_second_moment(std::size_t i, const std::vector<Vec<D>>& positions,
                               const std::vector<double>& volumes, const NeighbourList& neighbours,
                               const Kernel& kernel, const Domain<D>& domain, const Mat<D>& A);

// rate_i = sum_j w_ij (c_j - c_i). Gather loop: each particle writes only its own rate.
void apply_diffusion(const NeighbourList& neighbours, const std::vector<double>& weights,
                     const std::vector<double>& c, std::vector<double>& rate);

}  // namespace cosph

namespace cosph {

// Explicit (forward Euler) diffusion on fixed particles: precomputed pair weights, the stable step
// and the update c += dt * L c. Shared by the diffusion and monodomain modules.
template <int D>
class ExplicitDiffusion {
 public:
  // How the step limit dt = factor * h^2 / (d max tr D) of seed 001 is made safe:
  //  - Monotone: also dt <= 1 / max_i sum_j w_ij (Gershgorin). Each step is then a convex
  //    combination (weights are positive): stable, and c obeys the discrete maximum principle.
  //  - Stable: also dt <= 0.9 * 2 / lambda_max, lambda_max the operator's largest eigenvalue
  //    magnitude (power iteration at set-up). Stable but not monotone; used where other terms
  //    (reactions) break the maximum principle anyway, and it allows the paper's larger step.
  enum class Limit { Monotone, Stable };

  void setup(const std::vector<Vec<D>>& positions, const std::vector<double>& volumes,
             const NeighbourList& neighbours, const Kernel& kernel, const Domain<D>& domain,
             const std::vector<Mat<D>>& diffusion_tensor, bool corrected, double time_step_factor,
             Limit limit = Limit::Monotone);

  double stable_dt() const { return stable_dt_; }
  // c_i += dt * sum_j w_ij (c_j - c_i).
  void step(std::vector<double>& c, double dt);
  // rate_i = sum_j w_ij (c_j - c_i), for callers that fuse the update with other local work.
  const std::vector<double>& rate(const std::vector<double>& c);
  // Largest eigenvalue magnitude of the assembled operator (power iteration).
  double spectral_radius() const;

 private:
  const NeighbourList* neighbours_ = nullptr;
  std::vector<double> weights_, rate_;
  double stable_dt_ = 0.0;
};

extern template class ExplicitDiffusion<2>;
extern template class ExplicitDiffusion<3>;

}  // namespace cosph
