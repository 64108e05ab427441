#include "diffusion/diffusion_module.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "driver/state_reader.hpp"
#include "driver/static_body_module.hpp"
#include "geometry/regions.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "operators/diffusion_operator.hpp"

namespace cosph {
namespace {

const std::vector<std::string> kSpaceTimeVariables = {"x", "y", "z", "t"};

template <int D>
class DiffusionModule final : public StaticBodyModule<D> {
  using Base = StaticBodyModule<D>;
  using Base::domain_;
  using Base::kernel_;
  using Base::key_;
  using Base::name_;
  using Base::particles_;
  using Base::steps_;
  using Base::time_;

 public:
  DiffusionModule(const proto::ModuleSpec& spec, const ModuleContext& context)
      : Base(spec, context, "diffusion", spec.diffusion().body()), spec_(spec.diffusion()) {}

  ModuleInfo info() const override {
    ModuleInfo info;
    info.type = "diffusion";
    info.name = name_;
    info.reads = {{spec_.field(), {spec_.field()}}};
    info.writes = {{spec_.field(), {spec_.field()}}};
    info.active_features.push_back(spec_.has_anisotropy() ? "anisotropic diffusion"
                                                          : "isotropic diffusion");
    info.active_features.push_back("kernel " + kernel_name(kernel_.type()));
    if (spec_.kernel_correction()) info.active_features.push_back("kernel correction");
    if (!fixed_.empty()) info.active_features.push_back("fixed values");
    if (spec_.has_time_step()) info.active_features.push_back("fixed time step");
    return info;
  }

  void initialize() override {
    const bool has_iso = spec_.has_diffusivity(), has_aniso = spec_.has_anisotropy();
    if (has_iso == has_aniso) throw ConfigError(key_, "give either diffusivity or anisotropy");
    const Mat<D> tensor = diffusion_tensor();

    Base::build_body();
    const auto& x = particles_.vector("position");
    const auto& V = particles_.scalar("volume");
    auto& c = particles_.add_scalar(spec_.field(),
                                    {.output = true, .checkpoint = true, .exchange = true});

    const Expression initial =
        Base::parse_expression(spec_.initial(), kSpaceTimeVariables, key_ + ".initial");
    for (std::size_t i = 0; i < x.size(); ++i) {
      c[i] = initial.evaluate(Base::space_time(x[i], 0.0));
    }

    for (int k = 0; k < spec_.fixed_values_size(); ++k) {
      const std::string path = key_ + ".fixed_values[" + std::to_string(k) + "]";
      const auto& fv = spec_.fixed_values(k);
      auto shape = build_shape<D>(fv.region().shape(), path + ".region.shape");
      Fixed fixed{select_region<D>(x, *shape),
                  Base::parse_expression(fv.value(), kSpaceTimeVariables, path + ".value")};
      if (fixed.particles.empty())
        throw ConfigError(path + ".region", "the region contains no particle");
      fixed_.push_back(std::move(fixed));
    }
    apply_fixed_values();

    neighbours_ = build_inner_list<D>(x, kernel_.support_radius(), domain_);
    const std::vector<Mat<D>> tensors(x.size(), tensor);
    try {
      diffusion_.setup(x, V, neighbours_, kernel_, domain_, tensors, spec_.kernel_correction(),
                       spec_.time_step_factor());
    } catch (const RuntimeError& e) {
      throw RuntimeError("module '" + name_ + "': " + e.what());
    }
    max_dt_ = spec_.has_time_step() ? spec_.time_step() : diffusion_.stable_dt();

    // Bounds for the health check: with positive weights and dt * sum_j w_ij <= 1 each step is a
    // convex combination, so c stays within the range of its initial and boundary values
    // (discrete maximum principle), and without fixed values sum_i V_i c_i^2 cannot grow.
    lower_ = *std::min_element(c.begin(), c.end());
    upper_ = *std::max_element(c.begin(), c.end());
    initial_energy_ = energy();
  }

