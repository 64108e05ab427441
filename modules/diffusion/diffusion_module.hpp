// The `diffusion` module: a scalar field c on fixed particles obeying dc/dt = div(D grad c),
// with D isotropic or transversely isotropic, explicit Euler in time with the step
// dt = factor * h^2 / (d tr D) (seed 001 section 4.2.1), Dirichlet values on regions, and the
// natural zero-flux condition on free boundaries. The monodomain module builds on its operator.
#pragma once

#include <memory>

#include "driver/module.hpp"
#include "driver/registry.hpp"

namespace cosph {

// Creates a 2D or 3D diffusion module from its scene spec.
std::unique_ptr<Module> make_diffusion_module(const proto::ModuleSpec& spec,
                                              const ModuleContext& context);

}  // namespace cosph
