#include "driver/registry.hpp"

#include <stdexcept>

#include "core/error.hpp"

namespace cosph {

void ModuleRegistry::add(const std::string& type, ModuleFactory factory) {
  if (factories_.count(type)) throw std::logic_error("module type '" + type + "' registered twice");
  factories_[type] = std::move(factory);
}

std::unique_ptr<Module> ModuleRegistry::create(const std::string& type,
                                               const proto::ModuleSpec& spec,
                                               const ModuleContext& context) const {
  auto it = factories_.find(type);
  if (it == factories_.end()) {
    std::string known;
    for (const auto& [name, f] : factories_) known += (known.empty() ? "" : ", ") + name;
    throw ConfigError(context.key_path, "no module of type '" + type + "' (known: " + known + ")");
  }
  return it->second(spec, context);
}

std::string module_type(const proto::ModuleSpec& spec) {
  const auto* oneof = spec.GetDescriptor()->FindOneofByName("type");
  const auto* field = spec.GetReflection()->GetOneofFieldDescriptor(spec, oneof);
  return field ? field->name() : std::string();
}

}  // namespace cosph
