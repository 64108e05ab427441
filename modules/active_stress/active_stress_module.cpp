#include "active_stress/active_stress_module.hpp"

#include "active_stress/active_stress_law.hpp"
#include "core/parallel.hpp"
#include "driver/static_body_module.hpp"

namespace cosph {
namespace {

template <int D>
class ActiveStressModule final : public StaticBodyModule<D> {
  using Base = StaticBodyModule<D>;
  using Base::key_;
  using Base::name_;
  using Base::particles_;
  using Base::steps_;
  using Base::time_;

 public:
  ActiveStressModule(const proto::ModuleSpec& spec, const ModuleContext& context)
      : Base(spec, context, "active_stress", spec.active_stress().body()),
        spec_(spec.active_stress()) {
    if (spec_.law_case() == proto::ActiveStressSpec::LAW_NOT_SET)
      throw ConfigError(key_, "give the law: ode or prescribed");
    if (spec_.has_prescribed())
      law_ = Base::parse_expression(spec_.prescribed(), {"V", "x", "y", "z", "t"},
                                    key_ + ".prescribed");
    if (spec_.has_voltage())
      voltage_ = Base::parse_expression(spec_.voltage(), {"x", "y", "z", "t"}, key_ + ".voltage");
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
    Base::build_body();
    particles_.add_scalar("voltage", {.output = true, .checkpoint = true, .exchange = true});
    auto& T = particles_.add_scalar("active_stress",
                                    {.output = true, .checkpoint = true, .exchange = true});
    std::fill(T.begin(), T.end(), spec_.initial());
    update_voltage();
    if (spec_.has_prescribed()) update_prescribed();
  }

  double max_dt() const override { return spec_.has_ode() ? spec_.time_step() : INFINITY; }

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
    Base::write_scalar_port("active_stress", out);
  }

  void read(const std::string& port, const FieldBuffer& in) override {
    if (port != "voltage")
      throw RuntimeError("module '" + name_ + "' reads only the port 'voltage'");
    if (spec_.has_voltage())
      throw RuntimeError("module '" + name_ +
                         "': its voltage is prescribed by the scene; it reads no port");
    Base::read_scalar_port(port, "voltage", in);
  }

  void save(StateRecord& state) const override {
    Base::save_state(state, {"active_stress", "voltage"});
  }
  void load(const StateRecord& state) override {
    Base::load_state(state, {"active_stress", "voltage"});
  }

 private:
  void update_voltage() {
    if (!spec_.has_voltage()) return;
    auto& V = particles_.scalar("voltage");
    const auto& x = particles_.vector("position");
    parallel_for_each_index(
        V.size(), [&](std::size_t i) { V[i] = voltage_.evaluate(Base::space_time(x[i], time_)); });
  }

  void update_prescribed() {
    auto& T = particles_.scalar("active_stress");
    const auto& V = particles_.scalar("voltage");
    const auto& x = particles_.vector("position");
    parallel_for_each_index(T.size(), [&](std::size_t i) {
      const auto p = Base::space_time(x[i], time_);
      T[i] = law_.evaluate({V[i], p[0], p[1], p[2], p[3]});
    });
  }

  proto::ActiveStressSpec spec_;
  Expression law_, voltage_;
};

}  // namespace

std::unique_ptr<Module> make_active_stress_module(const proto::ModuleSpec& spec,
                                                  const ModuleContext& context) {
  if (context.scene->dimension() == 2)
    return std::make_unique<ActiveStressModule<2>>(spec, context);
  return std::make_unique<ActiveStressModule<3>>(spec, context);
}

}  // namespace cosph
