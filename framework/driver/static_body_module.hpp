// Common ground of modules whose particles never move (diffusion, monodomain, active stress):
// the scene context, one body of particles with its kernel and domain, time and step count, and
// the parts of the Module contract that are the same for all of them (bodies, particle count,
// saving and loading named per-particle fields). A derived module adds its physics.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "driver/module.hpp"
#include "driver/registry.hpp"
#include "driver/scene_geometry.hpp"
#include "driver/state_reader.hpp"
#include "expression/expression.hpp"

namespace cosph {

template <int D>
class StaticBodyModule : public Module {
 public:
  // `key` is the module's scene key under modules[i] (e.g. "monodomain"); `body` its body spec.
  StaticBodyModule(const proto::ModuleSpec& spec, const ModuleContext& context,
                   const std::string& key, const proto::BodySpec& body)
      : name_(spec.name()),
        key_(context.key_path + "." + key),
        scene_(*context.scene),
        scene_directory_(context.scene_directory),
        body_spec_(body),
        particles_(body.name().empty() ? spec.name() : body.name()),
        kernel_(build_kernel(body, D)),
        domain_(build_domain<D>(*context.scene)) {}

  double time() const override { return time_; }
  std::size_t particle_count() const override { return particles_.size(); }

  void bodies(BodyViews& views) const override {
    BodyView<D> view{name_, &particles_, kernel_, domain_};
    if constexpr (D == 2)
      views.bodies2.push_back(view);
    else
      views.bodies3.push_back(view);
  }

 protected:
  // Builds the body's particles ("position", "volume"), sorted by cell once.
  void build_body() {
    build_static_body<D>(scene_, body_spec_, key_ + ".body", scene_directory_, kernel_, particles_,
                         &faces_, &cells_);
  }

  // Parses a scene expression; its errors become ConfigErrors at `key`.
  static Expression parse_expression(const std::string& text,
                                     const std::vector<std::string>& variables,
                                     const std::string& key) {
    try {
      return Expression::parse(text, variables);
    } catch (const ExpressionError& e) {
      throw ConfigError(key, e.what());
    }
  }

  // x, y, z (zero beyond D) and t, the variables of space-time expressions.
  static std::array<double, 4> space_time(const Vec<D>& x, double t) {
    std::array<double, 4> p{0.0, 0.0, 0.0, t};
    for (int a = 0; a < D; ++a) p[a] = x[a];
    return p;
  }

  // Saves the named scalar fields, time and steps.
  void save_state(StateRecord& state, const std::vector<std::string>& fields) const {
    for (const auto& f : fields) state.arrays[f] = particles_.scalar(f);
    state.scalars["time"] = time_;
    state.integers["steps"] = steps_;
  }

  // Loads them back, refusing a record of another size.
  void load_state(const StateRecord& state, const std::vector<std::string>& fields) {
    const StateReader read(state, "module '" + name_ + "'");
    for (const auto& f : fields) particles_.scalar(f) = read.array(f, particles_.size());
    time_ = read.scalar("time");
    steps_ = read.integer("steps");
  }

  // Copies one scalar field into a port buffer, or from one (checking its shape).
  void write_scalar_port(const std::string& field, FieldBuffer& out) const {
    out.points = particles_.size();
    out.arrays.clear();
    out.arrays[field] = {1, particles_.scalar(field)};
  }
  void read_scalar_port(const std::string& port, const std::string& field, const FieldBuffer& in) {
    auto it = in.arrays.find(field);
    if (it == in.arrays.end() || in.points != particles_.size() || it->second.components != 1 ||
        it->second.values.size() != in.points)
      throw RuntimeError("module '" + name_ + "': port '" + port +
                         "' got a buffer of another shape");
    particles_.scalar(field) = it->second.values;
  }

  std::string name_, key_;
  const proto::Scene& scene_;
  std::string scene_directory_;
  proto::BodySpec body_spec_;
  ParticleSet<D> particles_;
  std::vector<BoundaryFace<D>> faces_;  // the placement's exact faces, if it knows them
  std::vector<CellMoments<D>> cells_;   // the particles' cells, if the placement knows them
  Kernel kernel_;
  Domain<D> domain_;
  double time_ = 0.0;
  long long steps_ = 0;
};

}  // namespace cosph
