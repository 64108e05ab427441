#include "driver/coupler_registry.hpp"

#include <stdexcept>

#include "core/error.hpp"

namespace cosph {

void CouplerRegistry::add(const std::string& type, std::vector<std::string> roles,
                          CouplerFactory factory) {
  if (entries_.count(type)) throw std::logic_error("coupler type '" + type + "' registered twice");
  entries_[type] = {std::move(roles), std::move(factory)};
}

const std::vector<std::string>& CouplerRegistry::roles(const std::string& type) const {
  return entries_.at(type).roles;
}

std::unique_ptr<Coupler> CouplerRegistry::create(const std::string& type,
                                                 const proto::CouplerSpec& spec,
                                                 std::vector<std::unique_ptr<Module>> children,
                                                 const CouplerContext& context) const {
  return entries_.at(type).factory(spec, std::move(children), context);
}

std::string coupler_type(const proto::CouplerSpec& spec) {
  const auto* oneof = spec.GetDescriptor()->FindOneofByName("type");
  const auto* field = spec.GetReflection()->GetOneofFieldDescriptor(spec, oneof);
  return field ? field->name() : std::string();
}

std::vector<std::string> coupled_names(const proto::CouplerSpec& spec,
                                       const std::vector<std::string>& roles) {
  const auto* oneof = spec.GetDescriptor()->FindOneofByName("type");
  const auto* field = spec.GetReflection()->GetOneofFieldDescriptor(spec, oneof);
  if (!field) return {};
  const auto& typed = spec.GetReflection()->GetMessage(spec, field);
  std::vector<std::string> names;
  for (const auto& role : roles) {
    const auto* f = typed.GetDescriptor()->FindFieldByName(role);
    if (!f) throw std::logic_error("coupler '" + field->name() + "' has no field '" + role + "'");
    names.push_back(typed.GetReflection()->GetString(typed, f));
  }
  return names;
}

}  // namespace cosph
