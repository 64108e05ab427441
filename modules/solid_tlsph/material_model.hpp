// One hyperelastic law chosen by the scene, behind a single call: P(F) and W(F) per particle (with
// the particle's fibre frame for anisotropic laws), plus the small-strain moduli that set the wave
// speed (stable time step, artificial viscosity) and the hourglass stiffness. The formulas
// themselves are the free functions of materials.hpp, tested there.
#pragma once

#include <string>

#include "core/types.hpp"
#include "scene.pb.h"
#include "solid_tlsph/materials.hpp"

namespace cosph {

template <int D>
class MaterialModel {
 public:
  // Validates the parameters; throws ConfigError at `key` (e.g. "modules[0].solid.material").
  MaterialModel(const proto::MaterialSpec& spec, const std::string& key);

  // First Piola-Kirchhoff stress and strain energy density. `frame` holds the unit fibre, sheet
  // (and normal) directions as columns; laws without fibres ignore it.
  Mat<D> stress(const Mat<D>& F, const Mat<D>& frame) const {
    switch (law_) {
      case Law::StVenantKirchhoff:
        return svk_stress<D>(lame_, F);
      case Law::NeoHookean:
        return neo_hookean_stress<D>(lame_, F);
      case Law::HolzapfelOgden:
        return holzapfel_ogden_stress<D>(ho_, F, frame.col(0), frame.col(1));
      case Law::Guccione:
        if constexpr (D == 3) return guccione_stress(guccione_, F, frame);
    }
    return Mat<D>::Zero();
  }
  double energy(const Mat<D>& F, const Mat<D>& frame) const;

  const std::string& name() const { return name_; }
  bool anisotropic() const { return law_ == Law::HolzapfelOgden || law_ == Law::Guccione; }
  double density() const { return density_; }
  // Largest longitudinal modulus at F = I (over the axes, with the fibres along them): the wave
  // speed is sqrt(M / rho).
  double wave_modulus() const { return wave_modulus_; }
  double wave_speed() const;
  // Small-strain bulk and shear moduli and the Young's modulus they give (hourglass stiffness).
  double bulk_modulus() const { return bulk_; }
  double shear_modulus() const { return shear_; }
  double young_modulus() const { return 9.0 * bulk_ * shear_ / (3.0 * bulk_ + shear_); }

 private:
  enum class Law { StVenantKirchhoff, NeoHookean, HolzapfelOgden, Guccione };
  void measure_small_strain_moduli();

  Law law_ = Law::StVenantKirchhoff;
  std::string name_;
  double density_ = 0.0;
  LameParameters lame_{};
  HolzapfelOgdenParameters ho_{};
  GuccioneParameters guccione_{};
  double wave_modulus_ = 0.0, bulk_ = 0.0, shear_ = 0.0;
};

extern template class MaterialModel<2>;
extern template class MaterialModel<3>;

}  // namespace cosph
