// The `fluid` module: weakly-compressible SPH with inter-particle Riemann solvers (seed 003
// sections 2 and 7), free-surface and confined flows in 2D and 3D, walls by the one-sided
// Riemann condition, dual-criteria time stepping with position-based Verlet.
#pragma once

#include <memory>

#include "driver/module.hpp"
#include "driver/registry.hpp"

namespace cosph {

std::unique_ptr<Module> make_fluid_module(const proto::ModuleSpec& spec,
                                          const ModuleContext& context);

}  // namespace cosph
