// The discrete operators of total-Lagrangian SPH (seed 001 eqs. 35-39, seed 000 eqs. 16-20), on
// pairs fixed in the reference configuration. Everything that does not change in a
// total-Lagrangian body (neighbours, corrected kernel gradients) is computed once; a step is then
// two gathers over the same pairs.
//
// Notation: X reference positions, u displacements, x = X + u, X_ij = X_j - X_i. For particle i
// and neighbour j the corrected gradient g_ij makes
//     F_i = I + sum_j (u_j - u_i) g_ij^T
// exact for affine displacements (linear correction: g_ij = B_i^T w_ij with w_ij = V_j grad_i W
// and B_i = (sum_j X_ij (x) w_ij)^-1, seed 001 eq. 39 with the sign erratum) or for quadratic ones
// too (quadratic correction, below).
//   Momentum: the exact gradient of the discrete strain energy sum_i V_i Psi(F_i),
//     rho0_i a_i = P_i sum_j g_ij + sum_j P_j b_ij,     b_ij = -(V_j / V_i) g_ji,
// which for the linear correction is seed 001 eqs. 37-38, sum_j (P_i B_i^T + P_j B_j^T) w_ij.
// The energy is translation and rotation invariant for any objective law, so linear and angular
// momentum are conserved to round-off (tests/unit/solid_tlsph_test).
//
// Why quadratic: in bending the displacement is quadratic across the thickness and a first-order
// correction is exact only at particles whose neighbourhood is symmetric. Next to a surface it
// under-reads the bending strain: the discrete energy of the exact pure-bending field is 79% of
// the true one at 5 particles through the thickness, 94% at 10 and 98% at 20 (the plate's period
// is 20%, 6% and 2.3% long). The quadratic correction fits u_j - u_i = G X_ij + (second order)
// by weighted least squares with the weights of the linear one (omega_ij = -V_j W'(r) / r, so that
// the linear fit is exactly B_i^T w_ij): where the neighbourhood is symmetric the second-order
// moments decouple and g_ij is the linear one; elsewhere F is exact for quadratic fields. A
// particle whose neighbours cannot determine a quadratic (fewer than three distinct layers along
// some direction, e.g. a body one or two particles thick) keeps the linear correction.
#pragma once

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/types.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/neighbour_list.hpp"

namespace cosph {

enum class GradientCorrection { linear, quadratic };

template <int D>
struct ReferencePairs {
  NeighbourList neighbours;               // in the reference configuration, self excluded
  std::vector<Vec<D>> gradient;           // g_ij, one per pair
  std::vector<Vec<D>> reverse;            // b_ij = -(V_j / V_i) g_ji, one per pair
  std::vector<std::size_t> reverse_pair;  // per pair (i, j): the index of the pair (j, i)
  std::vector<Vec<D>> gradient_sum;       // sum_j g_ij, one per particle
  std::vector<char> quadratic;            // per particle: 1 where the quadratic correction holds
  std::size_t quadratic_particles() const {
    return static_cast<std::size_t>(std::count(quadratic.begin(), quadratic.end(), char(1)));
  }
  // Only with hourglass control: V_j W_ij / |X_ij|^2 per pair.
  std::vector<double> hourglass_weight;
  // Only where asked (build_reference_pairs' `curvature`): the quadratic fit's second-derivative
  // coefficients h_ij, symmetric, so that the fitted d2u/dX_b dX_c at particle i is sum_j (u_j -
  // u_i) h_ij(b, c) (zero where the linear correction holds), and their sums over j.
  std::vector<Mat<D>> curvature;
  std::vector<Mat<D>> curvature_sum;
  std::vector<Mat<D>> curvature_reverse;  // -(V_j / V_i) h_ji, as `reverse` is for g
};

// Where a particle's strain energy is sampled when it is integrated over the particle's dual cell
// instead of taken at the particle: 2D points per particle, offsets d_q = X_q - X_i, equal weights
// 1 / (2D); F at a point is the quadratic fit's F_i + H_i d_q (the pairs' curvature).
template <int D>
struct EnergyQuadrature {
  static constexpr int points = 2 * D;
  using Points = std::array<Vec<D>, points>;
  std::vector<Points> offset;

  // The points c +- sqrt(D lambda_k) e_k of a cell with centroid c (relative to the particle) and
  // covariance sum_k lambda_k e_k e_k^T: with equal weights they reproduce both moments, so they
  // integrate quadratic fields over the cell exactly (a cube's points are its face centres).
  static Points points_of(const Vec<D>& centroid, const Mat<D>& covariance) {
    const Eigen::SelfAdjointEigenSolver<Mat<D>> eigen(covariance);
    Points p;
    for (int k = 0; k < D; ++k) {
      const Vec<D> axis =
          std::sqrt(D * std::max(eigen.eigenvalues()[k], 0.0)) * eigen.eigenvectors().col(k);
      p[2 * k] = centroid + axis;
      p[2 * k + 1] = centroid - axis;
    }
    return p;
  }
};

// Builds the pairs. Throws RuntimeError naming the particle whose linear correction matrix is
// singular.
template <int D>
ReferencePairs<D> build_reference_pairs(const std::vector<Vec<D>>& X,
                                        const std::vector<double>& volume, const Kernel& kernel,
                                        GradientCorrection correction, bool hourglass,
                                        bool curvature = false);

// F_i = I + sum_j (u_j - u_i) g_ij^T from the displacements, for one particle (inline: the
// solid fuses it with the stress in one loop) and for all.
template <int D>
Mat<D> deformation_gradient(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& u,
                            std::size_t i) {
  const auto& nl = pairs.neighbours;
  Mat<D> G = Mat<D>::Zero();
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k)
    G.noalias() += (u[nl.index[k]] - u[i]) * pairs.gradient[k].transpose();
  return Mat<D>::Identity() + G;
}

