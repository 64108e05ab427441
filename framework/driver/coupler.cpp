#include "driver/coupler.hpp"

#include <algorithm>

#include "core/error.hpp"

namespace cosph {

Coupler::Coupler(std::string type, std::string name, std::vector<std::unique_ptr<Module>> children)
    : type_(std::move(type)), name_(std::move(name)), children_(std::move(children)) {}

ModuleInfo Coupler::info() const {
  ModuleInfo info;
  info.type = type_;
  info.name = name_;
  info.active_features = features();
  for (const auto& c : children_) {
    const ModuleInfo ci = c->info();
    info.children.push_back(ci.name);
    info.dimension = ci.dimension;
    // A coupler offers its children's ports, each also as "child.port".
    for (auto p : ci.reads) info.reads.push_back({ci.name + "." + p.name, p.fields});
    for (auto p : ci.writes) info.writes.push_back({ci.name + "." + p.name, p.fields});
    if (info.spacing == 0.0 || (ci.spacing > 0.0 && ci.spacing < info.spacing))
      info.spacing = ci.spacing;
  }
  return info;
}

double Coupler::time() const { return children_.front()->time(); }

const Module& Coupler::port_owner(const std::string& port, bool writes, std::string& local) const {
  for (const auto& c : children_) {
    const ModuleInfo ci = c->info();
    const auto& ports = writes ? ci.writes : ci.reads;
    for (const auto& p : ports)
      if (ci.name + "." + p.name == port) {
        local = p.name;
        return *c;
      }
  }
  throw RuntimeError("coupler '" + name_ + "' has no port '" + port +
                     "' (its ports are its children's, named child.port)");
}

void Coupler::write(const std::string& port, FieldBuffer& out) const {
  std::string local;
  port_owner(port, true, local).write(local, out);
}

void Coupler::read(const std::string& port, const FieldBuffer& in) {
  std::string local;
  const_cast<Module&>(port_owner(port, false, local)).read(local, in);
}

void Coupler::save(StateRecord& state) const {
  save_own(state);
  state.children.clear();
  for (const auto& c : children_) {
    StateRecord child;
    const ModuleInfo ci = c->info();
    child.name = ci.name;
    child.type = ci.type;
    c->save(child);
    state.children.push_back(std::move(child));
  }
}

void Coupler::load(const StateRecord& state) {
  if (state.children.size() != children_.size())
    throw RuntimeError("coupler '" + name_ + "': checkpoint has " +
                       std::to_string(state.children.size()) + " children, the coupler " +
                       std::to_string(children_.size()));
  for (std::size_t k = 0; k < children_.size(); ++k) {
    const ModuleInfo ci = children_[k]->info();
    const StateRecord& child = state.children[k];
    if (child.name != ci.name || child.type != ci.type)
      throw RuntimeError("coupler '" + name_ + "': checkpoint child '" + child.name + "' (" +
                         child.type + ") does not match '" + ci.name + "' (" + ci.type + ")");
    children_[k]->load(child);
  }
  load_own(state);
  connect();
}

void Coupler::prepare_output() {
  for (auto& c : children_) c->prepare_output();
}

void Coupler::bodies(BodyViews& views) const {
  for (const auto& c : children_) c->bodies(views);
}

std::size_t Coupler::particle_count() const {
  std::size_t n = 0;
  for (const auto& c : children_) n += c->particle_count();
  return n;
}

}  // namespace cosph
