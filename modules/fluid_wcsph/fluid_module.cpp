#include "fluid_wcsph/fluid_module.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "driver/health_monitor.hpp"
#include "driver/scene_geometry.hpp"
#include "driver/state_reader.hpp"
#include "expression/expression.hpp"
#include "fluid_wcsph/boundary_set.hpp"
#include "fluid_wcsph/open_boundaries.hpp"
#include "fluid_wcsph/riemann.hpp"
#include "geometry/lattice.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {
namespace {

// Per advection step: neighbour lists (fluid-fluid, fluid-wall), density treatment, viscous and
// body forces, transport-velocity correction; then acoustic sub-steps of position-based Verlet
// (seed 003 section 7) until the advection step is covered: the first half moves half a step and
// updates the velocity with the Riemann pressure P*, the second half moves the other half and
// updates the density with the Riemann velocity U*.
template <int D>
class FluidModule final : public Module {
 public:
  FluidModule(const proto::ModuleSpec& spec, const ModuleContext& context)
      : name_(spec.name()),
        key_(context.key_path + ".fluid"),
        scene_(*context.scene),
        scene_directory_(context.scene_directory),
        spec_(spec.fluid()),
        kernel_(build_kernel(spec_.body(), D)),
        domain_(build_domain<D>(*context.scene)),
        fluid_(spec_.body().name().empty() ? spec.name() : spec_.body().name()),
        sound_speed_(sound_speed_of(spec_, key_)),
        walls_(name_ + "_walls"),
        contact_(name_ + "_contact"),
        open_(spec_, kernel_.support_radius(), sound_speed_, key_) {
    if (spec_.gravity_size() > 0) gravity_ = to_vec<D>(spec_.gravity());
    if (spec_.transport_velocity_hydrostatic_band() > 0.0 && gravity_.norm() == 0.0)
      throw ConfigError(key_ + ".transport_velocity_hydrostatic_band",
                        "a hydrostatic band needs gravity: without it no pressure marks the layer "
                        "under the free surface");
    if (has_output("wall_viscous_force") && !(spec_.viscosity() > 0.0))
      throw ConfigError(key_ + ".outputs",
                        "'wall_viscous_force' needs a viscous fluid: with viscosity 0 there is no "
                        "viscous term to split from wall_force");
    for (int a = 0; a < spec_.initial_velocity_size(); ++a)
      initial_velocity_.push_back(
          parse(spec_.initial_velocity(a), key_ + ".initial_velocity[" + std::to_string(a) + "]"));
    initial_pressure_ = parse(spec_.initial_pressure(), key_ + ".initial_pressure");
    for (int k = 0; k < spec_.walls_size(); ++k) {
      std::vector<Expression> velocity;
      for (int a = 0; a < spec_.walls(k).velocity_size(); ++a)
        velocity.push_back(parse_time(
            spec_.walls(k).velocity(a),
            key_ + ".walls[" + std::to_string(k) + "].velocity[" + std::to_string(a) + "]"));
      wall_velocity_.push_back(std::move(velocity));
    }
  }

  ModuleInfo info() const override {
    ModuleInfo info;
    info.type = "fluid";
    info.name = name_;
    info.dimension = D;
    info.spacing = spec_.body().spacing();
    // A coupler fills `contact` with another body's particles (position, velocity, volume and,
    // optionally, acceleration and mass: e.g. a solid's `particles`) and reads back the fluid's
    // force on each of them from `contact_force` (e.g. into the solid's `external_force`).
    info.reads = {{"contact", {"position", "velocity", "volume", "acceleration", "mass"}}};
    info.writes = {{"contact_force", {"force"}}};
    auto& f = info.active_features;
    f.push_back("weakly-compressible SPH, kernel " + kernel_name(kernel_.type()));
    f.push_back(spec_.riemann_solver() == "acoustic"          ? "acoustic Riemann solver"
                : spec_.riemann_solver() == "continuity_only" ? "Riemann solver, continuity only"
                                                              : "low-dissipation Riemann solver");
    f.push_back("density " + spec_.density_treatment());
    f.push_back(spec_.whole_acoustic_substeps()
                    ? "dual-criteria time stepping (whole acoustic sub-steps)"
                    : "dual-criteria time stepping");
    if (spec_.viscosity() > 0.0) f.push_back("viscosity");
    if (spec_.gravity_size() > 0) f.push_back("gravity");
    if (spec_.transport_velocity())
      f.push_back(
          "transport velocity (" + std::to_string(spec_.transport_velocity_sweeps()) + " sweeps" +
          (spec_.transport_velocity_free_surface() > 0.0 ? ", free surface left" : "") +
          (spec_.transport_velocity_hydrostatic_band() > 0.0 ? ", hydrostatic band left" : "") +
          ")");
    if (spec_.walls_size() > 0) f.push_back("walls (one-sided Riemann)");
    if (spec_.pressure_extension() == "clamped") f.push_back("pressure extension clamped at zero");
    for (const auto& o : open_.features()) f.push_back(o);
    if (domain_.any_periodic()) f.push_back("periodic");
    for (const auto& o : spec_.outputs()) f.push_back("output " + o);
    return info;
  }

  void initialize() override {
    // The fluid's particles move off any lattice at once; what they need is one mass each, so that
    // the density summation and its reinitialisation read rho0 in the bulk.
    if (lattice_placement(spec_.body()) != LatticePlacement::cell)
      throw ConfigError(
          key_ + ".body.placement",
          "the fluid needs equal particle volumes (placement: cell); vertex and conforming "
          "placements give their face, edge and corner particles fractions of a cell");
    const ParticleCloud<D> cloud = build_body<D>(spec_.body(), key_ + ".body", scene_directory_);
    check_body_cloud<D>(scene_, cloud, key_ + ".body");
    const std::size_t n = cloud.positions.size();
    fluid_.resize(n);
    auto& x = fluid_.add_vector("position", {.output = true, .checkpoint = true});
    auto& v = fluid_.add_vector("velocity", {.output = true, .checkpoint = true});
    auto& rho = fluid_.add_scalar("density", {.output = true, .checkpoint = true});
    auto& p = fluid_.add_scalar("pressure", {.output = true});
    auto& m = fluid_.add_scalar("mass", {.checkpoint = true});
    auto& volume = fluid_.add_scalar("volume");
    fluid_.add_scalar("density_rate", {.checkpoint = true});
    fluid_.add_vector("acceleration");
    if (has_output("vorticity")) {
      if constexpr (D == 2)
        fluid_.add_scalar("vorticity", {.output = true});
      else
        fluid_.add_vector("vorticity", {.output = true});
    }
    const double rho0 = spec_.density(), c2 = sound_speed_ * sound_speed_;
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = domain_.any_periodic() ? domain_.wrap(cloud.positions[i]) : cloud.positions[i];
      const auto point = space(x[i]);
      p[i] = initial_pressure_.evaluate(point);
      rho[i] = rho0 + p[i] / c2;
      m[i] = rho0 * cloud.volumes[i];
      volume[i] = m[i] / rho[i];
      for (int a = 0; a < D && !initial_velocity_.empty(); ++a)
        v[i][a] = initial_velocity_[a].evaluate(point);
    }
    open_.initialize(fluid_, 0.0);
    sort_by_cell();
    build_walls();
    reference_number_density_ = lattice_number_density();
    build_neighbours();
  }

