#include "solid_tlsph/material_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/error.hpp"

namespace cosph {

namespace {

// K = 2 mu (1 + nu) / (3 (1 - 2 nu)) (seed 000 eq. 12), or the given bulk modulus.
template <typename Spec>
double penalty_bulk(const Spec& spec, double shear) {
  if (spec.has_bulk_modulus()) return spec.bulk_modulus();
  const double nu = spec.poisson();
  return 2.0 * shear * (1.0 + nu) / (3.0 * (1.0 - 2.0 * nu));
}

}  // namespace

template <int D>
MaterialModel<D>::MaterialModel(const proto::MaterialSpec& spec, const std::string& key)
    : density_(spec.density()) {
  switch (spec.law_case()) {
    case proto::MaterialSpec::kStVenantKirchhoff:
    case proto::MaterialSpec::kNeoHookean: {
      const bool svk = spec.has_st_venant_kirchhoff();
      const auto& c = svk ? spec.st_venant_kirchhoff() : spec.neo_hookean();
      const std::string law_key = key + (svk ? ".st_venant_kirchhoff" : ".neo_hookean");
      try {
        lame_ = lame_from_young_poisson(c.young(), c.poisson());
      } catch (const std::invalid_argument& e) {
        throw ConfigError(law_key, e.what());
      }
      law_ = svk ? Law::StVenantKirchhoff : Law::NeoHookean;
      name_ = svk ? "St Venant-Kirchhoff" : "neo-Hookean";
      break;
    }
    case proto::MaterialSpec::kHolzapfelOgden: {
      const auto& c = spec.holzapfel_ogden();
      // Small-strain shear modulus of the isotropic part: S = a e^{b(I1-3)} I - a C^-1 ~ 2a E.
      ho_ = {
          c.a(), c.b(), c.af(), c.bf(), c.as(), c.bs(), c.afs(), c.bfs(), penalty_bulk(c, c.a())};
      law_ = Law::HolzapfelOgden;
      name_ = "Holzapfel-Ogden";
      break;
    }
    case proto::MaterialSpec::kGuccione: {
      if (D != 3)
        throw ConfigError(key + ".guccione",
                          "the Guccione law needs the full fibre frame: 3D scenes only");
      const auto& c = spec.guccione();
      // Small-strain cross-fibre shear modulus: W ~ c/2 Q, Q ~ 2 bt E_sn^2 gives mu = c bt / 2.
      guccione_ = {c.c(), c.bf(), c.bt(), c.bfs(), penalty_bulk(c, 0.5 * c.c() * c.bt())};
      law_ = Law::Guccione;
      name_ = "Guccione";
      break;
    }
    case proto::MaterialSpec::LAW_NOT_SET:
      throw ConfigError(key,
                        "give the law: st_venant_kirchhoff, neo_hookean, holzapfel_ogden or "
                        "guccione");
  }
  measure_small_strain_moduli();
}

template <int D>
double MaterialModel<D>::energy(const Mat<D>& F, const Mat<D>& frame) const {
  switch (law_) {
    case Law::StVenantKirchhoff:
      return svk_energy<D>(lame_, F);
    case Law::NeoHookean:
      return neo_hookean_energy<D>(lame_, F);
    case Law::HolzapfelOgden:
      return holzapfel_ogden_energy<D>(ho_, F, frame.col(0), frame.col(1));
    case Law::Guccione:
      if constexpr (D == 3) return guccione_energy(guccione_, F, frame);
  }
  return 0.0;
}

template <int D>
double MaterialModel<D>::wave_speed() const {
  return std::sqrt(wave_modulus_ / density_);
}

// The moduli are measured from the law itself (forward differences of P at F = I, with the
// fibre frame along the axes) rather than restated per law: one definition, no drift between
// them. Longitudinal: M_a = dP_aa/dF_aa; shear: mu = mean of dP_ab/dF_ab (a != b); bulk from the
// volumetric response K = (mean M_a) - 4 mu / 3 (3D) or - mu (plane strain, 2D: lambda + mu is
// the in-plane bulk modulus; used only for the hourglass scale).
template <int D>
void MaterialModel<D>::measure_small_strain_moduli() {
  const double delta = 1e-7;
  const Mat<D> frame = Mat<D>::Identity();
  double longitudinal_max = 0.0, longitudinal_mean = 0.0, shear = 0.0;
  for (int a = 0; a < D; ++a) {
    Mat<D> F = Mat<D>::Identity();
    F(a, a) += delta;
    const double M = stress(F, frame)(a, a) / delta;
    longitudinal_max = std::max(longitudinal_max, M);
    longitudinal_mean += M / D;
    for (int b = 0; b < D; ++b) {
      if (a == b) continue;
      Mat<D> G = Mat<D>::Identity();
      G(a, b) += delta;
      shear += stress(G, frame)(a, b) / delta / (D * (D - 1));
    }
  }
  wave_modulus_ = longitudinal_max;
  shear_ = shear;
  bulk_ = std::max(longitudinal_mean - 4.0 * shear / 3.0, shear);
}

template class MaterialModel<2>;
template class MaterialModel<3>;

}  // namespace cosph
