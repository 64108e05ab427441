// The `solid` module: elastic and hyperelastic solids by total-Lagrangian SPH (seeds 000, 001),
// 2D (plane strain) and 3D. Ports: writes `interface` (surface particles: position, normal,
// volume, velocity, acceleration); reads `external_force` (force per interface particle or per
// particle) and `active_stress` (active tension T_a per particle, P_active = T_a F f0 (x) f0).
#pragma once

#include <memory>

#include "driver/module.hpp"
#include "driver/registry.hpp"

namespace cosph {

std::unique_ptr<Module> make_solid_module(const proto::ModuleSpec& spec,
                                          const ModuleContext& context);

}  // namespace cosph
