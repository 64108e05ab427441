#include "solid_tlsph/materials.hpp"

#include <stdexcept>

namespace cosph {

LameParameters lame_from_young_poisson(double young, double poisson) {
  if (!(young > 0.0))
    throw std::invalid_argument("Young's modulus must be positive, got " + std::to_string(young));
  if (!(poisson > -1.0 && poisson < 0.5))
    throw std::invalid_argument("Poisson's ratio must lie in (-1, 0.5), got " +
                                std::to_string(poisson));
  const double mu = young / (2.0 * (1.0 + poisson));
  const double bulk = young / (3.0 * (1.0 - 2.0 * poisson));
  return {bulk - 2.0 * mu / 3.0, mu, bulk};
}

namespace {

// Green strain in the fibre frame: E_local = R^T E R with R = frame (columns f, s, n).
Mat<3> local_strain(const Mat<3>& F, const Mat<3>& frame) {
  const Mat<3> E = 0.5 * (F.transpose() * F - Mat<3>::Identity());
  return frame.transpose() * E * frame;
}

// dQ/dE_local (symmetric): Q = bf E_ff^2 + bt (E_ss^2 + E_nn^2 + E_sn^2 + E_ns^2)
//                               + bfs (E_fs^2 + E_sf^2 + E_fn^2 + E_nf^2).
Mat<3> weights(const GuccioneParameters& p) {
  Mat<3> w;
  w << p.bf, p.bfs, p.bfs,  //
      p.bfs, p.bt, p.bt,    //
      p.bfs, p.bt, p.bt;
  return w;
}

}  // namespace

double guccione_energy(const GuccioneParameters& p, const Mat<3>& F, const Mat<3>& frame) {
  const Mat<3> E = local_strain(F, frame);
  const double Q = (weights(p).array() * E.array() * E.array()).sum();
  const double J = F.determinant();
  return 0.5 * p.c * (std::exp(Q) - 1.0) + 0.5 * p.bulk * (J - 1.0) * (J - 1.0);
}

Mat<3> guccione_stress(const GuccioneParameters& p, const Mat<3>& F, const Mat<3>& frame) {
  const Mat<3> E = local_strain(F, frame);
  const Mat<3> w = weights(p);
  const double Q = (w.array() * E.array() * E.array()).sum();
  // S_local = dW/dE_local = C/2 e^Q dQ/dE = C e^Q (w .* E); rotated back S = R S_local R^T.
  const Mat<3> S_local = p.c * std::exp(Q) * w.cwiseProduct(E);
  const double J = F.determinant();
  const Mat<3> S =
      frame * S_local * frame.transpose() + p.bulk * (J - 1.0) * J * (F.transpose() * F).inverse();
  return F * S;
}

}  // namespace cosph
