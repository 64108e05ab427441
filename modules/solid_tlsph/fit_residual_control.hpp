// Zero-energy (hourglass) control that leaves alone every displacement the particles' gradient
// fits reproduce.
//
// F_i is the linear part of a weighted least-squares fit of the neighbours' relative
// displacements d_ij = u_j - u_i (tlsph_operators.cpp: weights omega_ij = -V_j W'(r) / r, basis
// p(s) = (s) or (s, s_a s_b) with s = X_ij / h, quadratic where the particle keeps the quadratic
// correction). Whatever the fit does not reproduce, r_ij = d_ij - a_i^T p(s_ij), is invisible to
// the energy sum_i V_i Psi(F_i): a particle can wander without changing any F (Land's ventricle
// in the steady solve, where the particles on the axis near the apex drifted millimetres sideways
// with the quadratic correction). This control adds the energy
//   E = sum_i c_i sum_j omega_ij |r_ij|^2,   c_i = kappa mu V_i / sum_j omega_ij |X_ij|^2,
// the mean squared residual "strain" of i's neighbourhood at kappa times the shear modulus mu.
// It is zero for every field the fits reproduce (affine ones, and quadratic ones where the fit is
// quadratic: bending keeps its stiffness), and objective: a rigid rotation R of the body rotates
// every residual, r -> R r. Since the fits are linear in u, E = u^T K u / 2 with a constant K:
//   dE/dd_ij = 2 c_i omega_ij r_ij   (the residual is omega-orthogonal to the fit's basis),
// so the force on k gathers 2 c_k sum_j omega_kj r_kj - sum_{i sees k} 2 c_i omega_ik r_ik, and the
// steady solver's tangent gains, per particle i and neighbour slots a, b (slot 0: i itself),
//   2 c_i (omega_a delta_ab - omega_a p_a . y_b),   y_b = M_i^-1 omega_b p_b,
// row and column 0 being minus the sums over the others (d_ij = u_j - u_i).
#pragma once

#include <Eigen/Dense>
#include <vector>

#include "core/types.hpp"
#include "kernels/kernel.hpp"
#include "solid_tlsph/tlsph_operators.hpp"

namespace cosph {

template <int D>
class FitResidualControl {
 public:
  static constexpr int kBasis = D + D * (D + 1) / 2;
  using Basis = Eigen::Matrix<double, kBasis, 1>;

  // kappa_mu = kappa times the material's small-strain shear modulus.
  FitResidualControl(const std::vector<Vec<D>>& X, const std::vector<double>& volume,
                     const ReferencePairs<D>& pairs, const Kernel& kernel, double kappa_mu);

  // The residuals r_ij of every pair at displacements u (stored per pair).
  void update_residuals(const std::vector<Vec<D>>& u);
  // The force on particle k from the residuals of the last update (gather, no atomics).
  Vec<D> force(std::size_t k) const;
  // E at the residuals of the last update.
  double energy() const;
  // K_i(a, b) of particle i for its slots a, b (0: i itself, s >= 1: its (s-1)-th neighbour).
  double stiffness(std::size_t i, std::size_t a, std::size_t b) const;

 private:
  double column_sum(std::size_t i, std::size_t pair) const;  // sum over a >= 1 of K_i(a, b)

  const ReferencePairs<D>& pairs_;
  std::vector<double> omega_;        // per pair
  std::vector<Basis> p_, y_;         // per pair: p(s_ij), M_i^-1 omega_ij p(s_ij)
  std::vector<Basis> p_sum_;         // per particle: sum_j omega_ij p(s_ij)
  std::vector<double> coefficient_;  // per particle: 2 c_i
  std::vector<Vec<D>> residual_;     // per pair
};

}  // namespace cosph
