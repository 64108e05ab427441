#include "monodomain/monodomain_module.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "driver/static_body_module.hpp"
#include "geometry/regions.hpp"
#include "monodomain/ionic_model.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "operators/diffusion_operator.hpp"

namespace cosph {
namespace {

const std::vector<std::string> kSpaceVariables = {"x", "y", "z"};

template <int D>
class MonodomainModule final : public StaticBodyModule<D> {
  using Base = StaticBodyModule<D>;
  using Base::domain_;
  using Base::kernel_;
  using Base::key_;
  using Base::name_;
  using Base::particles_;
  using Base::steps_;
  using Base::time_;

 public:
  MonodomainModule(const proto::ModuleSpec& spec, const ModuleContext& context)
      : Base(spec, context, "monodomain", spec.monodomain().body()), spec_(spec.monodomain()) {
    try {
      model_ = make_ionic_model(spec_.ionic_model());
    } catch (const std::invalid_argument& e) {
      throw ConfigError(key_ + ".ionic_model", e.what());
    }
  }

  ModuleInfo info() const override {
    ModuleInfo info;
    info.type = "monodomain";
    info.name = name_;
    info.writes = {{"voltage", {"voltage"}}};
    info.reads = {{"voltage", {"voltage"}}};
    info.active_features.push_back("ionic model " + model_->name());
    info.active_features.push_back(spec_.fibre_diffusivity() > 0.0 ? "anisotropic diffusion"
                                                                   : "isotropic diffusion");
    info.active_features.push_back("kernel " + kernel_name(kernel_.type()));
    if (spec_.kernel_correction()) info.active_features.push_back("kernel correction");
    if (!stimuli_.empty()) info.active_features.push_back("stimuli");
    if (spec_.output_millivolts()) info.active_features.push_back("output in mV");
    return info;
  }

  void initialize() override {
    Base::build_body();
    const auto& x = particles_.vector("position");
    const auto& volume = particles_.scalar("volume");
    const FieldFlags state{.output = true, .checkpoint = true, .exchange = true};
    auto& V = particles_.add_scalar("voltage", state);
    auto& w = particles_.add_scalar("gate", {.output = true, .checkpoint = true});
    auto& activation =
        particles_.add_scalar("activation_time", {.output = true, .checkpoint = true});
    if (spec_.output_millivolts()) particles_.add_scalar("voltage_mV", {.output = true});

    const Expression v0 = parse(spec_.initial_voltage(), key_ + ".initial_voltage");
    const Expression w0 = parse(spec_.initial_gate(), key_ + ".initial_gate");
    for (std::size_t i = 0; i < x.size(); ++i) {
      const auto p = point(x[i]);
      V[i] = v0.evaluate(p);
      w[i] = w0.evaluate(p);
      activation[i] = V[i] >= spec_.activation_threshold() ? 0.0 : -1.0;  // -1: not activated
    }

    for (int k = 0; k < spec_.stimuli_size(); ++k) {
      const auto& s = spec_.stimuli(k);
      const std::string path = key_ + ".stimuli[" + std::to_string(k) + "]";
      auto shape = build_shape<D>(s.region().shape(), path + ".region.shape");
      Stimulus stimulus{select_region<D>(x, *shape), s.value(), s.start(),
                        s.start() + s.duration()};
      if (stimulus.particles.empty())
        throw ConfigError(path + ".region", "the region contains no particle");
      stimuli_.push_back(std::move(stimulus));
    }
    apply_stimuli();

    std::vector<Mat<D>> tensors(x.size(), spec_.diffusivity() * Mat<D>::Identity());
    if (spec_.fibre_diffusivity() > 0.0) {
      const bool constant = spec_.fibre_size() > 0, field = spec_.fibre_field_size() > 0;
      if (constant == field)
        throw ConfigError(key_ + ".fibre", "fibre_diffusivity needs either fibre or fibre_field");
      std::vector<Expression> components;
      for (int a = 0; a < spec_.fibre_field_size(); ++a)
        components.push_back(
            parse(spec_.fibre_field(a), key_ + ".fibre_field[" + std::to_string(a) + "]"));
      const Vec<D> constant_fibre = to_vec<D>(spec_.fibre());
      for (std::size_t i = 0; i < x.size(); ++i) {
        Vec<D> f = constant_fibre;
        if (field)
          for (int a = 0; a < D; ++a) f[a] = components[a].evaluate(point(x[i]));
        if (!(f.norm() > 0.0) || !f.allFinite()) {
          std::ostringstream msg;
          msg << "fibre direction is zero or not finite at (" << x[i].transpose() << ")";
          throw ConfigError(key_ + (field ? ".fibre_field" : ".fibre"), msg.str());
        }
        f.normalize();
        tensors[i] += spec_.fibre_diffusivity() * f * f.transpose();
      }
    }
    neighbours_ = build_inner_list<D>(x, kernel_.support_radius(), domain_);
    try {
      diffusion_.setup(x, volume, neighbours_, kernel_, domain_, tensors, spec_.kernel_correction(),
                       spec_.time_step_factor(), ExplicitDiffusion<D>::Limit::Stable);
    } catch (const RuntimeError& e) {
      throw RuntimeError("module '" + name_ + "': " + e.what());
    }
    max_dt_ = spec_.has_time_step() ? spec_.time_step() : diffusion_.stable_dt();
    reaction_limit_ = reaction_step_limit(*model_);
    previous_.resize(x.size());
    update_derived();
  }

