#include "driver/module_tree.hpp"

#include <map>
#include <optional>
#include <string>

#include "core/error.hpp"

namespace cosph {

namespace {

struct Node {
  bool coupler = false;
  int index = 0;
  std::optional<int> owner;  // the coupler that owns it
};

std::string coupler_key(int c) { return "couplers[" + std::to_string(c) + "]"; }

class Assembly {
 public:
  Assembly(const proto::Scene& scene, std::vector<std::unique_ptr<Module>> modules,
           const CouplerRegistry& registry)
      : scene_(scene), registry_(registry) {
    for (int k = 0; k < scene.modules_size(); ++k) {
      nodes_[scene.modules(k).name()] = {false, k, std::nullopt};
      auto timed = std::make_unique<TimedModule>(std::move(modules[k]));
      tree_.modules.push_back(timed.get());
      pool_.push_back(std::move(timed));
    }
    tree_.couplers.assign(scene.couplers_size(), nullptr);
    tree_.children.resize(scene.couplers_size());
  }

  ModuleTree build() {
    declare_couplers();
    resolve_children();
    reject_cycles();
    for (int k = 0; k < scene_.modules_size(); ++k)
      if (!nodes_.at(scene_.modules(k).name()).owner) tree_.roots.push_back(std::move(pool_[k]));
    for (int c = 0; c < scene_.couplers_size(); ++c)
      if (!nodes_.at(scene_.couplers(c).name()).owner) tree_.roots.push_back(build_coupler(c));
    return std::move(tree_);
  }

 private:
  void declare_couplers() {
    for (int c = 0; c < scene_.couplers_size(); ++c) {
      const auto& spec = scene_.couplers(c);
      const std::string type = coupler_type(spec);
      if (type.empty()) throw ConfigError(coupler_key(c), "a coupler needs its type, e.g. 'fsi:'");
      if (!registry_.has(type))
        throw ConfigError(coupler_key(c), "no coupler of type '" + type + "'");
      if (auto it = nodes_.find(spec.name()); it != nodes_.end())
        throw ConfigError(coupler_key(c) + ".name",
                          "'" + spec.name() + "' is already the name of a " +
                              (it->second.coupler ? "coupler" : "module"));
      nodes_[spec.name()] = {true, c, std::nullopt};
    }
  }

  void resolve_children() {
    for (int c = 0; c < scene_.couplers_size(); ++c) {
      const auto& spec = scene_.couplers(c);
      const std::string type = coupler_type(spec);
      const auto& roles = registry_.roles(type);
      const auto names = coupled_names(spec, roles);
      for (std::size_t r = 0; r < roles.size(); ++r) {
        const std::string key = coupler_key(c) + "." + type + "." + roles[r];
        auto it = nodes_.find(names[r]);
        if (it == nodes_.end())
          throw ConfigError(key, "no module or coupler named '" + names[r] + "'");
        if (it->second.coupler && it->second.index == c)
          throw ConfigError(key, "coupler '" + spec.name() + "' cannot own itself");
        if (it->second.owner)
          throw ConfigError(key, "'" + names[r] + "' is already owned by coupler '" +
                                     scene_.couplers(*it->second.owner).name() +
                                     "' (a module belongs to one coupler)");
        it->second.owner = c;
      }
    }
  }

  // Each name has one owner, so a cycle is a chain of owners that comes back to where it began.
  void reject_cycles() const {
    for (int c = 0; c < scene_.couplers_size(); ++c) {
      std::string chain = scene_.couplers(c).name();
      std::optional<int> at = nodes_.at(chain).owner;
      for (int hops = 0; at && hops <= scene_.couplers_size(); ++hops) {
        chain += " <- " + scene_.couplers(*at).name();
        if (*at == c) throw ConfigError(coupler_key(c), "couplers own each other: " + chain);
        at = nodes_.at(scene_.couplers(*at).name()).owner;
      }
    }
  }

  std::unique_ptr<Module> build_coupler(int c) {
    const auto& spec = scene_.couplers(c);
    const std::string type = coupler_type(spec);
    std::vector<std::unique_ptr<Module>> children;
    for (const auto& name : coupled_names(spec, registry_.roles(type))) {
      const Node& node = nodes_.at(name);
      std::unique_ptr<Module> child =
          node.coupler ? build_coupler(node.index) : std::move(pool_[node.index]);
      tree_.children[c].push_back(node.coupler ? tree_.couplers[node.index]
                                               : tree_.modules[node.index]);
      children.push_back(std::move(child));
    }
    auto coupler = std::make_unique<TimedModule>(
        registry_.create(type, spec, std::move(children), {&scene_, coupler_key(c)}));
    coupler->initialize();
    tree_.couplers[c] = coupler.get();
    return coupler;
  }

  const proto::Scene& scene_;
  const CouplerRegistry& registry_;
  std::map<std::string, Node> nodes_;
  std::vector<std::unique_ptr<Module>> pool_;
  ModuleTree tree_;
};

}  // namespace

ModuleTree assemble_module_tree(const proto::Scene& scene,
                                std::vector<std::unique_ptr<Module>> modules,
                                const CouplerRegistry& registry) {
  return Assembly(scene, std::move(modules), registry).build();
}

}  // namespace cosph
