// The `monodomain` module: transmembrane potential V and gate w on fixed particles of cardiac
// tissue (seed 001 sections 3.1, 4.2):
//   dV/dt = div(D grad V) + I_ion(V, w),   dw/dt = g(V, w),   D = d_iso I + d_fibre f0 (x) f0,
// advanced by reaction-by-reaction Strang splitting (errata to seed 001 eqs. 44-46):
//   V half step, w half step, diffusion full step, w half step, V half step,
// each reaction by the quasi-steady-state update (eq. 34), the diffusion by the kernel-corrected
// explicit operator of framework/operators. The step is the diffusion limit 0.5 h^2/(d tr D)
// (reactions are unconditionally stable). Outputs: voltage, gate, activation time.
#pragma once

#include <memory>

#include "driver/module.hpp"
#include "driver/registry.hpp"

namespace cosph {

std::unique_ptr<Module> make_monodomain_module(const proto::ModuleSpec& spec,
                                               const ModuleContext& context);

}  // namespace cosph
