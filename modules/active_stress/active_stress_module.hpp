// The `active_stress` module: the active stress magnitude T_a per particle from the membrane
// potential, by the ODE of seed 001 (eqs. 17-18) or a prescribed law. It reads V_m through its
// `voltage` port (or a prescribed expression) and writes T_a through `active_stress`, which the
// solid module turns into P_active = T_a F f0 (x) f0.
#pragma once

#include <memory>

#include "driver/module.hpp"
#include "driver/registry.hpp"

namespace cosph {

std::unique_ptr<Module> make_active_stress_module(const proto::ModuleSpec& spec,
                                                  const ModuleContext& context);

}  // namespace cosph
