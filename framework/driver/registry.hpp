// Registry from a module type name (the scene's key under `modules[i]`, e.g. `diffusion`) to a
// factory. Modules are registered explicitly at start-up (app/module_catalogue.cpp), not by
// static initialisers, which static libraries would silently drop.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "driver/coupler_registry.hpp"
#include "driver/module.hpp"
#include "scene.pb.h"

namespace cosph {

// What a factory gets besides the module's own spec.
struct ModuleContext {
  const proto::Scene* scene = nullptr;
  std::string key_path;         // e.g. "modules[0]" — prefix for ConfigError key paths
  std::string scene_directory;  // relative file paths in the scene are relative to it
};

using ModuleFactory =
    std::function<std::unique_ptr<Module>(const proto::ModuleSpec&, const ModuleContext&)>;

class ModuleRegistry {
 public:
  void add(const std::string& type, ModuleFactory factory);
  bool has(const std::string& type) const { return factories_.count(type) > 0; }
  std::unique_ptr<Module> create(const std::string& type, const proto::ModuleSpec& spec,
                                 const ModuleContext& context) const;

  // The coupler types that scenes built with these modules may use.
  CouplerRegistry& couplers() { return couplers_; }
  const CouplerRegistry& couplers() const { return couplers_; }

 private:
  std::map<std::string, ModuleFactory> factories_;
  CouplerRegistry couplers_;
};

// The type of a module spec: the name of the oneof member that is set ("" if none).
std::string module_type(const proto::ModuleSpec& spec);

}  // namespace cosph
