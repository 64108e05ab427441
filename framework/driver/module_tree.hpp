// The scene's modules arranged under its couplers: every coupler takes ownership of the modules
// (or couplers) it names, and what no coupler owns is a root that the driver advances. Every
// module and coupler is wrapped in a TimedModule, so the summary has each one's time.
#pragma once

#include <memory>
#include <vector>

#include "driver/coupler_registry.hpp"
#include "driver/timed_module.hpp"
#include "scene.pb.h"

namespace cosph {

struct ModuleTree {
  std::vector<std::unique_ptr<Module>> roots;       // what the driver advances, in scene order
  std::vector<TimedModule*> modules;                // every scene module, in the order of `modules`
  std::vector<TimedModule*> couplers;               // every coupler, in the order of `couplers`
  std::vector<std::vector<TimedModule*>> children;  // of each coupler, in its roles' order
};

// Takes the scene's initialised modules (in scene order) and builds its couplers over them.
// Coupling mistakes are ConfigErrors naming the key: an unknown or doubly owned name, a cycle,
// a coupler without a type; a coupler's factory adds its own (missing ports, resolutions).
ModuleTree assemble_module_tree(const proto::Scene& scene,
                                std::vector<std::unique_ptr<Module>> modules,
                                const CouplerRegistry& registry);

}  // namespace cosph
