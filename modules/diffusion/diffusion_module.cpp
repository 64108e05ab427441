#include "diffusion/diffusion_module.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "driver/scene_geometry.hpp"
#include "expression/expression.hpp"
#include "geometry/regions.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "operators/diffusion_operator.hpp"

namespace cosph {
namespace {

const std::vector<std::string> kSpaceTimeVariables = {"x", "y", "z", "t"};

Expression parse_expression(const std::string& text, const std::vector<std::string>& variables,
                            const std::string& key_path) {
  try {
    return Expression::parse(text, variables);
  } catch (const ExpressionError& e) {
    throw ConfigError(key_path, e.what());
  }
}

template <int D>
class DiffusionModule final : public Module {
 public:
  DiffusionModule(const proto::ModuleSpec& spec, const ModuleContext& context)
      : name_(spec.name()),
        key_(context.key_path + ".diffusion"),
        spec_(spec.diffusion()),
        scene_(*context.scene),
        scene_directory_(context.scene_directory),
        particles_(spec.diffusion().body().name().empty() ? spec.name()
                                                          : spec.diffusion().body().name()),
        kernel_(build_kernel(spec.diffusion().body(), D)),
        domain_(build_domain<D>(*context.scene)) {}

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

    build_static_body<D>(scene_, spec_.body(), key_ + ".body", scene_directory_, kernel_,
                         particles_);
    const auto& x = particles_.vector("position");
    const auto& V = particles_.scalar("volume");
    auto& c = particles_.add_scalar(spec_.field(),
                                    {.output = true, .checkpoint = true, .exchange = true});

    const Expression initial =
        parse_expression(spec_.initial(), kSpaceTimeVariables, key_ + ".initial");
    for (std::size_t i = 0; i < x.size(); ++i) {
      const auto p = point(x[i], 0.0);
      c[i] = initial.evaluate(std::span<const double>(p.data(), p.size()));
    }

    for (int k = 0; k < spec_.fixed_values_size(); ++k) {
      const std::string path = key_ + ".fixed_values[" + std::to_string(k) + "]";
      const auto& fv = spec_.fixed_values(k);
      auto shape = build_shape<D>(fv.region().shape(), path + ".region.shape");
      Fixed fixed{select_region<D>(x, *shape),
                  parse_expression(fv.value(), kSpaceTimeVariables, path + ".value")};
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
  double time() const override { return time_; }

  void advance(double dt) override {
    diffusion_.step(particles_.scalar(spec_.field()), dt);
    time_ += dt;
    ++steps_;
    apply_fixed_values();
  }

  void write(const std::string& port, FieldBuffer& out) const override {
    check_port(port);
    out.points = particles_.size();
    out.arrays.clear();
    const auto& c = particles_.scalar(spec_.field());
    out.arrays[spec_.field()] = {1, c};
  }

  void read(const std::string& port, const FieldBuffer& in) override {
    check_port(port);
    auto it = in.arrays.find(spec_.field());
    if (it == in.arrays.end() || in.points != particles_.size() || it->second.components != 1)
      throw RuntimeError("module '" + name_ + "': port '" + port +
                         "' got a buffer of another shape");
    particles_.scalar(spec_.field()) = it->second.values;
  }

  void save(StateRecord& state) const override {
    state.arrays[spec_.field()] = particles_.scalar(spec_.field());
    state.scalars["lower_bound"] = lower_;
    state.scalars["upper_bound"] = upper_;
    state.scalars["initial_energy"] = initial_energy_;
    state.scalars["time"] = time_;
    state.integers["steps"] = steps_;
  }

  void load(const StateRecord& state) override {
    auto it = state.arrays.find(spec_.field());
    if (it == state.arrays.end() || it->second.size() != particles_.size())
      throw RuntimeError("module '" + name_ + "': checkpoint does not match: expected " +
                         std::to_string(particles_.size()) + " values of '" + spec_.field() + "'");
    particles_.scalar(spec_.field()) = it->second;
    time_ = state.scalars.at("time");
    lower_ = state.scalars.at("lower_bound");
    upper_ = state.scalars.at("upper_bound");
    initial_energy_ = state.scalars.at("initial_energy");
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

  static std::array<double, 4> point(const Vec<D>& x, double t) {
    std::array<double, 4> p{0.0, 0.0, 0.0, t};
    for (int a = 0; a < D; ++a) p[a] = x[a];
    return p;
  }

  void apply_fixed_values() {
    auto& c = particles_.scalar(spec_.field());
    const auto& x = particles_.vector("position");
    for (const auto& f : fixed_)
      for (Index i : f.particles) {
        const auto p = point(x[i], time_);
        c[i] = f.value.evaluate(std::span<const double>(p.data(), 4));
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

  std::string name_, key_;
  proto::DiffusionSpec spec_;
  const proto::Scene& scene_;
  std::string scene_directory_;
  ParticleSet<D> particles_;
  Kernel kernel_;
  Domain<D> domain_;
  NeighbourList neighbours_;
  ExplicitDiffusion<D> diffusion_;
  std::vector<Fixed> fixed_;
  double max_dt_ = 0.0, time_ = 0.0;
  double lower_ = INFINITY, upper_ = -INFINITY, initial_energy_ = 0.0;
  long long steps_ = 0;
};

}  // namespace

std::unique_ptr<Module> make_diffusion_module(const proto::ModuleSpec& spec,
                                              const ModuleContext& context) {
  if (context.scene->dimension() == 2) return std::make_unique<DiffusionModule<2>>(spec, context);
  return std::make_unique<DiffusionModule<3>>(spec, context);
}

}  // namespace cosph