template <int D>
void deformation_gradients(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& u,
                           std::vector<Mat<D>>& F);

// rho0_i a_i = P_i sum_j g_ij + sum_j P_j b_ij for the first Piola stresses P; returns the force
// density (the caller divides by rho0).
template <int D>
Vec<D> pair_stress_divergence(const ReferencePairs<D>& pairs, const std::vector<Mat<D>>& P,
                              std::size_t i) {
  const auto nb = pairs.neighbours.of(i);
  const std::size_t start = pairs.neighbours.offset[i];
  Vec<D> sum = P[i] * pairs.gradient_sum[i];
  for (std::size_t k = 0; k < nb.size(); ++k) sum.noalias() += P[nb[k]] * pairs.reverse[start + k];
  return sum;
}

// The slopes of F across particle i's dual cell from the quadratic fit (its curvature
// coefficients): F(X_i + d) = F_i + sum_c d_c S_c with S_c = sum_j (u_j - u_i) h_ij(:, c)^T; zero
// where the linear correction holds.
template <int D>
using GradientSlopes = std::array<Mat<D>, D>;
template <int D>
GradientSlopes<D> deformation_gradient_slopes(const ReferencePairs<D>& pairs,
                                              const std::vector<Vec<D>>& u, std::size_t i) {
  const auto& nl = pairs.neighbours;
  GradientSlopes<D> S;
  for (auto& s : S) s.setZero();
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
    const Vec<D> du = u[nl.index[k]] - u[i];
    for (int c = 0; c < D; ++c) S[c].noalias() += du * pairs.curvature[k].col(c).transpose();
  }
  return S;
}

// F at the point X_i + d of particle i's dual cell: F_i + sum_c d_c S_c.
template <int D>
Mat<D> gradient_at_offset(const Mat<D>& F, const GradientSlopes<D>& S, const Vec<D>& d) {
  Mat<D> F_d = F;
  for (int c = 0; c < D; ++c) F_d.noalias() += d[c] * S[c];
  return F_d;
}

// The energy of particle i integrated over its dual cell: P_iq = stress(F_iq) at the quadrature
// points F_iq = F_i + sum_c d_qc S_c, returned as their mean P_i = sum_q w_q P_iq and first
// moments T_i[c] = sum_q w_q d_qc P_iq, which is all the stress divergence needs; F_iq are kept
// in `Fq` (for the tangent) where given.
template <int D>
using StressMoments = std::array<Mat<D>, D>;
template <int D, typename Stress>
Mat<D> integrate_stress(const EnergyQuadrature<D>& quadrature, std::size_t i, const Mat<D>& F,
                        const GradientSlopes<D>& S, const Stress& stress, StressMoments<D>& T,
                        std::array<Mat<D>, EnergyQuadrature<D>::points>* Fq = nullptr) {
  constexpr double w = 1.0 / EnergyQuadrature<D>::points;
  Mat<D> mean = Mat<D>::Zero();
  for (auto& t : T) t.setZero();
  for (int q = 0; q < EnergyQuadrature<D>::points; ++q) {
    const Vec<D>& d = quadrature.offset[i][q];
    const Mat<D> F_q = gradient_at_offset<D>(F, S, d);
    if (Fq) (*Fq)[q] = F_q;
    const Mat<D> P_q = stress(F_q);
    mean.noalias() += w * P_q;
    for (int c = 0; c < D; ++c) T[c].noalias() += (w * d[c]) * P_q;
  }
  return mean;
}

// The exact gradient of the dual-cell energy sum_i V_i sum_q w_q Psi(F_iq), with F_iq linear in u
// through g_ij + h_ij d_q: pair_stress_divergence of the mean stresses plus the moments' share,
//   sum_c T_i[c] sum_j h_ij(:, c) - sum_j (V_j / V_i) sum_c T_j[c] h_ji(:, c).
template <int D>
Vec<D> quadrature_stress_divergence(const ReferencePairs<D>& pairs, const std::vector<Mat<D>>& P,
                                    const std::vector<StressMoments<D>>& T, std::size_t i) {
  const auto& nl = pairs.neighbours;
  Vec<D> sum = pair_stress_divergence<D>(pairs, P, i);
  for (int c = 0; c < D; ++c) sum.noalias() += T[i][c] * pairs.curvature_sum[i].col(c);
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
    const Index j = nl.index[k];
    const Mat<D>& h = pairs.curvature_reverse[k];
    for (int c = 0; c < D; ++c) sum.noalias() += T[j][c] * h.col(c);
  }
  return sum;
}

// Artificial viscosity of seed 000 (eqs. 19-20) in total-Lagrangian form: each pair's viscous
// pressure q_ij = rho_ij (-alpha c phi_ij + beta phi_ij^2) / 2 (phi_ij < 0: approaching pairs
// only) acts through the Piola transform A = J F^-T of both particles, like a pressure would:
//   rho0_i a_i += -sum_j q_ij (A_i g_ij + A_j b_ij)
// (for the linear correction -sum_j q_ij (A_i B_i^T + A_j B_j^T) w_ij). Antisymmetric pair
// forces: linear momentum is conserved. Returns the force density.
struct ViscosityParameters {
  double alpha, beta, sound_speed, smoothing_length;
};
template <int D>
Vec<D> artificial_viscosity(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& x,
                            const std::vector<Vec<D>>& v, const std::vector<double>& density,
                            const std::vector<Mat<D>>& A, const ViscosityParameters& p,
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
