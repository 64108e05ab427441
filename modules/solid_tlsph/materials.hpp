// Hyperelastic materials of the solid module (seeds 000 and 001; errata in ../shared/seeds):
// each is a strain energy W(F) per unit reference volume and its first Piola-Kirchhoff stress
// P = dW/dF = F S, S = 2 dW/dC. Formulas are free functions of small fixed-size matrices, tested
// against a central finite difference of W and for frame invariance
// (tests/unit/solid_materials_test). 2D is plane strain (F is 2x2, the out-of-plane stretch is 1).
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <cmath>
#include <string>

#include "core/types.hpp"

namespace cosph {

// Elastic constants from Young's modulus and Poisson's ratio (E = 2G(1 + nu) = 3K(1 - 2nu), the
// corrected seed 001 eq. 64). Throws std::invalid_argument unless E > 0 and -1 < nu < 0.5.
struct LameParameters {
  double lambda, mu, bulk;
};
LameParameters lame_from_young_poisson(double young, double poisson);

// ---- St Venant-Kirchhoff: the linear law on the Green strain E = (C - I)/2 --------------------
// W = lambda/2 (tr E)^2 + mu E:E,  S = lambda tr(E) I + 2 mu E.
template <int D>
double svk_energy(const LameParameters& p, const Mat<D>& F) {
  const Mat<D> E = 0.5 * (F.transpose() * F - Mat<D>::Identity());
  return 0.5 * p.lambda * E.trace() * E.trace() + p.mu * (E.array() * E.array()).sum();
}
template <int D>
Mat<D> svk_stress(const LameParameters& p, const Mat<D>& F) {
  const Mat<D> E = 0.5 * (F.transpose() * F - Mat<D>::Identity());
  return F * (p.lambda * E.trace() * Mat<D>::Identity() + 2.0 * p.mu * E);
}

// ---- Compressible neo-Hookean ---------------------------------------------------------------
// W = mu/2 (I1 - d) - mu ln J + lambda/2 (ln J)^2,  P = mu (F - F^-T) + lambda ln(J) F^-T.
// (I1 - d: in plane strain the out-of-plane stretch contributes 1 to I1 and 1 to d alike.)
template <int D>
double neo_hookean_energy(const LameParameters& p, const Mat<D>& F) {
  const double J = F.determinant(), lnJ = std::log(J);
  return 0.5 * p.mu * ((F.transpose() * F).trace() - D) - p.mu * lnJ + 0.5 * p.lambda * lnJ * lnJ;
}
template <int D>
Mat<D> neo_hookean_stress(const LameParameters& p, const Mat<D>& F) {
  const Mat<D> F_inv_T = F.inverse().transpose();
  return p.mu * (F - F_inv_T) + p.lambda * std::log(F.determinant()) * F_inv_T;
}

// ---- Holzapfel-Ogden (seed 001 eqs. 12-15, with the errata) ----------------------------------
// W = a/(2b) (exp[b(I1 - 3)] - 1) - a ln J
//   + sum_{i = f, s} a_i/(2 b_i) (exp[b_i (I4i - 1)^2] - 1)   (only in tension, I4i > 1)
//   + a_fs/(2 b_fs) (exp[b_fs I8fs^2] - 1) + K/2 (J - 1)^2,
// I1 = tr C, I4f = f0.C f0, I4s = s0.C s0, I8fs = f0.C s0. The "- a ln J" term makes the reference
// state stress-free (the isotropic term alone gives S = a I at F = I), K/2 (J - 1)^2 is the
// volumetric penalty. I1 - 3 counts the plane-strain stretch in 2D.
struct HolzapfelOgdenParameters {
  double a, b, af, bf, as, bs, afs, bfs, bulk;
};
template <int D>
double holzapfel_ogden_energy(const HolzapfelOgdenParameters& p, const Mat<D>& F, const Vec<D>& f0,
                              const Vec<D>& s0) {
  const Mat<D> C = F.transpose() * F;
  const double J = F.determinant();
  const double I1 = C.trace() + (3 - D), I4f = f0.dot(C * f0), I4s = s0.dot(C * s0),
               I8 = f0.dot(C * s0);
  double W = p.a / (2.0 * p.b) * (std::exp(p.b * (I1 - 3.0)) - 1.0) - p.a * std::log(J) +
             0.5 * p.bulk * (J - 1.0) * (J - 1.0);
  if (I4f > 1.0) W += p.af / (2.0 * p.bf) * (std::exp(p.bf * (I4f - 1.0) * (I4f - 1.0)) - 1.0);
  if (I4s > 1.0) W += p.as / (2.0 * p.bs) * (std::exp(p.bs * (I4s - 1.0) * (I4s - 1.0)) - 1.0);
  W += p.afs / (2.0 * p.bfs) * (std::exp(p.bfs * I8 * I8) - 1.0);
  return W;
}
template <int D>
Mat<D> holzapfel_ogden_stress(const HolzapfelOgdenParameters& p, const Mat<D>& F, const Vec<D>& f0,
                              const Vec<D>& s0) {
  const Mat<D> C = F.transpose() * F, C_inv = C.inverse();
  const double J = F.determinant();
  const double I1 = C.trace() + (3 - D), I4f = f0.dot(C * f0), I4s = s0.dot(C * s0),
               I8 = f0.dot(C * s0);
  // S = 2 dW/dC: dI1/dC = I, dI4f/dC = f0 f0, dI4s/dC = s0 s0 (seed 001 eq. 14 corrected),
  // dI8/dC = (f0 s0 + s0 f0)/2, d ln J/dC = C^-1/2, dJ/dC = J C^-1/2.
  Mat<D> S = p.a * std::exp(p.b * (I1 - 3.0)) * Mat<D>::Identity() - p.a * C_inv +
             p.bulk * (J - 1.0) * J * C_inv;
  if (I4f > 1.0)
    S +=
        2.0 * p.af * (I4f - 1.0) * std::exp(p.bf * (I4f - 1.0) * (I4f - 1.0)) * f0 * f0.transpose();
  if (I4s > 1.0)
    S +=
        2.0 * p.as * (I4s - 1.0) * std::exp(p.bs * (I4s - 1.0) * (I4s - 1.0)) * s0 * s0.transpose();
  S += p.afs * I8 * std::exp(p.bfs * I8 * I8) * (f0 * s0.transpose() + s0 * f0.transpose());
  return F * S;
}

// ---- Guccione (seed 000; Land et al. 2015) ---------------------------------------------------
// W = C/2 (exp Q - 1) + K/2 (J - 1)^2 (the penalty p = K (J - 1) of seed 000), with the Green
// strain in the fibre frame (f, s, n): Q = bf E_ff^2 + bt (E_ss^2 + E_nn^2 + 2 E_sn^2) + 2 bfs
// (E_fs^2 + E_fn^2). 3D only (the frame needs three directions).
struct GuccioneParameters {
  double c, bf, bt, bfs, bulk;
};
double guccione_energy(const GuccioneParameters& p, const Mat<3>& F, const Mat<3>& frame);
// `frame` has the unit fibre, sheet and normal directions as columns.
Mat<3> guccione_stress(const GuccioneParameters& p, const Mat<3>& F, const Mat<3>& frame);

}  // namespace cosph