  // The advection step follows the flow alone (dt = 0.25 h / max(|v|max, c/10)). Where viscosity
  // allows less (0.25 rho h^2 / eta), the viscous force is sub-cycled instead: applied at every
  // acoustic sub-step in as many split steps of at most viscous_dt as the sub-step needs
  // (apply_viscosity), while the neighbour lists and the density summation stay once per
  // advection step and the acoustic sub-step stays the sound speed's (or a contact body's
  // viscous limit, contact_viscous_dt). With whole_acoustic_substeps the step is rounded up to
  // a whole number of the acoustic sub-steps it would hold.
  double max_dt() const override {
    const double speed = max_speed();
    const double advection =
        spec_.advection_cfl() * kernel_.smoothing_length() / std::max(speed, 0.1 * sound_speed_);
    if (!spec_.whole_acoustic_substeps()) return advection;
    const double acoustic = acoustic_dt(speed, viscous_dt() < advection);
    return whole_substeps(advection, acoustic) * acoustic;
  }

  // The number of sub-steps of at most dt that cover span. The tolerance keeps a span of exactly
  // n sub-steps (max_dt's) at n, not n + 1 by round-off.
  static double whole_substeps(double span, double dt) {
    return std::ceil(span / dt * (1.0 - 1e-9));
  }

  double viscous_dt() const {
    if (!(spec_.viscosity() > 0.0)) return std::numeric_limits<double>::infinity();
    const double h = kernel_.smoothing_length();
    return spec_.advection_cfl() * h * h * spec_.density() / spec_.viscosity();
  }

  // One advection step, through the same stages a coupler drives (Module::begin_step).
  void advance(double Dt) override { advance_in_substeps(*this, Dt); }

  // Advection-step work: cell sort, neighbour lists and pair geometry (kept for the acoustic
  // sub-steps), density, viscous and body forces, transport-velocity shift.
  void begin_step(double Dt) override {
    if (steps_ > 0 && steps_ % kSortInterval == 0) sort_by_cell();
    build_neighbours();
    if (spec_.density_treatment() != "none") update_density_by_summation();
    step_size_ = Dt;
    step_done_ = 0.0;
    update_prior_acceleration();
    if (spec_.transport_velocity()) correct_transport_velocity();
  }

  // Whether the open advection step sub-cycles the viscous force (see max_dt).
  bool viscous_substeps() const { return viscous_dt() < step_size_; }

  // The acoustic step (dt = 0.6 h / (c + |v|max)), cut to what is left of the advection step;
  // with whole_acoustic_substeps, what is left split into equal sub-steps within the limit.
  double max_substep() const override {
    if (step_done_ >= step_size_ * (1.0 - 1e-12)) return 0.0;
    const double speed = max_speed();
    if (!(speed <= sound_speed_)) throw_supersonic(time_ + step_done_);
    const double dt = acoustic_dt(speed, viscous_substeps());
    const double left = step_size_ - step_done_;
    if (!spec_.whole_acoustic_substeps()) return std::min(dt, left);
    return left / whole_substeps(left, dt);
  }

  // The acoustic limit, and the contact body's viscous limit where the viscous force is
  // sub-cycled.
  double acoustic_dt(double speed, bool viscous_substeps) const {
    const double dt = spec_.acoustic_cfl() * kernel_.smoothing_length() / (sound_speed_ + speed);
    return viscous_substeps ? std::min(dt, contact_viscous_dt()) : dt;
  }

  // A contact body is handed the viscous force of an acoustic sub-step and answers only after it:
  // held that long against the fluid's shear, a body lighter than the fluid over-corrects its
  // velocity (a 500 kg/m^3 block in water of eta = 500 Pa s went non-finite with three split
  // steps per exchange). So the exchange interval keeps within the viscous limit with the
  // lightest contact particle's density in place of the fluid's, and never below the fluid's own
  // limit (what a sub-step was cut to before the viscous force was sub-cycled): the aluminium
  // plate (2.7 times water's density) keeps the sound speed's step.
  double contact_viscous_dt() const {
    return viscous_dt() * std::max(1.0, contact_density_ / spec_.density());
  }

  void substep(double dt) override {
    if (viscous_substeps()) apply_viscosity(time_ + step_done_, dt);
    pressure_relaxation(time_ + step_done_, dt);
    density_relaxation(time_ + step_done_, dt);
    if (walls_.records) accumulate_wall_impulse(dt);
    step_done_ += dt;
    ++acoustic_steps_;
  }

  // BoundarySet::pair_impulse of the walls: each sub-step's recorded pair forces times its length.
  void accumulate_wall_impulse(double dt) {
    auto& impulse = walls_.pair_impulse;
    const auto& pressure = walls_.pair_pressure_force;
    const auto& viscous = walls_.pair_viscous_force;
    auto& viscous_impulse = walls_.pair_viscous_impulse;
    const bool viscous_recorded = viscous.size() == impulse.size(),
               viscous_apart = viscous_recorded && viscous_impulse.size() == impulse.size();
    parallel_stream(impulse.size(), [&](std::size_t k) {
      impulse[k] += dt * (viscous_recorded ? Vec<D>(pressure[k] + viscous[k]) : pressure[k]);
      if (viscous_apart) viscous_impulse[k] += dt * viscous[k];
    });
    walls_.impulse_time += dt;
  }

  void end_step() override {
    if (open_.any()) open_.update(fluid_, time_ + step_size_);
    update_volumes();
    time_ += step_size_;
    ++steps_;
    step_size_ = step_done_ = 0.0;
  }

  double time() const override { return time_; }

  void prepare_output() override {
    if (walls_.particles.has("force"))
      walls_.particles.vector("force") = mean_recorded_force(walls_);
    if (walls_.particles.has("viscous_force"))
      walls_.particles.vector("viscous_force") =
          mean_pair_force(walls_, walls_.pair_viscous_impulse);
    if (fluid_.has("vorticity")) update_vorticity();
  }

  // The curl of the corrected velocity gradient grad v_i = G_i M_i^-1, with
  // G_i = sum_j V_j (v_j - v_i) (x) grad_i W_ij and M_i = sum_j V_j (x_j - x_i) (x) grad_i W_ij
  // (exact for linear velocity fields wherever M_i is invertible, the free surface included;
  // uncorrected, the bulk read 2.6% low at h = 1.3 dp). A particle whose neighbours do not span
  // the space (a lone drop: det M_i below 1e-3 of the full support's 1) keeps G_i alone. 2D: the
  // scalar dv_y/dx - dv_x/dy; 3D: the vector.
  void update_vorticity() {
    const auto& x = fluid_.vector("position");
    const auto& v = fluid_.vector("velocity");
    const auto& volume = fluid_.scalar("volume");
    const CellLinkedList<D> cells(x, kernel_.support_radius(), domain_);
    parallel_for_each_index(x.size(), [&](std::size_t i) {
      Mat<D> G = Mat<D>::Zero(), M = Mat<D>::Zero();
      cells.for_each_neighbour(x[i], kernel_.support_radius(), Index(i), [&](Index j) {
        const Vec<D> d = domain_.displacement(x[i], x[j]);  // x_i - x_j
        const double r = d.norm();
        if (!(r > 0.0)) return;
        const Vec<D> grad = kernel_.derivative(r) / r * d;  // grad_i W_ij
        G.noalias() += volume[j] * (v[j] - v[i]) * grad.transpose();
        M.noalias() -= volume[j] * d * grad.transpose();
      });
      const Mat<D> L = std::abs(M.determinant()) > 1e-3 ? Mat<D>(G * M.inverse()) : G;
      if constexpr (D == 2) {
        fluid_.scalar("vorticity")[i] = L(1, 0) - L(0, 1);
      } else {
        fluid_.vector("vorticity")[i] =
            Vec<3>(L(2, 1) - L(1, 2), L(0, 2) - L(2, 0), L(1, 0) - L(0, 1));
      }
    });
  }

