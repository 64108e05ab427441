// Building a simulation from scene text inside a test: loaded, checked, initialised, quiet, and
// with no files unless the options name an output directory. Shared by the module tests.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "driver/simulation.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace cosph::test {

inline std::unique_ptr<Simulation> make_simulation(const std::string& text,
                                                   const std::vector<std::string>& overrides = {},
                                                   RunOptions options = {}) {
  if (options.output_directory.empty()) options.bench = true;
  options.progress = false;
  auto simulation = std::make_unique<Simulation>(load_scene_text(text, "scene.yaml", overrides),
                                                 builtin_modules(), options);
  simulation->initialize();
  return simulation;
}

// The particles of body `k` of the first module (0: its main body; the fluid's walls are 1).
template <int D>
const ParticleSet<D>& particles_of(Simulation& simulation, std::size_t k = 0) {
  BodyViews views;
  simulation.module(0).bodies(views);
  if constexpr (D == 2)
    return *views.bodies2.at(k).particles;
  else
    return *views.bodies3.at(k).particles;
}

}  // namespace cosph::test