  double max_dt() const override { return max_dt_; }

  void advance(double dt) override {
    auto& V = particles_.scalar("voltage");
    auto& w = particles_.scalar("gate");
    auto& activation = particles_.scalar("activation_time");
    const double threshold = spec_.activation_threshold();
    // Each reaction half step in equal sub-steps no longer than the model's limit (one where
    // the diffusion limit is the shorter, as in every example).
    const int cuts = std::max(1, static_cast<int>(std::ceil(0.5 * dt / reaction_limit_)));
    const double half = 0.5 * dt / cuts;
    const double t_end = time_ + dt;
    // Three passes: the first reaction half steps (local), the diffusion rate (gather), then the
    // diffusion update fused with the second reaction half steps and the activation record.
    parallel_for_each_index(V.size(), [&](std::size_t i) {
      previous_[i] = V[i];
      for (int k = 0; k < cuts; ++k) react_before_diffusion(*model_, V[i], w[i], half);
    });
    const std::vector<double>& rate = diffusion_.rate(V);
    parallel_for_each_index(V.size(), [&](std::size_t i) {
      V[i] += dt * rate[i];
      for (int k = 0; k < cuts; ++k) react_after_diffusion(*model_, V[i], w[i], half);
      // Activation time: the first upward crossing of the threshold, interpolated in time.
      if (activation[i] < 0.0 && V[i] >= threshold) {
        const double before = previous_[i];
        const double fraction =
            V[i] > before ? std::clamp((threshold - before) / (V[i] - before), 0.0, 1.0) : 1.0;
        activation[i] = t_end - dt + fraction * dt;
      }
    });
    time_ = t_end;
    ++steps_;
    apply_stimuli();
    update_derived();
  }

  void write(const std::string& port, FieldBuffer& out) const override {
    check_port(port);
    Base::write_scalar_port("voltage", out);
  }

  void read(const std::string& port, const FieldBuffer& in) override {
    check_port(port);
    Base::read_scalar_port(port, "voltage", in);
  }

  void save(StateRecord& state) const override { Base::save_state(state, kStateFields); }

  void load(const StateRecord& state) override {
    Base::load_state(state, kStateFields);
    update_derived();
  }

  std::optional<HealthProblem> check_health() const override {
    double vmin = model_->voltage_min(), vmax = model_->voltage_max();
    for (const auto& s : stimuli_) {
      vmin = std::min(vmin, s.value);
      vmax = std::max(vmax, s.value);
    }
    const auto& V = particles_.scalar("voltage");
    const auto& w = particles_.scalar("gate");
    for (std::size_t i = 0; i < V.size(); ++i) {
      if (V[i] < vmin || V[i] > vmax) return problem("voltage", i, V[i], vmin, vmax);
      if (w[i] < model_->gate_min() || w[i] > model_->gate_max())
        return problem("gate", i, w[i], model_->gate_min(), model_->gate_max());
    }
    return std::nullopt;
  }

 private:
  struct Stimulus {
    std::vector<Index> particles;
    double value, start, end;
  };

  static Expression parse(const std::string& text, const std::string& key) {
    return Base::parse_expression(text, kSpaceVariables, key);
  }

  static std::array<double, 3> point(const Vec<D>& x) {
    const auto p = Base::space_time(x, 0.0);
    return {p[0], p[1], p[2]};
  }

  HealthProblem problem(const std::string& quantity, std::size_t i, double value, double lo,
                        double hi) const {
    std::ostringstream expected;
    expected << "within [" << lo << ", " << hi << "] (" << model_->name() << " physical range)";
    return {quantity, static_cast<long long>(i), value, expected.str()};
  }

  void apply_stimuli() {
    auto& V = particles_.scalar("voltage");
    for (const auto& s : stimuli_)
      if (time_ >= s.start && time_ < s.end)
        for (Index i : s.particles) V[i] = s.value;
  }

  void update_derived() {
    if (!spec_.output_millivolts()) return;
    const auto& V = particles_.scalar("voltage");
    auto& E = particles_.scalar("voltage_mV");
    for (std::size_t i = 0; i < V.size(); ++i)
      E[i] = 100.0 * V[i] - 80.0;  // Aliev-Panfilov scaling
  }

  void check_port(const std::string& port) const {
    if (port != "voltage")
      throw RuntimeError("module '" + name_ + "' has no port '" + port + "' (it has 'voltage')");
  }

  inline static const std::vector<std::string> kStateFields = {"voltage", "gate",
                                                               "activation_time"};
  proto::MonodomainSpec spec_;
  std::unique_ptr<IonicModel> model_;
  NeighbourList neighbours_;
  ExplicitDiffusion<D> diffusion_;
  std::vector<Stimulus> stimuli_;
  std::vector<double> previous_;
  double max_dt_ = 0.0;
  double reaction_limit_ = INFINITY;  // reaction_step_limit(*model_)
};

}  // namespace

std::unique_ptr<Module> make_monodomain_module(const proto::ModuleSpec& spec,
                                               const ModuleContext& context) {
  if (context.scene->dimension() == 2) return std::make_unique<MonodomainModule<2>>(spec, context);
  return std::make_unique<MonodomainModule<3>>(spec, context);
}

}  // namespace cosph