  // The force of the fluid on each contact particle in its last acoustic sub-step (pressure) and
  // advection step (viscosity; the mean over the sub-step's split steps where the viscous force is
  // sub-cycled), recorded in the fluid's own pair loops: a coupler that applies it to the contact
  // body over that sub-step balances the impulse exactly.
  void write(const std::string& port, FieldBuffer& out) const override {
    if (port != "contact_force")
      throw RuntimeError("module '" + name_ + "' writes only the port 'contact_force'");
    const std::vector<Vec<D>> force = recorded_force(contact_);
    out.points = force.size();
    out.arrays.clear();
    auto& f = out.arrays["force"];
    f.components = D;
    for (const auto& v : force) f.values.insert(f.values.end(), v.data(), v.data() + D);
  }

  // Another body's particles as seen by the fluid until the next exchange.
  void read(const std::string& port, const FieldBuffer& in) override {
    if (port != "contact")
      throw RuntimeError("module '" + name_ + "' has no port '" + port + "' (it reads 'contact')");
    const std::size_t n = in.points;
    auto field = [&](const std::string& name, int components, bool required) {
      auto it = in.arrays.find(name);
      if (it == in.arrays.end()) {
        if (required)
          throw RuntimeError("module '" + name_ + "': port 'contact' needs '" + name + "'");
        return static_cast<const std::vector<double>*>(nullptr);
      }
      if (it->second.components != components || it->second.values.size() != n * components)
        throw RuntimeError("module '" + name_ + "': port 'contact': '" + name + "' needs " +
                           std::to_string(components) + " component(s) for each of " +
                           std::to_string(n) + " points");
      return &it->second.values;
    };
    const auto* position = field("position", D, true);
    const auto* velocity = field("velocity", D, true);
    const auto* volume = field("volume", 1, true);
    const auto* acceleration = field("acceleration", D, false);
    const auto* mass = field("mass", 1, false);
    for (std::size_t i = 0; i < n; ++i)
      if (!((*volume)[i] > 0.0))
        throw RuntimeError("module '" + name_ + "': port 'contact': volume of point " +
                           std::to_string(i) + " is not positive");
    auto& c = contact_.particles;
    // Inside an advection step the pair lists of the step index the contact set: it may move,
    // not change its size.
    if (step_size_ > 0.0 && n != c.size())
      throw RuntimeError("module '" + name_ + "': port 'contact': " + std::to_string(n) +
                         " points inside an advection step that began with " +
                         std::to_string(c.size()));
    if (!c.has("position")) {
      c.add_vector("position", {.output = true});
      c.add_vector("velocity", {.output = true});
      c.add_scalar("volume", {.output = true});
      c.add_vector("acceleration");
    }
    c.resize(n);
    auto& x = c.vector("position");
    auto& v = c.vector("velocity");
    auto& a = c.vector("acceleration");
    auto& V = c.scalar("volume");
    for (std::size_t i = 0; i < n; ++i) {
      V[i] = (*volume)[i];
      for (int d = 0; d < D; ++d) {
        x[i][d] = (*position)[i * D + d];
        v[i][d] = (*velocity)[i * D + d];
        a[i][d] = acceleration ? (*acceleration)[i * D + d] : 0.0;
      }
    }
    // The lightest contact particle's density (infinite without masses: a body that does not
    // yield).
    contact_density_ = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n && mass; ++i)
      contact_density_ = std::min(contact_density_, (*mass)[i] / (*volume)[i]);
    contact_.moves = true;    // its cell list is rebuilt at every advection step
    contact_.records = true;  // a coupler reads the force on it back
    contact_.cells.reset();
  }

  void save(StateRecord& state) const override {
    for (const std::string& f : checkpointed()) {
      const auto raw = fluid_.raw(f);
      state.arrays[f].assign(raw.begin(), raw.end());
    }
    // Moved walls are where the motion took them, with the velocity and acceleration of their
    // last sub-step (a restart continues bit for bit).
    if (walls_.moves)
      for (const char* f : {"position", "velocity", "acceleration"}) {
        const auto raw = walls_.particles.raw(f);
        state.arrays[std::string("wall_") + f].assign(raw.begin(), raw.end());
      }
    state.scalars["time"] = time_;
    state.integers["steps"] = steps_;
    state.integers["acoustic_steps"] = acoustic_steps_;
  }

  void load(const StateRecord& state) override {
    // Open boundaries change the particle count: the checkpoint's count is the one to restore.
    if (auto it = state.arrays.find("mass"); it != state.arrays.end())
      fluid_.resize(it->second.size());
    const StateReader read(state, "module '" + name_ + "'");
    for (const std::string& f : checkpointed()) {
      auto raw = fluid_.raw(f);
      const auto& saved = read.array(f, raw.size());
      std::copy(saved.begin(), saved.end(), raw.begin());
    }
    if (walls_.moves) {
      for (const char* f : {"position", "velocity", "acceleration"}) {
        auto raw = walls_.particles.raw(f);
        const auto& saved = read.array(std::string("wall_") + f, raw.size());
        std::copy(saved.begin(), saved.end(), raw.begin());
      }
      walls_.cells.reset();
    }
    time_ = read.scalar("time");
    steps_ = read.integer("steps");
    acoustic_steps_ = read.integer("acoustic_steps");
    update_pressure();
    update_volumes();
  }

  void bodies(BodyViews& views) const override {
    BodyView<D> fluid{name_, &fluid_, kernel_, domain_};
    BodyView<D> walls{name_, &walls_.particles, kernel_, domain_};
    if constexpr (D == 2) {
      views.bodies2.push_back(fluid);
      if (!walls_.empty()) views.bodies2.push_back(walls);
    } else {
      views.bodies3.push_back(fluid);
      if (!walls_.empty()) views.bodies3.push_back(walls);
    }
  }
  std::size_t particle_count() const override { return fluid_.size() + walls_.particles.size(); }

  // Weak compressibility: the density stays within 30% of rho0 (a healthy run stays within a
  // few percent; beyond this the sound speed is too low for the flow).
  std::optional<HealthProblem> check_health() const override {
    const auto& rho = fluid_.scalar("density");
    const double rho0 = spec_.density();
    for (std::size_t i = 0; i < rho.size(); ++i)
      if (!(rho[i] > 0.7 * rho0 && rho[i] < 1.3 * rho0))
        return HealthProblem{"density", static_cast<long long>(i), rho[i],
                             "within 30% of rho0 (weakly compressible)"};
    return std::nullopt;
  }

 private:
  static constexpr long long kSortInterval = 100;
  // Split steps of the viscous force in one acoustic sub-step beyond which the viscosity is not a
  // physical choice but a broken scene (a stiff case takes a few: the hydrostatic plate 2).
  static constexpr double kMaxViscousSplits = 1e6;

  static double sound_speed_of(const proto::FluidSpec& spec, const std::string& key) {
    if (spec.has_sound_speed()) return spec.sound_speed();
    if (spec.has_max_velocity()) return 10.0 * spec.max_velocity();
    throw ConfigError(key, "give max_velocity (the sound speed is 10 U_max) or sound_speed");
  }

  static Expression parse(const std::string& text, const std::string& key) {
    try {
      return Expression::parse(text, {"x", "y", "z"});
    } catch (const ExpressionError& e) {
      throw ConfigError(key, e.what());
    }
  }
  std::vector<std::string> checkpointed() const {
    std::vector<std::string> f{"position", "velocity", "density", "density_rate", "mass"};
    if (open_.has_inflow()) f.push_back("in_buffer");
    return f;
  }
  static Expression parse_time(const std::string& text, const std::string& key) {
    try {
      return Expression::parse(text, {"t"});
    } catch (const ExpressionError& e) {
      throw ConfigError(key, e.what());
    }
  }
  static std::array<double, 3> space(const Vec<D>& x) {
    std::array<double, 3> p{0.0, 0.0, 0.0};
    for (int a = 0; a < D; ++a) p[a] = x[a];
    return p;
  }
  bool has_output(const std::string& name) const {
    return std::find(spec_.outputs().begin(), spec_.outputs().end(), name) != spec_.outputs().end();
  }

  double max_speed() const {
    const auto& v = fluid_.vector("velocity");
    double s = 0.0;
    for (const auto& u : v) s = std::max(s, u.squaredNorm());
    return std::sqrt(s);
  }

  // A particle at or past the sound speed (or not finite): the weakly compressible scheme no
  // longer holds, and the acoustic step, 0.6 h / (c + |v|), would shrink without bound inside
  // one advection step. Checked at every sub-step (the health monitor runs every few steps),
  // from the maximum the step size needs anyway.
  [[noreturn]] void throw_supersonic(double t) const {
    const auto& v = fluid_.vector("velocity");
    const auto& x = fluid_.vector("position");
    std::size_t worst = 0;
    for (std::size_t i = 0; i < v.size(); ++i)
      if (!(v[i].norm() <= v[worst].norm())) worst = i;
    std::ostringstream position;
    position << x[worst].transpose();
    std::ostringstream expected;
    expected << "below the sound speed " << sound_speed_
             << " (past it the weakly compressible scheme does not hold: if the flow is meant to "
                "be this fast, raise max_velocity or sound_speed)";
    throw HealthError(health_failure_message(
        {std::nullopt, t, name_, fluid_.name(), position.str()},
        {"speed", static_cast<long long>(worst), v[worst].norm(), expected.str()}));
  }

  RiemannSolver riemann() const {
    const std::string& kind = spec_.riemann_solver();
    return {spec_.density() * sound_speed_, sound_speed_,
            kind == "acoustic"          ? MomentumDissipation::acoustic
            : kind == "continuity_only" ? MomentumDissipation::none
                                        : MomentumDissipation::limited};
  }

  // At a slip wall with its own normals the Riemann pressure is the one-sided problem's acoustic
  // solution, P* = (p_i + p_w) / 2 + rho0 c (v_i - v_w) . n_w (Joukowsky's water hammer): the
  // low-dissipation limiter removes the velocity-jump term between fluid particles because there
  // it acts on shear too, but along the wall's normal there is no shear for it to damp. A scene
  // without momentum dissipation keeps none at its walls.
  RiemannSolver slip_wall_riemann() const {
    return {spec_.density() * sound_speed_, sound_speed_,
            spec_.riemann_solver() == "continuity_only" ? MomentumDissipation::none
                                                        : MomentumDissipation::acoustic};
  }

  // A slip wall pair's Riemann pressure as a vector (the pair's force on i is -2 V_i V_w |dW|
  // times it): the mean pressure along e_iw, and the acoustic dissipation of the velocity jump
  // along the wall particle's own normal n_w, along n_w weighted by max(e_iw . n_w, 0) (a flat
  // wall's pairs then sum to its normal whatever the fluid particle's place along the wall
  // lattice; a pair behind n_w would be anti-dissipative).
  static Vec<D> own_normal_pressure(const RiemannSolver& acoustic, const Vec<D>& n, const Vec<D>& e,
                                    double p_i, const Vec<D>& v_i, const OneSidedState<D>& wall) {
    const double mean = 0.5 * (p_i + wall.pressure);
    const double P = acoustic.pressure(p_i, wall.pressure, v_i.dot(n), wall.velocity.dot(n));
    return mean * e + ((P - mean) * std::max(e.dot(n), 0.0)) * n;
  }

  void sort_by_cell() {
    const auto order =
        cell_sort_order<D>(fluid_.vector("position"), kernel_.support_radius(), domain_);
    fluid_.permute(order);
  }

  void build_walls() {
    const double dp = spec_.body().spacing();
    std::vector<Vec<D>> x;
    std::vector<double> volume;
    std::vector<int> owner;
    for (int k = 0; k < spec_.walls_size(); ++k) {
      const auto& w = spec_.walls(k);
      const std::string path = key_ + ".walls[" + std::to_string(k) + "]";
      auto shape = build_shape<D>(w.shape(), path + ".shape");
      Vec<D> anchor = w.lattice_anchor_size() > 0 ? to_vec<D>(w.lattice_anchor())
                      : spec_.body().lattice_anchor_size() > 0
                          ? to_vec<D>(spec_.body().lattice_anchor())
                          : Vec<D>(Vec<D>::Zero());
      ParticleCloud<D> cloud;
      try {
        cloud = lattice_fill<D>(*shape, dp, anchor);
      } catch (const std::invalid_argument& e) {
        throw ConfigError(path + ".shape", e.what());
      }
      check_body_cloud<D>(scene_, cloud, path + ".shape");
      for (std::size_t i = 0; i < cloud.positions.size(); ++i) {
        x.push_back(cloud.positions[i]);
        volume.push_back(cloud.volumes[i]);
        owner.push_back(k);
      }
    }
    auto& walls = walls_.particles;
    walls.resize(x.size());
    walls.add_vector("position", {.output = true}) = x;
    walls.add_scalar("volume", {.output = true}) = volume;
    walls.add_vector("velocity", {.output = true});
    if (has_output("wall_force")) walls.add_vector("force", {.output = true});
    if (has_output("wall_viscous_force")) walls.add_vector("viscous_force", {.output = true});
    wall_owner_ = owner;
    walls_.records = has_output("wall_force") || has_output("wall_viscous_force");
    for (const auto& w : wall_velocity_) walls_.moves = walls_.moves || !w.empty();
    if (walls_.moves) walls.add_vector("acceleration", {.output = true});
    update_wall_motion(0.0, 0.0);
  }

  // Velocity at t and, for moving walls, acceleration (a centred difference of the prescribed
  // velocity over `dt`, or over a small fixed interval at a restart): the pressure extension of
  // an accelerating wall uses g - a_w.
  void update_wall_motion(double t, double dt) {
    if (walls_.empty()) return;
    auto& v = walls_.particles.vector("velocity");
    auto* a =
        walls_.particles.has("acceleration") ? &walls_.particles.vector("acceleration") : nullptr;
    const double step = dt > 0.0 ? dt : 1e-6;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const auto& expressions = wall_velocity_[wall_owner_[i]];
      for (int c = 0; c < D; ++c) {
        if (expressions.empty()) {
          v[i][c] = 0.0;
          if (a) (*a)[i][c] = 0.0;
          continue;
        }
        v[i][c] = expressions[c].evaluate({t});
        if (a)
          (*a)[i][c] = (expressions[c].evaluate({t + 0.5 * step}) -
                        expressions[c].evaluate({t - 0.5 * step})) /
                       step;
      }
    }
  }

  // Moving walls move with their prescribed velocity over the acoustic sub-step [t, t + dt],
  // taken at its middle.
  void move_walls(double t, double dt) {
    if (!walls_.moves) return;
    update_wall_motion(t + 0.5 * dt, dt);
    auto& x = walls_.particles.vector("position");
    const auto& v = walls_.particles.vector("velocity");
    for (std::size_t i = 0; i < x.size(); ++i) x[i] += dt * v[i];
  }

  // sum_k dp^D W(|k| dp) over a full lattice: the number density of a particle with a complete
  // neighbourhood, the reference of the density summation.
  double lattice_number_density() const {
    const double dp = spec_.body().spacing(), support = kernel_.support_radius();
    const int reach = static_cast<int>(std::ceil(support / dp)) + 1;
    double sum = 0.0;
    std::array<int, D> k;
    k.fill(-reach);
    while (true) {
      Vec<D> r;
      for (int a = 0; a < D; ++a) r[a] = k[a] * dp;
      sum += std::pow(dp, D) * kernel_.value(r.norm());
      int a = 0;
      for (; a < D; ++a) {
        if (++k[a] <= reach) break;
        k[a] = -reach;
      }
      if (a == D) break;
    }
    return sum;
  }

  // Neighbour lists and, per pair, the unit vector e_ij (from i to j) and -dW/dr at the
  // configuration of the advection step. The acoustic sub-steps reuse them (as SPHinXsys does):
  // particles move less than a quarter smoothing length per advection step (under 0.25 h + 0.6 h
  // |v| / (c + |v|) with whole_acoustic_substeps).
  void build_neighbours() {
    const auto& x = fluid_.vector("position");
    inner_ = build_inner_list<D>(x, kernel_.support_radius(), domain_);
    pair_geometry(x, x, inner_, inner_geometry_);
    for (BoundarySet<D>* b : {&walls_, &contact_}) {
      if (b->empty()) continue;
      const auto& bx = b->particles.vector("position");
      // Static walls keep their cell list; moving walls and contact bodies rebuild it.
      if (!b->cells || b->moves) {
        b->cells.emplace(bx, kernel_.support_radius(), domain_);
        if (b == &walls_ && slip_walls()) own_normals(*b);
      }
      b->list = build_contact_list<D>(x, *b->cells, kernel_.support_radius());
      pair_geometry(x, bx, b->list, b->geometry);
      if (slip_walls() && b->own_normal.empty()) boundary_normals(*b);
      if (b->records) {
        build_pairs_of(*b);
        b->pair_pressure_force.assign(b->list.pair_count(), Vec<D>::Zero());
        if (spec_.viscosity() > 0.0)
          b->pair_viscous_force.assign(b->list.pair_count(), Vec<D>::Zero());
        if (b == &walls_) {  // the output's step mean (a contact body is handed each sub-step's)
          b->pair_impulse.assign(b->list.pair_count(), Vec<D>::Zero());
          if (b->particles.has("viscous_force"))  // only a viscous fluid has it (the constructor)
            b->pair_viscous_impulse.assign(b->list.pair_count(), Vec<D>::Zero());
          b->impulse_time = 0.0;
        }
      }
    }
  }

  // The velocity condition at walls and contact bodies follows the equations solved: an inviscid
  // fluid slips along them (the Euler equations constrain only the normal velocity), a viscous
  // one sticks. The Riemann dissipation sees the matching ghost state: for slip, the velocity
  // jump along the boundary's normal (seed 003 eq. 14, as SPHinXsys); for no-slip, the mirrored
  // velocity 2 v_w - v_i along each pair's direction, whose tangential part is a numerical wall
  // friction on top of the viscous term's (3.8% of the Poiseuille channel's wall shear at L/20).
  // The Re = 100 cylinder at D/10 / D/20, read as the step's impulse: C_D +31% / +13%, period
  // +9.3% / +2.3%, lift amplitude -33% / +8.0% with it; +41% / +16%, +13.6% / +3.8%, -10% / +4.8%
  // with the normal jump alone (docs/ARCHITECTURE.md).
  bool slip_walls() const { return !(spec_.viscosity() > 0.0); }

  // BoundarySet::own_normal: sum_w' V_w' (-dW/dr) e_ww' over the set's own particles, normalised.
  void own_normals(BoundarySet<D>& b) const {
    const auto& x = b.particles.vector("position");
    const auto& V = b.particles.scalar("volume");
    const NeighbourList list = build_inner_list<D>(x, kernel_.support_radius(), domain_);
    b.own_normal.assign(x.size(), Vec<D>::Zero());
    parallel_for_each_index(x.size(), [&](std::size_t w) {
      Vec<D> g = Vec<D>::Zero();
      for (std::size_t k = list.offset[w]; k < list.offset[w + 1]; ++k) {
        const Vec<D> d = domain_.displacement(x[list.index[k]], x[w]);
        const double r = d.norm();
        if (r > 0.0) g += (V[list.index[k]] * -kernel_.derivative(r) / r) * d;
      }
      // Relative to one particle's own gradient scale: deep inside the sum is flat (round-off).
      const double scale = V[w] * -kernel_.derivative(0.5 * kernel_.support_radius()) + 1e-300;
      b.own_normal[w] = g.norm() > 1e-9 * scale ? Vec<D>(g.normalized()) : Vec<D>(Vec<D>::Zero());
    });
  }

  // BoundarySet::normal from the pair geometry just built: sum_w V_w (-dW/dr) e_iw, normalised.
  void boundary_normals(BoundarySet<D>& b) const {
    const auto& V = b.particles.scalar("volume");
    b.normal.resize(b.list.offset.size() - 1);
    parallel_for_each_index(b.normal.size(), [&](std::size_t i) {
      Vec<D> g = Vec<D>::Zero();
      for (std::size_t k = b.list.offset[i]; k < b.list.offset[i + 1]; ++k)
        g += (V[b.list.index[k]] * b.geometry.gradient[k]) * b.geometry.direction[k];
      const double norm = g.norm();
      b.normal[i] = norm > 0.0 ? Vec<D>(g / norm) : Vec<D>(Vec<D>::Zero());
    });
  }

  // The boundary sets that have particles, walls first.
  std::vector<BoundarySet<D>*> boundaries() {
    std::vector<BoundarySet<D>*> sets;
    for (BoundarySet<D>* b : {&walls_, &contact_})
      if (!b->empty()) sets.push_back(b);
    return sets;
  }

  void pair_geometry(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b,
                     const NeighbourList& list, PairGeometry<D>& g) const {
    g.direction.resize(list.pair_count());
    g.gradient.resize(list.pair_count());
    g.distance.resize(list.pair_count());
    const bool viscous = spec_.viscosity() > 0.0;
    g.gradient_over_distance.resize(viscous ? list.pair_count() : 0);
    parallel_for_each_index(a.size(), [&](std::size_t i) {
      for (std::size_t k = list.offset[i]; k < list.offset[i + 1]; ++k) {
        const Vec<D> d = domain_.displacement(b[list.index[k]], a[i]);
        const double r = d.norm();
        const bool ok = r > 0.0;
        g.direction[k] = ok ? Vec<D>(d / r) : Vec<D>(Vec<D>::Zero());
        g.gradient[k] = ok ? -kernel_.derivative(r) : 0.0;
        g.distance[k] = r;
        if (viscous) g.gradient_over_distance[k] = ok ? g.gradient[k] / r : 0.0;
      }
    });
  }

  // Eq. 12 (free surface: never below the continuity density) or eq. 13 (confined).
  void update_density_by_summation() {
    const auto& x = fluid_.vector("position");
    const auto& m = fluid_.scalar("mass");
    auto& rho = fluid_.scalar("density");
    const double rho0 = spec_.density(), sigma0 = reference_number_density_;
    const bool free_surface = spec_.density_treatment() == "reinitialisation";
    const auto sets = boundaries();
    const auto views = boundary_views(sets);  // field lookups once, not per particle
    const auto truncated = open_.truncation(fluid_);
    const bool keep = holds_by_number_density();  // the shift's hold test reads it
    if (keep) number_density_.resize(x.size());
    parallel_for_each_index(x.size(), [&](std::size_t i) {
      const double sigma = number_density(i, m, sets, views);
      if (keep) number_density_[i] = sigma;
      const double summed = rho0 * sigma / sigma0;
      rho[i] = free_surface || truncated(i) ? std::max(rho[i], summed) : summed;
    });
    update_pressure();
  }

  // Whether the transport-velocity shift holds the particles of a free surface by their number
  // density (transport_velocity_free_surface > 0).
  bool holds_by_number_density() const {
    return spec_.transport_velocity() && spec_.transport_velocity_free_surface() > 0.0;
  }

  void update_pressure() {
    const auto& rho = fluid_.scalar("density");
    auto& p = fluid_.scalar("pressure");
    const double c2 = sound_speed_ * sound_speed_, rho0 = spec_.density();
    for (std::size_t i = 0; i < rho.size(); ++i) p[i] = c2 * (rho[i] - rho0);
  }

  void update_volumes() {
    const auto& rho = fluid_.scalar("density");
    const auto& m = fluid_.scalar("mass");
    auto& volume = fluid_.scalar("volume");
    for (std::size_t i = 0; i < rho.size(); ++i) volume[i] = m[i] / rho[i];
  }

  // The accelerations held over the advection step's acoustic sub-steps: gravity, and the viscous
  // force (seed 003 eq. 10) unless it is sub-cycled (apply_viscosity).
  void update_prior_acceleration() {
    auto& a = fluid_.vector("acceleration");
    if (spec_.viscosity() > 0.0 && !viscous_substeps()) {
      update_viscous_volumes();
      viscous_acceleration(a, 1.0, false);
      parallel_stream(a.size(), [&](std::size_t i) { a[i] += gravity_; });
    } else {
      parallel_stream(a.size(), [&](std::size_t i) { a[i] = gravity_; });
    }
  }

  // The viscous force sub-cycled over the acoustic sub-step [t, t + dt]: k = ceil(dt /
  // viscous_dt) split steps v += (dt / k) a_visc(v), each within the explicit limit, before the
  // pressure half. A split step's pair loop costs less than the pressure and density loops
  // together, so k of them cost less than cutting the acoustic step to the limit (the hydrostatic
  // plate at 0.0125 m: k = 2 and 5 acoustic sub-steps per advection step, against 7 cut to the
  // limit). A contact body is handed the mean of the k recorded forces: over dt its impulse is the
  // fluid's. Inflow-buffer particles keep their prescribed velocity.
  void apply_viscosity(double t, double dt) {
    const double ratio = dt / viscous_dt();
    if (!(ratio < kMaxViscousSplits))
      throw RuntimeError("module '" + name_ + "': the viscous force would need " +
                         std::to_string(ratio) + " split steps in one acoustic sub-step at t = " +
                         std::to_string(t) + " (eta = " + std::to_string(spec_.viscosity()) +
                         ", limit " + std::to_string(viscous_dt()) + " s)");
    const long long k = std::max(1LL, static_cast<long long>(std::ceil(ratio * (1.0 - 1e-12))));
    auto& v = fluid_.vector("velocity");
    viscous_.resize(v.size());
    update_viscous_volumes();
    for (long long split = 0; split < k; ++split) {
      viscous_acceleration(viscous_, 1.0 / double(k), split > 0);
      parallel_stream(v.size(), [&](std::size_t i) { v[i] += (dt / double(k)) * viscous_[i]; });
    }
    open_.impose(fluid_, t);
  }

  // V_j = m_j / rho_j once per particle rather than once per pair, for the viscous force.
  void update_viscous_volumes() {
    const auto& rho = fluid_.scalar("density");
    const auto& m = fluid_.scalar("mass");
    viscous_volume_.resize(m.size());
    parallel_stream(m.size(), [&](std::size_t j) { viscous_volume_[j] = m[j] / rho[j]; });
  }

  // The viscous acceleration a_visc(v) into a, with the volumes of update_viscous_volumes; walls
  // and contact bodies are no-slip through the mirrored velocity 2 v_wall - v_i. With the pair
  // geometry of the advection step, as the acoustic sub-steps' pressure terms. Recording sets get
  // the reaction of each pair times record_scale, in place of what they held or, with
  // add_to_record, added to it.
  void viscous_acceleration(std::vector<Vec<D>>& a, double record_scale, bool add_to_record) {
    const auto& v = fluid_.vector("velocity");
    const auto& rho = fluid_.scalar("density");
    const auto& m = fluid_.scalar("mass");
    const double eta = spec_.viscosity();
    const auto sets = boundaries();
    const auto views = boundary_views(sets);
    parallel_for_each_index(v.size(), [&](std::size_t i) {
      Vec<D> sum = Vec<D>::Zero();
      // dW/r = -gradient_over_distance (0 for a pair at r = 0).
      const auto& inner_dW_r = inner_geometry_.gradient_over_distance;
      for (std::size_t k = inner_.offset[i]; k < inner_.offset[i + 1]; ++k) {
        const Index j = inner_.index[k];
        sum -= (viscous_volume_[j] * inner_dW_r[k]) * (v[i] - v[j]);
      }
      for (std::size_t s = 0; s < sets.size(); ++s) {
        BoundarySet<D>* b = sets[s];
        const auto& bv = views[s].v;
        const auto& bV = views[s].V;
        const auto& dW_r = b->geometry.gradient_over_distance;
        for (std::size_t k = b->list.offset[i]; k < b->list.offset[i + 1]; ++k) {
          const Index w = b->list.index[k];
          sum -= (bV[w] * dW_r[k]) * (2.0 * (v[i] - bv[w]));
          // Its reaction: m_i a_i = 4 eta V_i V_w dW/r (v_i - v_w), V_i = m_i / rho_i.
          if (b->records) {
            const Vec<D> f =
                (record_scale * 4.0 * eta * m[i] / rho[i] * bV[w] * dW_r[k]) * (v[i] - bv[w]);
            b->pair_viscous_force[k] = add_to_record ? Vec<D>(b->pair_viscous_force[k] + f) : f;
          }
        }
      }
      a[i] = (2.0 * eta / rho[i]) * sum;
    });
  }

  // Shifts particles away from crowded neighbourhoods: the transport-velocity correction (seed
  // 003 eq. 11) as a position shift -0.4 h^2 sum_j V_j grad W_ij, a gradient descent on the number
  // density. A single shift larger than this is unstable (the checkerboard mode overshoots), so
  // the scene's number of sweeps sets how fast the lattice is regularised. The neighbour list of
  // the step stays valid: each sweep moves a particle by a small fraction of h. In a free-surface
  // flow (transport_velocity_free_surface > 0) the particles whose number density at the step's
  // configuration is below that fraction of a full neighbourhood's keep their place over the step's
  // sweeps: at the surface the shift points out of the water. So do, with a hydrostatic band, those
  // whose pressure is below that many spacings' head: the layer under the surface, which the
  // shifted particles below would otherwise crowd up and dilate.
  void correct_transport_velocity() {
    auto& x = fluid_.vector("position");
    const double h = kernel_.smoothing_length();
    shift_.resize(x.size());
    const auto sets = boundaries();
    const auto views = boundary_views(sets);
    const auto truncated = open_.truncation(fluid_);
    // The number density below which a particle is held: 0 holds none (confined flows).
    const double hold_below = spec_.transport_velocity_free_surface() * reference_number_density_;
    const double band_pressure = spec_.density() * gravity_.norm() * spec_.body().spacing() *
                                 spec_.transport_velocity_hydrostatic_band();
    const auto& p = fluid_.scalar("pressure");
    held_.assign(x.size(), 0);
    // The density summation of this step left the number density; without one, sum it here.
    if (holds_by_number_density() && spec_.density_treatment() == "none") {
      const auto& m = fluid_.scalar("mass");
      number_density_.resize(x.size());
      parallel_for_each_index(
          x.size(), [&](std::size_t i) { number_density_[i] = number_density(i, m, sets, views); });
    }
    for (int sweep = 0; sweep < spec_.transport_velocity_sweeps(); ++sweep) {
      // The first sweep finds the particles where the lists were built: sum_j V_j grad W_ij =
      // sum_j V_j (-dW/dr) e_ij from the pair geometry, and decides which particles are held.
      const bool at_build = sweep == 0;
      parallel_for_each_index(x.size(), [&](std::size_t i) {
        if (held_[i]) return;
        Vec<D> sum;
        if (at_build) {
          sum = number_density_gradient_at_build(i, sets, views);
          held_[i] = (hold_below > 0.0 && number_density_[i] < hold_below) ||
                     (band_pressure > 0.0 && p[i] < band_pressure);
        } else {
          sum = number_density_gradient(i, sets, views);
        }
        if (truncated(i)) held_[i] = 1;
        shift_[i] = held_[i] ? Vec<D>(Vec<D>::Zero()) : Vec<D>(-0.4 * h * h * sum);
      });
      parallel_stream(x.size(), [&](std::size_t i) { x[i] = wrap(x[i] + shift_[i]); });
    }
  }

  // The arrays of a boundary set that the pair loops read, and the state it presents to a fluid
  // particle (walls have no acceleration field: theirs is taken as zero).
  struct BoundaryView {
    const std::vector<Vec<D>>& x;
    const std::vector<Vec<D>>& v;
    const std::vector<double>& V;
    const std::vector<Vec<D>>* a;
    Vec<D> g;
    bool clamped;  // the pressure extension clamped at zero
    BoundaryView(const BoundarySet<D>& b, const Vec<D>& gravity, bool clamped_extension)
        : x(b.particles.vector("position")),
          v(b.particles.vector("velocity")),
          V(b.particles.scalar("volume")),
          a(b.particles.has("acceleration") ? &b.particles.vector("acceleration") : nullptr),
          g(gravity),
          clamped(clamped_extension) {}
    OneSidedState<D> state(Index w, double p_i, double rho_i, const Vec<D>& v_i,
                           const Vec<D>& x_w_minus_x_i) const {
      return one_sided_state<D>(p_i, rho_i, v_i, v[w], a ? Vec<D>(g - (*a)[w]) : g, x_w_minus_x_i,
                                clamped);
    }
  };

  std::vector<BoundaryView> boundary_views(const std::vector<BoundarySet<D>*>& sets) const {
    std::vector<BoundaryView> views;
    const bool clamped = spec_.pressure_extension() == "clamped";
    for (const BoundarySet<D>* b : sets) views.emplace_back(*b, gravity_, clamped);
    return views;
  }

  Vec<D> wrap(const Vec<D>& x) const { return domain_.any_periodic() ? domain_.wrap(x) : x; }

  // sum_j V_j W_ij over the fluid (V_j = m_j / rho0, the self term included) and boundary
  // neighbours of i, from the step's pair geometry: rho0 times it over a full neighbourhood's is
  // the summed density (eq. 12, 13).
  double number_density(std::size_t i, const std::vector<double>& m,
                        const std::vector<BoundarySet<D>*>& sets,
                        const std::vector<BoundaryView>& views) const {
    const double rho0 = spec_.density();
    double sigma = m[i] / rho0 * kernel_.value(0.0);
    for (std::size_t k = inner_.offset[i]; k < inner_.offset[i + 1]; ++k)
      sigma += m[inner_.index[k]] / rho0 * kernel_.value(inner_geometry_.distance[k]);
    for (std::size_t s = 0; s < sets.size(); ++s) {
      const auto& list = sets[s]->list;
      const auto& r = sets[s]->geometry.distance;
      for (std::size_t k = list.offset[i]; k < list.offset[i + 1]; ++k)
        sigma += views[s].V[list.index[k]] * kernel_.value(r[k]);
    }
    return sigma;
  }

  // sum_j V_j grad W_ij = sum_j V_j (-dW/dr) e_ij (V = m / rho) over the fluid and boundary
  // neighbours of i, from the step's pair geometry (the first sweep).
  Vec<D> number_density_gradient_at_build(std::size_t i, const std::vector<BoundarySet<D>*>& sets,
                                          const std::vector<BoundaryView>& views) const {
    const auto& volume = fluid_.scalar("volume");
    Vec<D> gradient = Vec<D>::Zero();
    for (std::size_t k = inner_.offset[i]; k < inner_.offset[i + 1]; ++k)
      gradient +=
          (volume[inner_.index[k]] * inner_geometry_.gradient[k]) * inner_geometry_.direction[k];
    for (std::size_t s = 0; s < sets.size(); ++s) {
      const auto& list = sets[s]->list;
      const auto& g = sets[s]->geometry;
      for (std::size_t k = list.offset[i]; k < list.offset[i + 1]; ++k)
        gradient += (views[s].V[list.index[k]] * g.gradient[k]) * g.direction[k];
    }
    return gradient;
  }

  // sum_j V_j grad W_ij at the particles' present positions (the sweeps after the first).
  Vec<D> number_density_gradient(std::size_t i, const std::vector<BoundarySet<D>*>& sets,
                                 const std::vector<BoundaryView>& views) const {
    const auto& x = fluid_.vector("position");
    const auto& volume = fluid_.scalar("volume");
    Vec<D> sum = Vec<D>::Zero();
    for (std::size_t k = inner_.offset[i]; k < inner_.offset[i + 1]; ++k) {
      const Vec<D> d = domain_.displacement(x[i], x[inner_.index[k]]);
      const double r = d.norm();
      if (r > 0.0) sum += volume[inner_.index[k]] * kernel_.derivative(r) / r * d;
    }
    for (std::size_t s = 0; s < sets.size(); ++s) {
      const auto& list = sets[s]->list;
      for (std::size_t k = list.offset[i]; k < list.offset[i + 1]; ++k) {
        const Index w = list.index[k];
        const Vec<D> d = domain_.displacement(x[i], views[s].x[w]);
        const double r = d.norm();
        if (r > 0.0) sum += views[s].V[w] * kernel_.derivative(r) / r * d;
      }
    }
    return sum;
  }

  // Calls f(e_iw, -dW/dr, V_w, one-sided state of w, set, pair) for every boundary neighbour w of
  // fluid particle i (at x, with pressure p, density rho, velocity v), with the pair geometry of
  // the advection step (the two acoustic halves share it).
  template <typename F>
  void for_each_boundary_neighbour(std::size_t i, const Vec<D>& x, double p, double rho,
                                   const Vec<D>& v, const std::vector<BoundarySet<D>*>& sets,
                                   const std::vector<BoundaryView>& views, const F& f) const {
    for (std::size_t s = 0; s < sets.size(); ++s) {
      const BoundarySet<D>& b = *sets[s];
      const BoundaryView& view = views[s];
      for (std::size_t k = b.list.offset[i]; k < b.list.offset[i + 1]; ++k) {
        const Index w = b.list.index[k];
        f(b.geometry.direction[k], b.geometry.gradient[k], view.V[w],
          view.state(w, p, rho, v, domain_.displacement(view.x[w], x)), *sets[s], k);
      }
    }
  }

  // First half: density and position to mid-step, velocity over the step from P*.
  void pressure_relaxation(double t, double dt) {
    auto& x = fluid_.vector("position");
    auto& v = fluid_.vector("velocity");
    auto& rho = fluid_.scalar("density");
    auto& p = fluid_.scalar("pressure");
    const auto& drho = fluid_.scalar("density_rate");
    const auto& m = fluid_.scalar("mass");
    const auto& prior = fluid_.vector("acceleration");
    const double c2 = sound_speed_ * sound_speed_, rho0 = spec_.density();
    auto& volume = fluid_.scalar("volume");
    parallel_stream(x.size(), [&](std::size_t i) {
      rho[i] += 0.5 * dt * drho[i];
      p[i] = c2 * (rho[i] - rho0);
      volume[i] = m[i] / rho[i];
      x[i] = wrap(x[i] + 0.5 * dt * v[i]);
    });
    const RiemannSolver solver = riemann();
    const auto sets = boundaries();
    const auto views = boundary_views(sets);
    const bool slip = slip_walls();
    const RiemannSolver acoustic = slip_wall_riemann();
    dv_.resize(x.size());
    parallel_for_each_index(x.size(), [&](std::size_t i) {
      Vec<D> sum = Vec<D>::Zero();
      for (std::size_t k = inner_.offset[i]; k < inner_.offset[i + 1]; ++k) {
        const Index j = inner_.index[k];
        const Vec<D>& e = inner_geometry_.direction[k];
        const double P = solver.pressure(p[i], p[j], v[i].dot(e), v[j].dot(e));
        sum -= (volume[j] * P * inner_geometry_.gradient[k]) * e;
      }
      for_each_boundary_neighbour(
          i, x[i], p[i], rho[i], v[i], sets, views,
          [&](const Vec<D>& e, double gradient, double V, const auto& wall, BoundarySet<D>& b,
              std::size_t k) {
            if (slip && !b.own_normal.empty()) {
              const Vec<D> P =
                  own_normal_pressure(acoustic, b.own_normal[b.list.index[k]], e, p[i], v[i], wall);
              sum -= (V * gradient) * P;
              if (b.records) b.pair_pressure_force[k] = (2.0 * volume[i] * V * gradient) * P;
              return;
            }
            // No-slip: the mirrored velocity along e_iw. Slip at a contact
            // body: the jump along the normal as i sees it, the same for
            // all of i's pairs; the reaction stays pairwise.
            const Vec<D>& n = slip ? b.normal[i] : e;
            const double P =
                solver.pressure(p[i], wall.pressure, v[i].dot(n), wall.velocity.dot(n));
            sum -= (V * P * gradient) * e;
            // Its reaction on the boundary: m_i dv_i = -2 V_i V_w P* |dW|
            // e_iw.
            if (b.records) b.pair_pressure_force[k] = (2.0 * volume[i] * V * P * gradient) * e;
          });
      dv_[i] = (2.0 / rho[i]) * sum;
    });
    parallel_stream(x.size(), [&](std::size_t i) { v[i] += dt * (dv_[i] + prior[i]); });
    open_.impose(fluid_, t + dt);
  }

  // Second half: position to the end of the step, density rate from U*, density half step.
  void density_relaxation(double t, double dt) {
    auto& x = fluid_.vector("position");
    const auto& v = fluid_.vector("velocity");
    auto& rho = fluid_.scalar("density");
    const auto& p = fluid_.scalar("pressure");
    auto& drho = fluid_.scalar("density_rate");
    const auto& volume = fluid_.scalar("volume");  // m / rho of the first half
    parallel_stream(x.size(), [&](std::size_t i) { x[i] = wrap(x[i] + 0.5 * dt * v[i]); });
    move_walls(t, dt);
    const RiemannSolver solver = riemann();
    const auto sets = boundaries();
    const auto views = boundary_views(sets);
    parallel_for_each_index(x.size(), [&](std::size_t i) {
      double sum = 0.0;
      for (std::size_t k = inner_.offset[i]; k < inner_.offset[i + 1]; ++k) {
        const Index j = inner_.index[k];
        const Vec<D>& e = inner_geometry_.direction[k];
        const double u = v[i].dot(e);
        const double U = solver.velocity(p[i], p[j], u, v[j].dot(e));
        sum += volume[j] * (u - U) * inner_geometry_.gradient[k];
      }
      for_each_boundary_neighbour(i, x[i], p[i], rho[i], v[i], sets, views,
                                  [&](const Vec<D>& e, double gradient, double V, const auto& wall,
                                      BoundarySet<D>&, std::size_t) {
                                    const double u = v[i].dot(e);
                                    const double U = solver.velocity(p[i], wall.pressure, u,
                                                                     wall.velocity.dot(e));
                                    sum += V * (u - U) * gradient;
                                  });
      drho[i] = 2.0 * rho[i] * sum;
    });
    parallel_stream(x.size(), [&](std::size_t i) { rho[i] += 0.5 * dt * drho[i]; });
  }

  std::string name_, key_;
  const proto::Scene& scene_;
  std::string scene_directory_;
  proto::FluidSpec spec_;
  Kernel kernel_;
  Domain<D> domain_;
  ParticleSet<D> fluid_;
  double sound_speed_;  // before open_, which takes it
  BoundarySet<D> walls_, contact_;
  OpenBoundaries<D> open_;
  std::vector<int> wall_owner_;
  std::vector<std::vector<Expression>> wall_velocity_;
  std::vector<Expression> initial_velocity_;
  Expression initial_pressure_;
  Vec<D> gravity_ = Vec<D>::Zero();
  double reference_number_density_ = 1.0;
  NeighbourList inner_;
  PairGeometry<D> inner_geometry_;
  std::vector<Vec<D>> dv_, shift_;
  std::vector<char> held_;              // particles the transport-velocity shift leaves this step
  std::vector<double> number_density_;  // sum_j V_j W_ij of the step (with a free-surface hold)
  std::vector<Vec<D>> viscous_;         // the sub-cycled viscous acceleration
  double contact_density_ = std::numeric_limits<double>::infinity();  // see contact_viscous_dt
  std::vector<double> viscous_volume_;  // m / rho per particle, for the viscous force
  double time_ = 0.0;
  double step_size_ = 0.0, step_done_ = 0.0;  // the open advection step (staged advance)
  long long steps_ = 0, acoustic_steps_ = 0;
};

}  // namespace

std::unique_ptr<Module> make_fluid_module(const proto::ModuleSpec& spec,
                                          const ModuleContext& context) {
  if (context.scene->dimension() == 2) return std::make_unique<FluidModule<2>>(spec, context);
  return std::make_unique<FluidModule<3>>(spec, context);
}

}  // namespace cosph
