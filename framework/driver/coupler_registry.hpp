// Registry from a coupler type (the scene's key under `couplers[i]`, e.g. `fsi`) to its roles
// (the fields of its spec that name the modules it owns, e.g. `fluid` and `solid`) and a factory.
// Registered explicitly at start-up (app/module_catalogue.cpp), like the modules.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "driver/coupler.hpp"
#include "scene.pb.h"

namespace cosph {

struct CouplerContext {
  const proto::Scene* scene = nullptr;
  std::string key_path;  // e.g. "couplers[0]"
};

// The children arrive initialised, in the order of the type's roles.
using CouplerFactory = std::function<std::unique_ptr<Coupler>(
    const proto::CouplerSpec&, std::vector<std::unique_ptr<Module>> children,
    const CouplerContext&)>;

class CouplerRegistry {
 public:
  void add(const std::string& type, std::vector<std::string> roles, CouplerFactory factory);
  bool has(const std::string& type) const { return entries_.count(type) > 0; }
  const std::vector<std::string>& roles(const std::string& type) const;
  std::unique_ptr<Coupler> create(const std::string& type, const proto::CouplerSpec& spec,
                                  std::vector<std::unique_ptr<Module>> children,
                                  const CouplerContext& context) const;

 private:
  struct Entry {
    std::vector<std::string> roles;
    CouplerFactory factory;
  };
  std::map<std::string, Entry> entries_;
};

// The type of a coupler spec: the name of the oneof member that is set ("" if none).
std::string coupler_type(const proto::CouplerSpec& spec);
// The module names a coupler spec gives for each role of its type.
std::vector<std::string> coupled_names(const proto::CouplerSpec& spec,
                                       const std::vector<std::string>& roles);

}  // namespace cosph