  std::optional<HealthProblem> check_health() const override {
    const auto& c = particles_.scalar(spec_.field());
    const double tolerance = 1e-9 * std::max(1.0, upper_ - lower_);
    for (std::size_t i = 0; i < c.size(); ++i)
      if (c[i] < lower_ - tolerance || c[i] > upper_ + tolerance) {
        std::ostringstream expected;
        expected << "within [" << lower_ << ", " << upper_ << "] (discrete maximum principle)";
        return HealthProblem{spec_.field(), static_cast<long long>(i), c[i], expected.str()};
      }
    if (fixed_.empty()) {
      const double e = energy();
      if (e > initial_energy_ * (1.0 + 1e-9))
        return HealthProblem{"sum V " + spec_.field() + "^2", -1, e,
                             "at most its initial value " + std::to_string(initial_energy_) +
                                 " (diffusion dissipates)"};
    }
    return std::nullopt;
  }

  double max_dt() const override { return max_dt_; }

  void advance(double dt) override {
    diffusion_.step(particles_.scalar(spec_.field()), dt);
    time_ += dt;
    ++steps_;
    apply_fixed_values();
  }

  void write(const std::string& port, FieldBuffer& out) const override {
    check_port(port);
    Base::write_scalar_port(spec_.field(), out);
  }

  void read(const std::string& port, const FieldBuffer& in) override {
    check_port(port);
    Base::read_scalar_port(port, spec_.field(), in);
  }

  void save(StateRecord& state) const override {
    Base::save_state(state, {spec_.field()});
    state.scalars["lower_bound"] = lower_;
    state.scalars["upper_bound"] = upper_;
    state.scalars["initial_energy"] = initial_energy_;
  }

  void load(const StateRecord& state) override {
    Base::load_state(state, {spec_.field()});
    const StateReader read(state, "module '" + name_ + "'");
    lower_ = read.scalar("lower_bound");
    upper_ = read.scalar("upper_bound");
    initial_energy_ = read.scalar("initial_energy");
  }

 private:
  struct Fixed {
    std::vector<Index> particles;
    Expression value;
  };

  Mat<D> diffusion_tensor() const {
    if (spec_.has_diffusivity()) return spec_.diffusivity() * Mat<D>::Identity();
    const auto& a = spec_.anisotropy();
    Vec<D> f = to_vec<D>(a.direction());
    if (!(f.norm() > 0.0)) throw ConfigError(key_ + ".anisotropy.direction", "must not be zero");
    f.normalize();
    return a.across() * Mat<D>::Identity() + (a.along() - a.across()) * f * f.transpose();
  }

  void apply_fixed_values() {
    auto& c = particles_.scalar(spec_.field());
    const auto& x = particles_.vector("position");
    for (const auto& f : fixed_)
      for (Index i : f.particles) {
        c[i] = f.value.evaluate(Base::space_time(x[i], time_));
        // Boundary values widen the range the maximum principle allows.
        lower_ = std::min(lower_, c[i]);
        upper_ = std::max(upper_, c[i]);
      }
  }

  double energy() const {
    const auto& c = particles_.scalar(spec_.field());
    const auto& V = particles_.scalar("volume");
    return deterministic_sum(c.size(), 0.0, [&](std::size_t i) { return V[i] * c[i] * c[i]; });
  }

  void check_port(const std::string& port) const {
    if (port != spec_.field())
      throw RuntimeError("module '" + name_ + "' has no port '" + port + "' (it has '" +
                         spec_.field() + "')");
  }

  proto::DiffusionSpec spec_;
  NeighbourList neighbours_;
  ExplicitDiffusion<D> diffusion_;
  std::vector<Fixed> fixed_;
  double max_dt_ = 0.0;
  double lower_ = INFINITY, upper_ = -INFINITY, initial_energy_ = 0.0;
};

}  // namespace

std::unique_ptr<Module> make_diffusion_module(const proto::ModuleSpec& spec,
                                              const ModuleContext& context) {
  if (context.scene->dimension() == 2) return std::make_unique<DiffusionModule<2>>(spec, context);
  return std::make_unique<DiffusionModule<3>>(spec, context);
}

}  // namespace cosph
