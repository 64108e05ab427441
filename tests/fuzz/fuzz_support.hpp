// What every fuzz target does with an input it has turned into a scene: build it and run two
// steps on one thread, writing nothing. A cosph error (ConfigError, SceneError, RuntimeError)
// with a message is the accepted way to refuse; any other exception escapes to the fuzzer, and
// an empty message aborts: both are bugs.
#pragma once

#include <cstdlib>
#include <iostream>
#include <string>
#include <utility>

#include "core/error.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace cosph::fuzz {

inline void require_message(const std::exception& e) {
  if (std::string(e.what()).empty()) {
    std::cerr << "a cosph error without a message\n";
    std::abort();
  }
}

// Loads the scene with `load` (a callable returning a LoadedScene; it may throw too) and runs it
// for two steps, from `restart_file` when one is given.
template <typename Load>
void run_two_steps(Load&& load, const std::string& restart_file = "") {
  try {
    RunOptions options;
    options.bench = true;
    options.progress = false;
    options.threads = 1;
    options.max_steps = 2;
    options.restart_file = restart_file;
    Simulation simulation(std::forward<Load>(load)(), builtin_modules(), options);
    simulation.initialize();
    simulation.run();
  } catch (const ConfigError& e) {
    require_message(e);
  } catch (const RuntimeError& e) {
    require_message(e);
  }
}

}  // namespace cosph::fuzz
