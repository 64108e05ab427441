#include "active_stress/active_stress_module.hpp"

#include "active_stress/active_stress_law.hpp"
#include "core/error.hpp"
#include "core/parallel.hpp"
#include "driver/scene_geometry.hpp"
#include "expression/expression.hpp"

namespace cosph {
namespace {

template <int D>
class ActiveStressModule final : public Module {
 public:
  ActiveStressModule(const proto::ModuleSpec& spec, const ModuleContext& context)
      : name_(spec.name()),
        key_(context.key_path + ".active_stress"),
        spec_(spec.active_stress()),
        scene_(*context.scene),
        scene_directory_(context.scene_directory),
        particles_(spec.active_stress().body().name().empty() ? spec.name()
                                                              : spec.active_stress().body().name()),
        kernel_(build_kernel(spec.active_stress().body(), D)),
        domain_(build_domain<D>(*context.scene)) {
    if (spec_.law_case() == proto::ActiveStressSpec::LAW_NOT_SET)
      throw ConfigError(key_, "give the law: ode or prescribed");
    if (spec_.has_prescribed())
      law_ = parse(spec_.prescribed(), {"V", "x", "y", "z", "t"}, key_ + ".prescribed");
    if (spec_.has_voltage())
      voltage_ = parse(spec_.voltage(), {"x", "y", "z", "t"}, key_ + ".voltage");
  }

  ModuleInfo info() const override {
    ModuleInfo info;
    info.type = "active_stress";
    info.name = name_;
    info.reads = {{"voltage", {"voltage"}}};
    info.writes = {{"active_stress", {"active_stress"}}};
    info.active_features.push_back(spec_.has_ode() ? "active stress ODE (QSS)"
                                                   : "prescribed active stress");
    if (spec_.has_voltage()) info.active_features.push_back("prescribed voltage");
    return info;
  }

  void initialize() override {
    build_static_body<D>(scene_, spec_.body(), key_ + ".body", scene_directory_, kernel_,
                         particles_);
    particles_.add_scalar("voltage", {.output = true, .checkpoint = true, .exchange = true});
    auto& T = particles_.add_scalar("active_stress",
                                    {.output = true, .checkpoint = true, .exchange = true});
    std::fill(T.begin(), T.end(), spec_.initial());
    update_voltage();
    if (spec_.has_prescribed()) update_prescribed();
  }

  double max_dt() const override { return spec_.has_ode() ? spec_.time_step() : INFINITY; }
  double time() const override { return time_; }

  void advance(double dt) override {
    auto& T = particles_.scalar("active_stress");
    const auto& V = particles_.scalar("voltage");
    time_ += dt;
    if (spec_.has_ode()) {
      // V is the value read at the start of the step (operator splitting with the EP module).
      parallel_for_each_index(
          T.size(), [&](std::size_t i) { T[i] = active_stress_step(spec_.ode(), T[i], V[i], dt); });
      update_voltage();
    } else {
      update_voltage();
      update_prescribed();
    }
    ++steps_;
  }

  void write(const std::string& port, FieldBuffer& out) const override {
    if (port != "active_stress")
      throw RuntimeError("module '" + name_ + "' writes only the port 'active_stress'");
    out.points = particles_.size();
    out.arrays.clear();
    out.arrays["active_stress"] = {1, particles_.scalar("active_stress")};
  }

  void read(const std::string& port, const FieldBuffer& in) override {
    if (port != "voltage")
      throw RuntimeError("module '" + name_ + "' reads only the port 'voltage'");
    if (spec_.has_voltage())
      throw RuntimeError("module '" + name_ +
                         "': its voltage is prescribed by the scene; it reads no port");
    auto it = in.arrays.find("voltage");
    if (it == in.arrays.end() || in.points != particles_.size() || it->second.components != 1)
      throw RuntimeError("module '" + name_ + "': port 'voltage' got a buffer of another shape");
    particles_.scalar("voltage") = it->second.values;
  }

  void save(StateRecord& state) const override {
    state.arrays["active_stress"] = particles_.scalar("active_stress");
    state.arrays["voltage"] = particles_.scalar("voltage");
    state.scalars["time"] = time_;
    state.integers["steps"] = steps_;
  }

  void load(const StateRecord& state) override {
    for (const char* f : {"active_stress", "voltage"}) {
      auto it = state.arrays.find(f);
      if (it == state.arrays.end() || it->second.size() != particles_.size())
        throw RuntimeError("module '" + name_ + "': checkpoint does not match: expected " +
                           std::to_string(particles_.size()) + " values of '" + f + "'");
      particles_.scalar(f) = it->second;
    }
    time_ = state.scalars.at("time");
    steps_ = state.integers.at("steps");
  }

  void bodies(BodyViews& views) const override {
    BodyView<D> view{name_, &particles_, kernel_, domain_};
    if constexpr (D == 2)
      views.bodies2.push_back(view);
    else
      views.bodies3.push_back(view);
  }

  std::size_t particle_count() const override { return particles_.size(); }

 private:
  static Expression parse(const std::string& text, const std::vector<std::string>& variables,
                          const std::string& key) {
    try {
      return Expression::parse(text, variables);
    } catch (const ExpressionError& e) {
      throw ConfigError(key, e.what());
    }
  }

  void update_voltage() {
    if (!spec_.has_voltage()) return;
    auto& V = particles_.scalar("voltage");
    const auto& x = particles_.vector("position");
    parallel_for_each_index(V.size(), [&](std::size_t i) {
      std::array<double, 4> p{0.0, 0.0, 0.0, time_};
      for (int a = 0; a < D; ++a) p[a] = x[i][a];
      V[i] = voltage_.evaluate(p);
    });
  }

  void update_prescribed() {
    auto& T = particles_.scalar("active_stress");
    const auto& V = particles_.scalar("voltage");
    const auto& x = particles_.vector("position");
    parallel_for_each_index(T.size(), [&](std::size_t i) {
      std::array<double, 5> p{V[i], 0.0, 0.0, 0.0, time_};
      for (int a = 0; a < D; ++a) p[1 + a] = x[i][a];
      T[i] = law_.evaluate(p);
    });
  }

  std::string name_, key_;
  proto::ActiveStressSpec spec_;
  const proto::Scene& scene_;
  std::string scene_directory_;
  ParticleSet<D> particles_;
  Kernel kernel_;
  Domain<D> domain_;
  Expression law_, voltage_;
  double time_ = 0.0;
  long long steps_ = 0;
};

}  // namespace

std::unique_ptr<Module> make_active_stress_module(const proto::ModuleSpec& spec,
                                                  const ModuleContext& context) {
  if (context.scene->dimension() == 2)
    return std::make_unique<ActiveStressModule<2>>(spec, context);
  return std::make_unique<ActiveStressModule<3>>(spec, context);
}

}  // namespace cosph
