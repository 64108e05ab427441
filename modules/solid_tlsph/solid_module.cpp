#include "solid_tlsph/solid_module.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>
#include <sstream>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "core/scoped_seconds.hpp"
#include "driver/state_reader.hpp"
#include "driver/static_body_module.hpp"
#include "geometry/regions.hpp"
#include "geometry/surface.hpp"
#include "io/probes.hpp"
#include "solid_tlsph/fibre_frames.hpp"
#include "solid_tlsph/material_model.hpp"
#include "solid_tlsph/static_equilibrium.hpp"
#include "solid_tlsph/tlsph_operators.hpp"

namespace cosph {
namespace {

const std::vector<std::string> kSpaceTime = {"x", "y", "z", "t"};

template <int D>
class SolidModule final : public StaticBodyModule<D> {
  using Base = StaticBodyModule<D>;
  using Base::kernel_;
  using Base::key_;
  using Base::name_;
  using Base::particles_;
  using Base::steps_;
  using Base::time_;

 public:
  SolidModule(const proto::ModuleSpec& spec, const ModuleContext& context)
      : Base(spec, context, "solid", spec.solid().body()),
        spec_(spec.solid()),
        material_(spec_.material(), key_ + ".material") {
    if (spec_.has_active_tension())
      active_tension_ = parse(spec_.active_tension(), key_ + ".active_tension");
    if (D == 2 && std::find(spec_.outputs().begin(), spec_.outputs().end(), "von_mises") !=
                      spec_.outputs().end())
      plane_strain_.emplace(spec_.material(), key_ + ".material");
    for (int a = 0; a < spec_.initial_velocity_size(); ++a)
      initial_velocity_.push_back(
          parse(spec_.initial_velocity(a), key_ + ".initial_velocity[" + std::to_string(a) + "]"));
    if (spec_.has_steady_state()) check_steady_state_spec();
    if (dual_cell_quadrature()) check_energy_quadrature_spec();
    if (spec_.has_steady_state() && spec_.steady_state().has_grid_sequence())
      build_coarse_level(spec, context);
  }

  ModuleInfo info() const override {
    ModuleInfo info;
    info.type = "solid";
    info.name = name_;
    info.dimension = D;
    info.spacing = spec_.body().spacing();
    // `interface`: the surface particles with their current normals; `particles`: every particle,
    // the point set a fluid's contact sees (it must see all solid particles within its kernel
    // support: one surface layer under-fills it, and a thin flag is seen from both sides).
    info.writes = {{"interface", {"position", "normal", "volume", "velocity", "acceleration"}},
                   {"particles", {"position", "volume", "velocity", "acceleration", "mass"}}};
    info.reads = {{"external_force", {"force"}}, {"active_stress", {"active_stress"}}};
    auto& f = info.active_features;
    f.push_back("material " + material_.name());
    f.push_back("total-Lagrangian SPH, kernel " + kernel_name(kernel_.type()) +
                ", corrected gradients");
    if (dual_cell_quadrature()) f.push_back("energy integrated over the dual cells");
    if (spec_.gradient_correction() == "quadratic")
      f.push_back("quadratic gradient correction (" + std::to_string(pairs_.quadratic_particles()) +
                  " of " + std::to_string(X_.size()) + " particles)");
    if (steady())
      f.push_back("steady state: quasi-Newton, " +
                  std::to_string(spec_.steady_state().load_steps()) +
                  " load step(s) over the ramp, relative tolerance " +
                  short_number(spec_.steady_state().tolerance()));
    else
      f.push_back(spec_.integrator() == "rk4" ? "RK4 integrator" : "position Verlet integrator");
    if (coarse_)
      f.push_back(
          "grid sequencing (" + std::to_string(spec_.steady_state().grid_sequence().levels()) +
          " coarser level(s), coarsest " + std::to_string(coarsest().X_.size()) + " particles)");
    if (spec_.has_artificial_viscosity()) f.push_back("artificial viscosity");
    if (pair_hourglass()) f.push_back("hourglass control");
    if (fit_residual_hourglass()) f.push_back("hourglass control (fit residual)");
    if (spec_.damping() > 0.0 && !steady()) f.push_back("mass-proportional damping");
    if (spec_.load_ramp_time() > 0.0) f.push_back("load ramp");
    if (spec_.body_force_size() > 0) f.push_back("body force");
    if (spec_.constraints_size() > 0) f.push_back("constraints");
    if (spec_.pressures_size() > 0) f.push_back("follower pressure (Nanson)");
    if (spec_.has_active_tension()) f.push_back("prescribed active tension");
    if (has_frames()) f.push_back("fibre frames");
    for (const auto& o : spec_.outputs()) f.push_back("output " + o);
    if (steady()) {
      info.statistics["load_increments"] = double(steady_increments_);
      info.statistics["increment_bisections"] = double(steady_bisections_);
      info.statistics["newton_iterations"] = double(newton_iterations_);
      info.statistics["tangent_factorisations"] = double(factorisations_);
      info.statistics["shifted_factorisations"] = double(shifted_factorisations_);
      info.statistics["relative_residual"] = steady_residual_;
      info.statistics["residual_evaluations"] = double(residual_evaluations_);
      if (coarse_) {
        info.statistics["smoothing_sweeps"] = double(smoothing_sweeps_);
        info.statistics["coarse_guesses_rejected"] = double(coarse_guesses_rejected_);
        info.statistics["coarse_level_failed"] = coarse_failed_ ? 1.0 : 0.0;
        info.statistics["coarse_level_newton_iterations"] = double(coarse_->newton_iterations_);
      }
      // Where the steady state's time went (this process's solves; not checkpointed).
      if (equilibrium_) {
        info.statistics["tangent_assembly_seconds"] = equilibrium_->assembly_seconds();
        info.statistics["factorisation_seconds"] = equilibrium_->solver().factorisation_seconds();
        info.statistics["triangular_solve_seconds"] =
            equilibrium_->solver().triangular_solve_seconds();
        info.statistics["residual_seconds"] = equilibrium_->solver().residual_seconds();
        if (coarse_) {
          info.statistics["smoothing_seconds"] = equilibrium_->smoothing_seconds();
          info.statistics["coarse_level_seconds"] = coarse_seconds_;
        }
      }
    }
    return info;
  }

  void initialize() override {
    Base::build_body();
    const std::size_t n = particles_.size();
    const auto& volume = particles_.scalar("volume");
    X_ = particles_.vector("position");
    particles_.add_vector("reference_position");
    particles_.vector("reference_position") = X_;
    const FieldFlags state{.output = true, .checkpoint = true, .exchange = true};
    particles_.add_vector("displacement", state);
    auto& v = particles_.add_vector("velocity", state);
    particles_.add_vector("acceleration", {.exchange = true});
    auto& mass = particles_.add_scalar("mass");
    auto& J = particles_.add_scalar("J", {.output = true});
    std::fill(J.begin(), J.end(), 1.0);
    for (std::size_t i = 0; i < n; ++i) mass[i] = material_.density() * volume[i];
    for (const auto& o : spec_.outputs()) {
      if (o == "von_mises") particles_.add_scalar("von_mises", {.output = true});
      if (o == "strain_energy") particles_.add_scalar("strain_energy", {.output = true});
      if (o == "fibre_strain") particles_.add_vector("fibre_strain", {.output = true});
      if (o == "stress") particles_.add_matrix("stress", {.output = true});
      if (o == "hourglass") particles_.add_scalar("hourglass", {.output = true});
      if (o == "external_force") particles_.add_vector("external_force", {.output = true});
    }
    // T_a per particle: prescribed here, or added when a coupler first writes the port.
    if (spec_.has_active_tension())
      active_ = &particles_.add_scalar("active_tension", {.output = true});

    // A fibre spec is checked even when nothing needs it yet (a coupler may send active stress
    // later): its errors belong at start-up, with the scene line.
    if (has_frames() || spec_.has_fibres()) build_frames();
    try {
      pairs_ = build_reference_pairs<D>(X_, volume, kernel_,
                                        spec_.gradient_correction() == "quadratic"
                                            ? GradientCorrection::quadratic
                                            : GradientCorrection::linear,
                                        pair_hourglass(), dual_cell_quadrature());
    } catch (const RuntimeError& e) {
      throw RuntimeError("module '" + name_ + "': " + e.what());
    }
    if (fit_residual_hourglass())
      fit_control_.emplace(X_, volume, pairs_, kernel_,
                           spec_.hourglass_control().coefficient() * material_.shear_modulus());
    if (dual_cell_quadrature()) build_energy_quadrature();
    F_.assign(n, Mat<D>::Identity());
    P_.assign(n, Mat<D>::Zero());
    if (spec_.has_artificial_viscosity()) {
      A_.assign(n, Mat<D>::Zero());
      density_.assign(n, material_.density());
    }
    x_ = X_;

    build_constraints();
    build_pressures();
    if (spec_.body_force_size() > 0) body_force_ = to_vec<D>(spec_.body_force());

    for (std::size_t i = 0; i < n && !initial_velocity_.empty(); ++i) {
      const auto p = Base::space_time(X_[i], 0.0);
      for (int a = 0; a < D; ++a) v[i][a] = initial_velocity_[a].evaluate(p);
    }
    auto& u = particles_.vector("displacement");
    apply_constraints(0.0, u, v);
    if (steady()) build_static_equilibrium();
    if (coarse_) coarse_->initialize();
    if (!spec_.has_time_step() && !steady()) update_stiffness_eigenvalue();
    compute_acceleration(0.0, u, v, particles_.vector("acceleration"));
    prepare_output();
  }

  double max_dt() const override {
    if (steady()) {
      // A load increment during the ramp; after it, the whole rest of the run in one step.
      const double ramp = spec_.load_ramp_time();
      return time_ < ramp * (1.0 - 1e-12) ? ramp / spec_.steady_state().load_steps() : INFINITY;
    }
    if (spec_.has_time_step()) return spec_.time_step();
    const auto& v = particles_.vector("velocity");
    const auto& a = particles_.vector("acceleration");
    double v2_max = 0.0, a2_max = 0.0;  // squared: two square roots, not two per particle
    for (std::size_t i = 0; i < v.size(); ++i) {
      v2_max = std::max(v2_max, v[i].squaredNorm());
      a2_max = std::max(a2_max, a[i].squaredNorm());
    }
    const double v_max = std::sqrt(v2_max), a_max = std::sqrt(a2_max);
    // Seed 001 eq. 42; the acceleration bound keeps a particle from moving more than about h in
    // a step under a sudden load.
    const double h = kernel_.smoothing_length();
    double dt = h / (material_.wave_speed() + v_max);
    if (a_max > 0.0) dt = std::min(dt, std::sqrt(h / a_max));
    dt *= spec_.time_step_factor();
    // The discrete operator's own limit: near free surfaces the corrected gradients make it
    // stiffer than the continuum wave speed says (thin near-incompressible walls go unstable at
    // eq. 42's step), so the largest eigenvalue lambda of the linearised acceleration bounds the
    // step too: Verlet and RK4 are stable for sqrt(lambda) dt < 2 (2.8 for RK4, not used). Its
    // own factor: the limit is measured, eq. 42's is an estimate.
    if (stiffness_eigenvalue_ > 0.0)
      dt = std::min(dt, spec_.eigenvalue_step_factor() * 2.0 / std::sqrt(stiffness_eigenvalue_));
    return dt;
  }

  void advance(double dt) override {
    if (steady()) {
      advance_steady(dt);
    } else {
      if (steps_ > 0 && steps_ % kStiffnessInterval == 0) update_stiffness_eigenvalue();
      if (spec_.integrator() == "rk4")
        advance_rk4(dt);
      else
        advance_verlet(dt);
    }
    time_ += dt;
    ++steps_;
  }

  void prepare_output() override {
    const auto& u = particles_.vector("displacement");
    deformation_gradients<D>(pairs_, u, F_);
    if (particles_.has("hourglass")) update_hourglass_measure();
    auto& J = particles_.scalar("J");
    const bool vm = particles_.has("von_mises"), energy = particles_.has("strain_energy"),
               fibre = particles_.has("fibre_strain"), stress = particles_.has("stress");
    parallel_for_each_index(u.size(), [&](std::size_t i) {
      J[i] = F_[i].determinant();
      if (!(vm || stress || energy || fibre)) return;
      const Mat<D> frame = has_frames() ? frames_[i] : Mat<D>::Identity();
      if (vm || stress) {
        const Mat<D> sigma = first_piola(i, F_[i], frame) * F_[i].transpose() / J[i];
        if (stress) particles_.matrix("stress")[i] = sigma;
        if (vm) particles_.scalar("von_mises")[i] = von_mises(sigma, out_of_plane_stress(i));
      }
      if (energy) particles_.scalar("strain_energy")[i] = strain_energy(i, frame, u);
      if (fibre) {
        const Mat<D> E = 0.5 * (F_[i].transpose() * F_[i] - Mat<D>::Identity());
        particles_.vector("fibre_strain")[i] = over_fibres(
            i, frame, [&](const Mat<D>& f) { return Vec<D>((f.transpose() * E * f).diagonal()); });
      }
    });
  }

  void write(const std::string& port, FieldBuffer& out) const override {
    if (port == "particles") return write_particles(out);
    if (port != "interface")
      throw RuntimeError("module '" + name_ + "' has no port '" + port +
                         "' (it writes 'interface' and 'particles')");
    const Surface<D>& s = surface();
    const auto& x = particles_.vector("position");
    const auto& v = particles_.vector("velocity");
    const auto& a = particles_.vector("acceleration");
    const auto& V = particles_.scalar("volume");
    out.points = s.particles.size();
    out.arrays.clear();
    auto& position = out.arrays["position"];
    auto& normal = out.arrays["normal"];
    auto& volume = out.arrays["volume"];
    auto& velocity = out.arrays["velocity"];
    auto& acceleration = out.arrays["acceleration"];
    position.components = normal.components = velocity.components = acceleration.components = D;
    for (std::size_t k = 0; k < s.particles.size(); ++k) {
      const Index i = s.particles[k];
      // Current normal by Nanson: n ~ F^-T N.
      const Vec<D> n = (F_[i].inverse().transpose() * s.normals[k]).normalized();
      volume.values.push_back(V[i]);
      for (int c = 0; c < D; ++c) {
        position.values.push_back(x[i][c]);
        normal.values.push_back(n[c]);
        velocity.values.push_back(v[i][c]);
        acceleration.values.push_back(a[i][c]);
      }
    }
  }

  void read(const std::string& port, const FieldBuffer& in) override {
    if (port == "external_force") {
      auto it = in.arrays.find("force");
      const std::size_t n = particles_.size(), m = surface().particles.size();
      if (it == in.arrays.end() || it->second.components != D ||
          (in.points != n && in.points != m) || it->second.values.size() != in.points * D)
        throw RuntimeError("module '" + name_ + "': port 'external_force' needs 'force' with " +
                           std::to_string(D) + " components per particle (" + std::to_string(n) +
                           ") or per interface particle (" + std::to_string(m) + ")");
      external_force_.assign(n, Vec<D>::Zero());
      for (std::size_t k = 0; k < in.points; ++k) {
        const std::size_t i = in.points == n ? k : surface().particles[k];
        for (int c = 0; c < D; ++c) external_force_[i][c] = it->second.values[k * D + c];
      }
      if (particles_.has("external_force")) particles_.vector("external_force") = external_force_;
      return;
    }
    if (port == "active_stress") {
      if (spec_.has_active_tension())
        throw RuntimeError("module '" + name_ +
                           "': its active tension is prescribed by the scene; it reads no port");
      if (!particles_.has("active_tension")) {
        active_ = &particles_.add_scalar("active_tension", {.output = true, .checkpoint = true});
        if (!has_frames()) build_frames();
      }
      // The port carries the active_stress module's field `active_stress` (T_a per particle).
      auto it = in.arrays.find("active_stress");
      if (it == in.arrays.end() || in.points != particles_.size() || it->second.components != 1 ||
          it->second.values.size() != in.points)
        throw RuntimeError("module '" + name_ +
                           "': port 'active_stress' needs 'active_stress' with one value per "
                           "particle (" +
                           std::to_string(particles_.size()) + ")");
      particles_.scalar("active_tension") = it->second.values;
      return;
    }
    throw RuntimeError("module '" + name_ + "' has no port '" + port +
                       "' (it reads 'external_force' and 'active_stress')");
  }

  void save(StateRecord& state) const override {
    for (const char* f : {"displacement", "velocity", "acceleration"}) {
      const auto raw = particles_.raw(f);
      state.arrays[f].assign(raw.begin(), raw.end());
    }
    if (particles_.has("active_tension"))
      state.arrays["active_tension"] = particles_.scalar("active_tension");
    state.scalars["time"] = time_;
    state.scalars["stiffness_eigenvalue"] = stiffness_eigenvalue_;
    state.integers["steps"] = steps_;
    if (steady()) {
      state.integers["load_increments"] = steady_increments_;
      state.integers["increment_bisections"] = steady_bisections_;
      state.integers["newton_iterations"] = newton_iterations_;
      state.integers["residual_evaluations"] = residual_evaluations_;
      state.integers["tangent_factorisations"] = factorisations_;
      state.integers["shifted_factorisations"] = shifted_factorisations_;
      state.scalars["relative_residual"] = steady_residual_;
      if (coarse_) {
        state.integers["smoothing_sweeps"] = smoothing_sweeps_;
        state.integers["coarse_guesses_rejected"] = coarse_guesses_rejected_;
        state.integers["coarse_level_failed"] = coarse_failed_ ? 1 : 0;
        save_coarse_level(state);
      }
      // With a coarse level every step starts on a fresh tangent: none to keep.
      if (const auto* point = coarse_ ? nullptr : equilibrium_->kept_tangent()) {
        auto& u = state.arrays["steady_tangent_displacement"];
        for (const Vec<D>& ui : point->u) u.insert(u.end(), ui.data(), ui.data() + D);
        state.scalars["steady_tangent_force_time"] = point->force_time;
        state.scalars["steady_tangent_load_time"] = point->tangent_time;
      }
    }
  }

  void load(const StateRecord& state) override {
    const StateReader read(state, "module '" + name_ + "'");
    for (const char* f : {"displacement", "velocity", "acceleration"}) {
      auto raw = particles_.raw(f);
      const auto& saved = read.array(f, raw.size());
      std::copy(saved.begin(), saved.end(), raw.begin());
    }
    if (const auto* tension = read.optional_array("active_tension", particles_.size())) {
      if (!particles_.has("active_tension"))
        active_ = &particles_.add_scalar("active_tension", {.output = true, .checkpoint = true});
      particles_.scalar("active_tension") = *tension;
    }
    time_ = read.scalar("time");
    stiffness_eigenvalue_ = read.scalar("stiffness_eigenvalue");
    if (!(std::isfinite(stiffness_eigenvalue_) && stiffness_eigenvalue_ >= 0.0))
      throw RuntimeError("module '" + name_ + "': checkpoint's stiffness_eigenvalue " +
                         std::to_string(stiffness_eigenvalue_) + " is not an eigenvalue");
    steps_ = read.integer("steps");
    if (steady()) {
      steady_increments_ = read.integer("load_increments");
      steady_bisections_ = read.integer("increment_bisections");
      newton_iterations_ = read.integer("newton_iterations");
      residual_evaluations_ = read.integer("residual_evaluations");
      factorisations_ = read.integer("tangent_factorisations");
      shifted_factorisations_ = read.integer("shifted_factorisations");
      steady_residual_ = read.scalar("relative_residual");
      if (coarse_) {
        smoothing_sweeps_ = read.integer("smoothing_sweeps");
        coarse_guesses_rejected_ = read.integer("coarse_guesses_rejected");
        coarse_failed_ = read.integer("coarse_level_failed") != 0;
        load_coarse_level(state);
      }
      if (const auto* u = read.optional_array("steady_tangent_displacement", D * X_.size()))
        restore_steady_tangent(*u, read.scalar("steady_tangent_force_time"),
                               read.scalar("steady_tangent_load_time"));
    }
    const auto& u = particles_.vector("displacement");
    auto& x = particles_.vector("position");
    for (std::size_t i = 0; i < u.size(); ++i) x[i] = X_[i] + u[i];
    prepare_output();
  }

  std::optional<HealthProblem> check_health() const override {
    // J from the current displacements (the step's own F is the mid-step one).
    std::vector<Mat<D>> F(F_.size());
    deformation_gradients<D>(pairs_, particles_.vector("displacement"), F);
    for (std::size_t i = 0; i < F.size(); ++i) {
      const double J = F[i].determinant();
      if (!(J > 0.0))
        return HealthProblem{"J", static_cast<long long>(i), J,
                             "> 0 (a particle's neighbourhood is inverted: tangled particles)"};
    }
    return std::nullopt;
  }

 private:
  enum class ConstraintKind { Clamp, Fixed, Displacement, Velocity };
  struct Constraint {
    ConstraintKind kind = ConstraintKind::Clamp;
    std::vector<Index> particles;
    std::array<bool, D> components{};
    std::vector<Expression> values;
  };
  struct Pressure {
    std::vector<Index> particles;
    std::vector<Vec<D>> areas;  // reference outward area vector N dA
    Expression value;
  };

  static Expression parse(const std::string& text, const std::string& key) {
    return Base::parse_expression(text, kSpaceTime, key);
  }

  // Every particle's position, reference volume, velocity, acceleration and mass.
  void write_particles(FieldBuffer& out) const {
    out.points = particles_.size();
    out.arrays.clear();
    out.arrays["volume"] = {1, particles_.scalar("volume")};
    out.arrays["mass"] = {1, particles_.scalar("mass")};
    for (const char* f : {"position", "velocity", "acceleration"}) {
      const auto raw = particles_.raw(f);
      out.arrays[f] = {D, std::vector<double>(raw.begin(), raw.end())};
    }
  }

  bool has_frames() const {
    return material_.anisotropic() || spec_.has_active_tension() || !frames_.empty() ||
           std::find(spec_.outputs().begin(), spec_.outputs().end(), "fibre_strain") !=
               spec_.outputs().end();
  }

  // The fibre frames and where the rule leaves the fibre undefined (first_piola reads both).
  void build_frames() {
    frames_ = build_fibre_frames<D>(spec_.fibres(), X_, spec_.body().spacing(), key_ + ".fibres",
                                    Base::scene_directory_);
    fibre_undefined_ = fibre_undefined_in_wall<D>(spec_.fibres(), X_);
  }

  double load_factor(double t) const {
    const double ramp = spec_.load_ramp_time();
    return ramp > 0.0 ? std::min(t / ramp, 1.0) : 1.0;
  }

  // sigma_zz of particle i in plane strain (2D; 0 in 3D, where sigma is whole): the 3D law at
  // F3 = diag(F, 1), sigma_zz = P3_zz / J. The active tension acts in the plane (f0 has no z).
  double out_of_plane_stress(std::size_t i) const {
    if constexpr (D == 2) {
      Mat<3> F3 = Mat<3>::Identity(), frame3 = Mat<3>::Identity();
      F3.topLeftCorner<2, 2>() = F_[i];
      if (has_frames()) frame3.topLeftCorner<2, 2>() = frames_[i];
      return plane_strain_->stress(F3, frame3)(2, 2) / F_[i].determinant();
    } else {
      (void)i;
      return 0.0;
    }
  }

  static double von_mises(const Mat<D>& s, double s_zz) {
    Mat<3> full = Mat<3>::Zero();
    full.template topLeftCorner<D, D>() = s;
    if constexpr (D == 2) full(2, 2) = s_zz;
    const Mat<3> dev = full - full.trace() / 3.0 * Mat<3>::Identity();
    return std::sqrt(1.5 * (dev.array() * dev.array()).sum());
  }

  bool fibre_undefined(std::size_t i) const {
    return !fibre_undefined_.empty() && fibre_undefined_[i];
  }

  // What depends on the fibre at particle i: value(frame), or where the fibre rule leaves f0
  // undefined within the wall its mean over the wall's fibres (mean_over_wall_fibres). The mean of
  // the law's energies is an energy whose stress is the mean of the stresses, so such a particle
  // stays hyperelastic and the tangent's differences of P follow it.
  template <class Value>
  auto over_fibres(std::size_t i, const Mat<D>& frame, Value&& value) const {
    if constexpr (D == 3)
      if (fibre_undefined(i)) return mean_over_wall_fibres(frame, value);
    return value(frame);
  }

  // P of particle i: the law plus the active stress T_a F A0, A0 = f0 (x) f0; where the fibre
  // rule leaves f0 undefined within the wall, both are their means over the wall's fibres: the
  // law's by over_fibres, A0's in closed form, (I - s0 (x) s0) / 2 (fibre_undefined_in_wall).
  Mat<D> first_piola(std::size_t i, const Mat<D>& F, const Mat<D>& frame) const {
    Mat<D> P = material_.anisotropic()
                   ? over_fibres(i, frame, [&](const Mat<D>& f) { return material_.stress(F, f); })
                   : material_.stress(F, frame);
    if (active_ && (*active_)[i] != 0.0) {
      if (fibre_undefined(i)) {
        const Vec<D> s0 = frame.col(1);
        P.noalias() += 0.5 * (*active_)[i] * (F - (F * s0) * s0.transpose());
      } else {
        const Vec<D> f0 = frame.col(0);
        P.noalias() += (*active_)[i] * (F * f0) * f0.transpose();
      }
    }
    return P;
  }

  // The dual cell's points need the quadratic fit's curvature and a cell the lattice defines.
  void check_energy_quadrature_spec() const {
    const std::string key = key_ + ".energy_quadrature";
    if (spec_.gradient_correction() != "quadratic")
      throw ConfigError(key,
                        "dual_cell needs gradient_correction: quadratic (F at the cell's "
                        "points comes from the quadratic fit)");
    const auto& body = spec_.body();
    if (!body.has_shape() || body.perturbation() != 0.0)
      throw ConfigError(key,
                        "dual_cell needs a body placed on an unperturbed lattice or the "
                        "conforming grid (placement cell, vertex or conforming): they "
                        "define the particles' cells");
  }

  // W per unit reference volume at displacements u (F_ holds their F): at the particle, or the
  // mean over its cell's points.
  double strain_energy(std::size_t i, const Mat<D>& frame, const std::vector<Vec<D>>& u) const {
    auto energy = [&](const Mat<D>& F) {
      if (!material_.anisotropic()) return material_.energy(F, frame);  // no fibre to average
      return over_fibres(i, frame, [&](const Mat<D>& f) { return material_.energy(F, f); });
    };
    if (quadrature_.offset.empty()) return energy(F_[i]);
    const GradientSlopes<D> S = deformation_gradient_slopes<D>(pairs_, u, i);
    double sum = 0.0;
    for (const Vec<D>& d : quadrature_.offset[i]) sum += energy(gradient_at_offset<D>(F_[i], S, d));
    return sum / EnergyQuadrature<D>::points;
  }

  bool dual_cell_quadrature() const { return spec_.energy_quadrature() == "dual_cell"; }

  // The energy's points in every particle's cell (scene key energy_quadrature).
  void build_energy_quadrature() {
    const LatticePlacement placement = lattice_placement(spec_.body());
    const double spacing = spec_.body().spacing();
    // A conforming placement gives its cells; a lattice's are measured on the shape.
    if (placement != LatticePlacement::conforming && !body_shape_)
      body_shape_ = build_shape<D>(spec_.body().shape(), key_ + ".body.shape");
    quadrature_.offset.resize(X_.size());
    parallel_for_each_index(X_.size(), [&](std::size_t i) {
      const CellMoments<D> cell = Base::cells_.empty()
                                      ? cell_moments<D>(*body_shape_, X_[i], spacing, placement)
                                      : Base::cells_[i];
      quadrature_.offset[i] = EnergyQuadrature<D>::points_of(cell.centroid, cell.covariance);
    });
    Fq_.assign(X_.size(), {});
    T_.assign(X_.size(), {});
  }

  Vec<D> stress_divergence(std::size_t i) const {
    if (quadrature_.offset.empty()) return pair_stress_divergence<D>(pairs_, P_, i);
    return quadrature_stress_divergence<D>(pairs_, P_, T_, i);
  }

  const Surface<D>& surface() const {
    if (!surface_)
      surface_ = detect_surface<D>(X_, particles_.scalar("volume"), spec_.body().spacing());
    return *surface_;
  }

  void build_constraints() {
    for (int k = 0; k < spec_.constraints_size(); ++k) {
      const auto& c = spec_.constraints(k);
      const std::string path = key_ + ".constraints[" + std::to_string(k) + "]";
      auto shape = build_shape<D>(c.region().shape(), path + ".region.shape");
      Constraint constraint;
      constraint.particles = select_region<D>(X_, *shape);
      if (constraint.particles.empty())
        throw ConfigError(path + ".region", "the region contains no particle");
      switch (c.kind_case()) {
        case proto::Constraint::kClamp:
          constraint.kind = ConstraintKind::Clamp;
          break;
        case proto::Constraint::kFixed:
          constraint.kind = ConstraintKind::Fixed;
          for (int a : c.fixed().components()) {
            if (a < 0 || a >= D)
              throw ConfigError(path + ".fixed.components", "component " + std::to_string(a) +
                                                                " does not exist in " +
                                                                std::to_string(D) + "D");
            constraint.components[a] = true;
          }
          break;
        case proto::Constraint::kDisplacement:
        case proto::Constraint::kVelocity: {
          const bool displacement = c.has_displacement();
          constraint.kind = displacement ? ConstraintKind::Displacement : ConstraintKind::Velocity;
          const auto& m = displacement ? c.displacement() : c.velocity();
          for (int a = 0; a < m.values_size(); ++a)
            constraint.values.push_back(
                parse(m.values(a), path + (displacement ? ".displacement" : ".velocity") +
                                       ".values[" + std::to_string(a) + "]"));
          break;
        }
        case proto::Constraint::KIND_NOT_SET:
          throw ConfigError(path, "give one of: clamp, fixed, displacement, velocity");
      }
      constraints_.push_back(std::move(constraint));
    }
  }

  // The non-affine part of each particle's neighbourhood motion, the amplitude of zero-energy
  // (hourglass) modes: sqrt(sum_j W_ij |F_i X_ij - x_ij|^2 / sum_j W_ij |X_ij|^2).
  void update_hourglass_measure() {
    const auto& nl = pairs_.neighbours;
    const auto& u = particles_.vector("displacement");
    auto& measure = particles_.scalar("hourglass");
    parallel_for_each_index(u.size(), [&](std::size_t i) {
      double error = 0.0, scale = 0.0;
      for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
        const Index j = nl.index[k];
        const Vec<D> X_ij = X_[j] - X_[i];
        const double W = kernel_.value(X_ij.norm());
        error += W * (F_[i] * X_ij - (X_ij + u[j] - u[i])).squaredNorm();
        scale += W * X_ij.squaredNorm();
      }
      measure[i] = scale > 0.0 ? std::sqrt(error / scale) : 0.0;
    });
  }

  // Surface particles of each pressure region, with their reference area vectors N dA.
  void build_pressures() {
    for (int k = 0; k < spec_.pressures_size(); ++k) {
      const auto& spec = spec_.pressures(k);
      const std::string path = key_ + ".pressures[" + std::to_string(k) + "]";
      Pressure load;
      load.value = parse(spec.value(), path + ".value");
      if (spec.has_face() == spec.has_region())
        throw ConfigError(path, "a pressure needs either a region or a face (not both)");
      if (spec.has_face()) {
        if (spec.normal_size() > 0)
          throw ConfigError(path + ".normal", "a face's normals are its own; give no normal");
        const BoundaryFace<D>& face = find_face(spec.face(), path + ".face");
        for (std::size_t m = 0; m < face.particles.size(); ++m) {
          load.particles.push_back(static_cast<Index>(face.particles[m]));
          load.areas.push_back(face.areas[m]);
        }
        pressures_.push_back(std::move(load));
        continue;
      }
      if (lattice_placement(spec_.body()) == LatticePlacement::conforming)
        throw ConfigError(path + ".region",
                          "with placement conforming, name the pressure's face (inner, outer or "
                          "base) instead of a region: the face's areas are exact");
      auto shape = build_shape<D>(spec.region().shape(), path + ".region.shape");
      const Surface<D>& s = surface();
      const bool given = spec.normal_size() > 0;
      Vec<D> normal = Vec<D>::Zero();
      if (given) {
        normal = to_vec<D>(spec.normal());
        if (!(normal.norm() > 0.0)) throw ConfigError(path + ".normal", "normal is zero");
        normal.normalize();
      }
      for (std::size_t m = 0; m < s.particles.size(); ++m) {
        const Index i = s.particles[m];
        if (!shape->contains(X_[i])) continue;
        const Vec<D> n = given ? normal : s.normals[m];
        load.particles.push_back(i);
        load.areas.push_back(face_area(i, n, path) * n);
      }
      if (load.particles.empty())
        throw ConfigError(path + ".region", "the region contains no surface particle");
      pressures_.push_back(std::move(load));
    }
  }

  const BoundaryFace<D>& find_face(const std::string& name, const std::string& path) const {
    std::string known;
    for (const auto& face : Base::faces_) {
      if (face.name == name) return face;
      known += (known.empty() ? "" : ", ") + face.name;
    }
    throw ConfigError(path, known.empty()
                                ? "the body's placement knows no faces (placement: conforming "
                                  "on a truncated_ellipsoidal_shell does)"
                                : "no face '" + name + "' (the body's faces: " + known + ")");
  }

  // The face area dA a surface particle carries, its volume over the depth of that volume under
  // the face: a cell-centred particle's cell reaches one spacing in; a vertex particle's dual
  // cell reaches as far as the body's shape holds it along the normal (half a spacing for a node
  // on the face, more for a face between two layers of nodes), so that on a vertex lattice a
  // face's edge and corner particles carry their share of the face.
  double face_area(Index i, const Vec<D>& normal, const std::string& path) {
    const double volume = particles_.scalar("volume")[i];
    const double spacing = spec_.body().spacing();
    if (lattice_placement(spec_.body()) != LatticePlacement::vertex) return volume / spacing;
    if (!body_shape_) body_shape_ = build_shape<D>(spec_.body().shape(), key_ + ".body.shape");
    const double depth = dual_cell_depth<D>(*body_shape_, X_[i], normal, spacing);
    if (!(depth > 0.0)) {
      std::ostringstream where;
      where << X_[i].transpose();
      throw ConfigError(path + ".normal",
                        "the normal points out of the body on both sides of the surface particle "
                        "at X = (" +
                            where.str() + ")");
    }
    return volume / depth;
  }

  // Holds constrained particles at time t (before an acceleration is computed from u, v).
  void apply_constraints(double t, std::vector<Vec<D>>& u, std::vector<Vec<D>>& v) const {
    for (const auto& c : constraints_)
      for (Index i : c.particles) switch (c.kind) {
          case ConstraintKind::Clamp:
            u[i].setZero();
            v[i].setZero();
            break;
          case ConstraintKind::Fixed:
            for (int a = 0; a < D; ++a)
              if (c.components[a]) {
                u[i][a] = 0.0;
                v[i][a] = 0.0;
              }
            break;
          case ConstraintKind::Displacement: {
            const auto p = Base::space_time(X_[i], t);
            for (int a = 0; a < D; ++a) u[i][a] = c.values[a].evaluate(p);
            break;
          }
          case ConstraintKind::Velocity: {
            const auto p = Base::space_time(X_[i], t);
            for (int a = 0; a < D; ++a) v[i][a] = c.values[a].evaluate(p);
            break;
          }
        }
  }

  // Constrained components carry no acceleration (their motion is prescribed).
  void constrain_acceleration(std::vector<Vec<D>>& a) const {
    for (const auto& c : constraints_)
      for (Index i : c.particles) {
        if (c.kind == ConstraintKind::Fixed) {
          for (int d = 0; d < D; ++d)
            if (c.components[d]) a[i][d] = 0.0;
        } else {
          a[i].setZero();
        }
      }
  }

  // a(u, v, t) without damping: stress divergence, artificial viscosity, hourglass control, body
  // force, follower pressure, external force; constrained components zeroed.
  void compute_acceleration(double t, const std::vector<Vec<D>>& u, const std::vector<Vec<D>>& v,
                            std::vector<Vec<D>>& a) {
    const std::size_t n = u.size();
    const bool viscosity = spec_.has_artificial_viscosity();
    const bool hourglass = pair_hourglass();
    update_active_tension(t);
    if (fit_control_) fit_control_->update_residuals(u);
    const auto& volume = particles_.scalar("volume");
    const std::size_t grain = pair_loop_grain(n, pairs_.neighbours.pair_count());
    parallel_for_each_index(
        n,
        [&](std::size_t i) {
          const Mat<D>& F = F_[i] = deformation_gradient<D>(pairs_, u, i);
          const Mat<D> frame = frames_.empty() ? Mat<D>::Identity() : frames_[i];
          if (quadrature_.offset.empty())
            P_[i] = first_piola(i, F, frame);
          else
            P_[i] = integrate_stress<D>(
                quadrature_, i, F, deformation_gradient_slopes<D>(pairs_, u, i),
                [&](const Mat<D>& F_q) { return first_piola(i, F_q, frame); }, T_[i], &Fq_[i]);
          x_[i] = X_[i] + u[i];
          if (viscosity) {
            const double J = F.determinant();
            A_[i] = J * F.inverse().transpose();
            density_[i] = material_.density() / J;
          }
        },
        grain);
    const double rho0 = material_.density();
    const Vec<D> gravity = body_force_ * load_factor(t);
    const ViscosityParameters viscous{spec_.artificial_viscosity().alpha(),
                                      spec_.artificial_viscosity().beta(), material_.wave_speed(),
                                      kernel_.smoothing_length()};
    const double stiffness = spec_.hourglass_control().coefficient() * material_.young_modulus();
    parallel_for_each_index(
        n,
        [&](std::size_t i) {
          Vec<D> force = stress_divergence(i);
          if (viscosity) force += artificial_viscosity<D>(pairs_, x_, v, density_, A_, viscous, i);
          if (hourglass) force += hourglass_force<D>(pairs_, X_, x_, F_, stiffness, i);
          if (fit_control_) force += fit_control_->force(i) / volume[i];
          a[i] = force / rho0 + gravity;
        },
        grain);
    const auto& mass = particles_.scalar("mass");
    const double factor = load_factor(t);
    for (const auto& load : pressures_)
      for (std::size_t k = 0; k < load.particles.size(); ++k) {
        const Index i = load.particles[k];
        const double p = factor * load.value.evaluate(Base::space_time(X_[i], t));
        const Mat<D>& F = F_[i];
        // Nanson: n da = J F^-T N dA; the pressure pushes against the outward normal.
        a[i] -= (p * F.determinant() / mass[i]) * (F.inverse().transpose() * load.areas[k]);
      }
    if (!external_force_.empty())
      for (std::size_t i = 0; i < n; ++i) a[i] += external_force_[i] / mass[i];
    constrain_acceleration(a);
  }

  // Largest eigenvalue of the linearised acceleration q -> -(a(u + eps q) - a(u)) / eps at the
  // current state (constraints included), by power iteration from a fixed start vector, so that it
  // is the same on every run and thread count. Redone every kStiffnessInterval steps because
  // exponential laws stiffen as they deform; checkpointed with the state.
  void update_stiffness_eigenvalue() {
    const auto& u = particles_.vector("displacement");
    const auto& v = particles_.vector("velocity");
    const std::size_t n = u.size();
    std::vector<Vec<D>> q(n), shifted(n), a0(n), a1(n);
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < D; ++c)  // deterministic pseudo-random start (Weyl sequence)
        q[i][c] = std::fmod(0.618033988749895 * double(i * D + c + 1), 1.0) - 0.5;
    const double h = kernel_.smoothing_length();
    compute_acceleration(time_, u, v, a0);
    double lambda = 0.0;
    for (int iteration = 0; iteration < 30; ++iteration) {
      const double norm =
          std::sqrt(deterministic_sum(n, 0.0, [&](std::size_t i) { return q[i].squaredNorm(); }));
      if (!(norm > 0.0) || !std::isfinite(norm)) break;
      // A unit vector of displacements, scaled so that a typical particle moves 1e-7 h.
      const double eps = 1e-7 * h * std::sqrt(double(n));
      parallel_stream(n, [&](std::size_t i) { shifted[i] = u[i] + (eps / norm) * q[i]; });
      compute_acceleration(time_, shifted, v, a1);
      parallel_stream(n, [&](std::size_t i) { q[i] = (a0[i] - a1[i]) / eps; });
      lambda =
          std::sqrt(deterministic_sum(n, 0.0, [&](std::size_t i) { return q[i].squaredNorm(); }));
    }
    stiffness_eigenvalue_ = lambda;
  }

  void update_active_tension(double t) {
    if (!spec_.has_active_tension()) return;
    auto& T = particles_.scalar("active_tension");
    parallel_for_each_index(T.size(), [&](std::size_t i) {
      T[i] = active_tension_.evaluate(Base::space_time(X_[i], t));
    });
  }

  // Position Verlet (seed 001 eqs. 47-49): half drift, kick with the mid-step acceleration, half
  // drift. Damping is implicit in the kick (unconditionally stable).
  void advance_verlet(double dt) {
    auto& u = particles_.vector("displacement");
    auto& v = particles_.vector("velocity");
    auto& a = particles_.vector("acceleration");
    auto& x = particles_.vector("position");
    const double t = time_, half = 0.5 * dt, damping = 1.0 / (1.0 + spec_.damping() * dt);
    parallel_stream(u.size(), [&](std::size_t i) { u[i] += half * v[i]; });
    apply_constraints(t + half, u, v);
    compute_acceleration(t + half, u, v, a);
    // Through raw pointers: with the vectors captured by reference the compiler reloads their
    // data pointers after every store, as they might alias (1.5% of a small solid's step).
    Vec<D>* const up = u.data();
    Vec<D>* const vp = v.data();
    const Vec<D>* const ap = a.data();
    parallel_stream(u.size(), [=](std::size_t i) {
      vp[i] = (vp[i] + dt * ap[i]) * damping;
      up[i] += half * vp[i];
    });
    finish_constraints(t, dt, u, v);
    parallel_stream(u.size(), [&](std::size_t i) { x[i] = X_[i] + u[i]; });
  }

  // Classical RK4 on (u, v) (seed 000), damping explicit in the rates.
  void advance_rk4(double dt) {
    auto& u = particles_.vector("displacement");
    auto& v = particles_.vector("velocity");
    auto& a = particles_.vector("acceleration");
    auto& x = particles_.vector("position");
    const std::size_t n = u.size();
    const double t = time_, zeta = spec_.damping();
    u0_ = u;
    v0_ = v;
    us_ = u;
    vs_ = v;
    du_.assign(n, Vec<D>::Zero());
    dv_.assign(n, Vec<D>::Zero());
    const double c[4] = {0.0, 0.5, 0.5, 1.0}, w[4] = {1.0 / 6, 2.0 / 6, 2.0 / 6, 1.0 / 6};
    for (int s = 0; s < 4; ++s) {
      if (s > 0)
        parallel_stream(n, [&](std::size_t i) {
          const Vec<D> rate_u = vs_[i];  // the previous stage's rates: (v_s, a_s)
          us_[i] = u0_[i] + c[s] * dt * rate_u;
          vs_[i] = v0_[i] + c[s] * dt * a[i];
        });
      apply_constraints(t + c[s] * dt, us_, vs_);
      compute_acceleration(t + c[s] * dt, us_, vs_, a);
      parallel_stream(n, [&](std::size_t i) {
        a[i] -= zeta * vs_[i];
        du_[i] += w[s] * vs_[i];
        dv_[i] += w[s] * a[i];
      });
    }
    parallel_stream(n, [&](std::size_t i) {
      u[i] = u0_[i] + dt * du_[i];
      v[i] = v0_[i] + dt * dv_[i];
    });
    finish_constraints(t, dt, u, v);
    parallel_stream(n, [&](std::size_t i) { x[i] = X_[i] + u[i]; });
  }

  // End-of-step constraints: clamps and fixed components stay put, prescribed velocities take
  // their value at t + dt, prescribed displacements theirs (with the velocity that reaches it).
  void finish_constraints(double t, double dt, std::vector<Vec<D>>& u, std::vector<Vec<D>>& v) {
    apply_constraints(t + dt, u, v);
    for (const auto& c : constraints_) {
      if (c.kind != ConstraintKind::Displacement) continue;
      for (Index i : c.particles) {
        const auto before = Base::space_time(X_[i], t), after = Base::space_time(X_[i], t + dt);
        for (int a = 0; a < D; ++a)
          v[i][a] = (c.values[a].evaluate(after) - c.values[a].evaluate(before)) / dt;
      }
    }
  }

  // ---- Steady state (static equilibrium by Newton, static_equilibrium.hpp) ----

  bool steady() const { return spec_.has_steady_state(); }
  bool pair_hourglass() const {
    return spec_.has_hourglass_control() && spec_.hourglass_control().form() == "pair";
  }
  bool fit_residual_hourglass() const {
    return spec_.has_hourglass_control() && spec_.hourglass_control().form() == "fit_residual";
  }

  static std::string short_number(double v) {
    std::ostringstream o;
    o << v;
    return o.str();
  }

  // What a static solve cannot honour is refused with its key: it has no velocities, and the
  // pair hourglass forces have no tangent here.
  void check_steady_state_spec() const {
    const std::string why = " is not allowed with steady_state (a static solve has no velocities)";
    if (spec_.initial_velocity_size() > 0)
      throw ConfigError(key_ + ".initial_velocity", "initial_velocity" + why);
    if (spec_.has_time_step())
      throw ConfigError(key_ + ".time_step",
                        "time_step is not used with steady_state: its steps are the load "
                        "increments (steady_state.load_steps over load_ramp_time)");
    if (pair_hourglass())
      throw ConfigError(key_ + ".hourglass_control",
                        "hourglass control of form 'pair' is not supported with steady_state (its "
                        "forces have no tangent in the Newton solve); use form: fit_residual");
    for (int k = 0; k < spec_.constraints_size(); ++k)
      if (spec_.constraints(k).has_velocity())
        throw ConfigError(key_ + ".constraints[" + std::to_string(k) + "].velocity",
                          "a prescribed velocity" + why + "; prescribe a displacement");
  }

  void build_static_equilibrium() {
    const std::size_t n = X_.size();
    prescribed_.assign(n * D, 0);
    for (const auto& c : constraints_)
      for (Index i : c.particles)
        for (int a = 0; a < D; ++a)
          if (c.kind != ConstraintKind::Fixed || c.components[a]) prescribed_[i * D + a] = 1;
    equilibrium_.emplace(pairs_, particles_.scalar("volume"), prescribed_);
    zero_velocity_.assign(n, Vec<D>::Zero());
    internal_force_.assign(n, Vec<D>::Zero());
    loaded_slot_.assign(n, -1);
    for (const auto& load : pressures_)
      for (Index i : load.particles)
        if (loaded_slot_[i] < 0) {
          loaded_slot_[i] = static_cast<long long>(loaded_particles_.size());
          loaded_particles_.push_back(i);
        }
    static_body_.prescribe = [this](double t, std::vector<Vec<D>>& u) {
      apply_constraints(t, u, zero_velocity_);
    };
    static_body_.force = [this](double t, const std::vector<Vec<D>>& u, std::vector<Vec<D>>& f) {
      return static_force(t, u, f);
    };
    static_body_.control = fit_control_ ? &*fit_control_ : nullptr;
    static_body_.quadrature = quadrature_.offset.empty() ? nullptr : &quadrature_;
    static_body_.tangents = [this](double t, std::vector<MaterialTangent<D>>& C,
                                   std::vector<Index>& loaded, std::vector<ForceTangent<D>>& L) {
      static_tangents(t, C, loaded, L);
    };
  }

  // The net force m a at rest (v = 0), and the scale max(|f_internal|, |f_external|) over the
  // free components, f_internal = V_i (stress divergence).
  double static_force(double t, const std::vector<Vec<D>>& u, std::vector<Vec<D>>& force) {
    compute_acceleration(t, u, zero_velocity_, force);
    const auto& mass = particles_.scalar("mass");
    const auto& volume = particles_.scalar("volume");
    parallel_for_each_index(u.size(), [&](std::size_t i) {
      force[i] *= mass[i];
      internal_force_[i] = volume[i] * stress_divergence(i);
    });
    auto free_norm = [&](auto&& component) {
      return std::sqrt(deterministic_sum(u.size(), 0.0, [&](std::size_t i) {
        double sum = 0.0;
        for (int a = 0; a < D; ++a)
          if (!prescribed_[i * D + a]) sum += component(i, a) * component(i, a);
        return sum;
      }));
    };
    const double internal = free_norm([&](std::size_t i, int a) { return internal_force_[i][a]; });
    const double external =
        free_norm([&](std::size_t i, int a) { return force[i][a] - internal_force_[i][a]; });
    return std::max(internal, external);
  }

  // dP/dF of every particle and df/dF of the follower pressure's particles, at F_ (the last
  // static_force call), by central differences of the laws themselves.
  void static_tangents(double t, std::vector<MaterialTangent<D>>& C, std::vector<Index>& loaded,
                       std::vector<ForceTangent<D>>& L) {
    const std::size_t n = X_.size();
    const int points = quadrature_.offset.empty() ? 1 : EnergyQuadrature<D>::points;
    C.resize(n * static_cast<std::size_t>(points));
    parallel_for_each_index(n, [&](std::size_t i) {
      const Mat<D> frame = frames_.empty() ? Mat<D>::Identity() : frames_[i];
      for (int q = 0; q < points; ++q)
        C[i * points + q] = derivative_in_F<D, D * D>(
            [&](const Mat<D>& F) { return flatten<D>(first_piola(i, F, frame)); },
            points == 1 ? F_[i] : Fq_[i][q]);
    });
    loaded = loaded_particles_;
    L.assign(loaded.size(), ForceTangent<D>::Zero());
    const double factor = load_factor(t);
    for (const auto& load : pressures_)
      for (std::size_t k = 0; k < load.particles.size(); ++k) {
        const Index i = load.particles[k];
        const double p = factor * load.value.evaluate(Base::space_time(X_[i], t));
        const Vec<D> area = load.areas[k];
        L[static_cast<std::size_t>(loaded_slot_[i])] += derivative_in_F<D, D>(
            [&](const Mat<D>& F) -> Vec<D> {
              return -p * F.determinant() * (F.inverse().transpose() * area);
            },
            F_[i]);
      }
  }

  // The factorisation the uninterrupted run would start its next increment on, rebuilt where the
  // checkpoint says it was taken, so that a restart continues bit for bit.
  void restore_steady_tangent(const std::vector<double>& flat, double force_time,
                              double tangent_time) {
    const bool finite =
        std::isfinite(force_time) && std::isfinite(tangent_time) &&
        std::all_of(flat.begin(), flat.end(), [](double v) { return std::isfinite(v); });
    if (!finite)
      throw RuntimeError("module '" + name_ +
                         "': the checkpoint's steady-state tangent point is not finite");
    typename StaticEquilibrium<D>::TangentPoint point{std::vector<Vec<D>>(X_.size()), force_time,
                                                      tangent_time};
    for (std::size_t i = 0; i < X_.size(); ++i)
      point.u[i] = Eigen::Map<const Vec<D>>(flat.data() + i * D);
    try {
      equilibrium_->restore_tangent(point, static_body_);
    } catch (const RuntimeError& e) {
      throw RuntimeError("module '" + name_ + "': " + e.what());
    }
    // The tangent's force call set F, P and the active tension of its own point and load time;
    // those of the checkpoint's state come back.
    std::vector<Vec<D>> force(X_.size());
    static_force(time_, particles_.vector("displacement"), force);
  }

  // One step is a load increment to t + dt, bisected where Newton does not converge.
  void advance_steady(double dt) {
    auto& u = particles_.vector("displacement");
    if (coarse_)
      solve_from_coarse_level(time_, time_ + dt, u);
    else
      solve_increment(time_, time_ + dt, u, 0);
    static_force(time_ + dt, u, particles_.vector("acceleration"));  // F, P of the solution
    auto& x = particles_.vector("position");
    for (std::size_t i = 0; i < u.size(); ++i) x[i] = X_[i] + u[i];
    std::fill(particles_.vector("velocity").begin(), particles_.vector("velocity").end(),
              Vec<D>::Zero());
    std::fill(particles_.vector("acceleration").begin(), particles_.vector("acceleration").end(),
              Vec<D>::Zero());
  }

  // ---- Grid sequencing (steady_state.grid_sequence) ----

  // The same module at twice the spacing, one level fewer; the coarsest takes the step in the
  // grid sequence's load_steps increments and has no sequence of its own.
  void build_coarse_level(const proto::ModuleSpec& spec, const ModuleContext& context) {
    const std::string key = key_ + ".steady_state.grid_sequence";
    if (!spec_.body().has_shape())
      throw ConfigError(key,
                        "grid sequencing needs a body generated from a shape (a coarser "
                        "version of the body's particles is built from it)");
    const auto& sequence = spec_.steady_state().grid_sequence();
    proto::ModuleSpec coarse = spec;
    coarse.set_name(spec.name() + " (grid level " + std::to_string(sequence.levels()) + ")");
    auto& solid = *coarse.mutable_solid();
    solid.mutable_body()->set_spacing(2.0 * spec_.body().spacing());
    solid.clear_outputs();
    auto& steady = *solid.mutable_steady_state();
    if (sequence.levels() > 1)
      steady.mutable_grid_sequence()->set_levels(sequence.levels() - 1);
    else
      steady.clear_grid_sequence();
    coarse_ = std::make_unique<SolidModule>(coarse, context);
  }

  const SolidModule& coarsest() const { return coarse_ ? coarse_->coarsest() : *this; }

  // The coarse level's displacements interpolated at this body's reference positions.
  std::vector<Vec<D>> coarse_displacements() {
    if (!prolongation_) {
      std::vector<std::string> fields;
      for (int a = 0; a < D; ++a) fields.push_back(std::string("displacement.") + "xyz"[a]);
      prolongation_.emplace(
          X_, fields, std::vector<std::string>{},
          ProbeOptions{"reference_position", ProbeOptions::Interpolation::linear});
    }
    const auto values =
        prolongation_->sample(coarse_->particles_, "volume", coarse_->kernel_, coarse_->domain_);
    std::vector<Vec<D>> u(X_.size());
    for (std::size_t i = 0; i < u.size(); ++i)
      for (int a = 0; a < D; ++a) {
        const double v = values[a * u.size() + i];
        u[i][a] = std::isfinite(v) ? v : 0.0;  // no coarse particle near: no guess there
      }
    return u;
  }

  // The step from the coarse level's guess (guess_from_coarse_level); where there is none that
  // converges, from the last equilibrium in the coarsest level's increments, as without a coarse
  // level.
  void solve_from_coarse_level(double t0, double t1, std::vector<Vec<D>>& u) {
    if (!coarse_failed_ && guess_from_coarse_level(t0, t1, u)) return;
    ++coarse_guesses_rejected_;
    const int increments = spec_.steady_state().grid_sequence().load_steps();
    for (int k = 0; k < increments; ++k)
      solve_increment(t0 + (t1 - t0) * k / increments, t0 + (t1 - t0) * (k + 1) / increments, u, 0);
  }

  // The step solved at the coarse level first; this level starts from the coarse increment
  // added to its last equilibrium, smoothed, on a fresh tangent at the load of t1. Returns false
  // with u unchanged where the guess does not converge, or where the coarse level itself does not
  // (too coarse to carry the load: Land's ventricle at 2 mm with the energy at the nodes, in three
  // increments); a failed coarse level is not asked again.
  bool guess_from_coarse_level(double t0, double t1, std::vector<Vec<D>>& u) {
    const std::vector<Vec<D>> start = u;
    try {
      const ScopedSeconds timer(coarse_seconds_);
      const std::vector<Vec<D>> before = coarse_displacements();
      const int increments =
          coarse_->coarse_ ? 1 : spec_.steady_state().grid_sequence().load_steps();
      for (int k = 0; k < increments; ++k) coarse_->advance((t1 - t0) / increments);
      const std::vector<Vec<D>> after = coarse_displacements();
      for (std::size_t i = 0; i < u.size(); ++i) u[i] += after[i] - before[i];
    } catch (const RuntimeError&) {
      coarse_failed_ = true;
      return false;
    }
    const SmoothingOutcome smoothing = equilibrium_->smooth(
        t1, u, static_body_, spec_.steady_state().grid_sequence().smoothing_sweeps());
    smoothing_sweeps_ += smoothing.sweeps;
    const NewtonOutcome outcome = equilibrium_->solve(t1, t1, u, static_body_, newton_settings());
    count(outcome);
    if (outcome.converged) {
      ++steady_increments_;
      return true;
    }
    u = start;
    return false;
  }

  // The coarse level's state is a child record of this one's.
  void save_coarse_level(StateRecord& state) const {
    StateRecord child;
    child.name = coarse_->name_;
    coarse_->save(child);
    state.children.push_back(std::move(child));
  }

  void load_coarse_level(const StateRecord& state) {
    for (const auto& child : state.children)
      if (child.name == coarse_->name_) return coarse_->load(child);
    throw RuntimeError("module '" + name_ +
                       "': the checkpoint holds no state of its coarse level '" + coarse_->name_ +
                       "' (written without grid_sequence?)");
  }

  NewtonSettings newton_settings() const {
    return {spec_.steady_state().tolerance(), spec_.steady_state().max_iterations()};
  }

  void count(const NewtonOutcome& outcome) {
    newton_iterations_ += outcome.iterations;
    residual_evaluations_ += outcome.residual_evaluations;
    factorisations_ += outcome.factorisations;
    shifted_factorisations_ += outcome.shifted_factorisations;
    steady_residual_ = outcome.relative_residual;
  }

  void solve_increment(double t0, double t1, std::vector<Vec<D>>& u, int depth) {
    constexpr int kMaxBisections = 6;
    const std::vector<Vec<D>> start = u;
    const NewtonOutcome outcome = equilibrium_->solve(t0, t1, u, static_body_, newton_settings());
    count(outcome);
    if (outcome.converged) {
      ++steady_increments_;
      return;
    }
    if (depth == kMaxBisections)
      throw RuntimeError(
          "module '" + name_ + "': the steady state at t = " + short_number(t1) +
          " did not converge (relative residual " + short_number(outcome.relative_residual) +
          " after " + std::to_string(outcome.iterations) + " Newton iterations, load increment " +
          short_number(t1 - t0) + " after " + std::to_string(kMaxBisections) +
          " bisections); the load may exceed what the body can carry");
    ++steady_bisections_;
    u = start;
    solve_increment(t0, 0.5 * (t0 + t1), u, depth + 1);
    solve_increment(0.5 * (t0 + t1), t1, u, depth + 1);
  }

  proto::SolidSpec spec_;
  MaterialModel<D> material_;
  // 2D is plane strain: the out-of-plane stress sigma_zz that holds F_zz = 1 enters the von Mises
  // stress. The same law in 3D gives it (built only when von Mises is asked for, in 2D).
  std::optional<MaterialModel<3>> plane_strain_;
  Expression active_tension_;
  std::vector<Expression> initial_velocity_;
  std::vector<Vec<D>> X_, x_;
  std::vector<Mat<D>> frames_, F_, P_, A_;  // P: first Piola; A = J F^-T (viscosity)
  // energy_quadrature: dual_cell only: the points, F there and the stresses' first moments.
  EnergyQuadrature<D> quadrature_;
  std::vector<std::array<Mat<D>, EnergyQuadrature<D>::points>> Fq_;
  std::vector<StressMoments<D>> T_;
  std::vector<double> density_;
  std::vector<char> fibre_undefined_;  // per particle, where the fibre rule is singular; or empty
  const std::vector<double>* active_ = nullptr;  // T_a per particle, when there is one
  ReferencePairs<D> pairs_;
  std::vector<Constraint> constraints_;
  std::vector<Pressure> pressures_;
  Vec<D> body_force_ = Vec<D>::Zero();
  std::vector<Vec<D>> external_force_;
  mutable std::optional<Surface<D>> surface_;
  ShapePtr<D> body_shape_;  // built for vertex pressure areas and lattice cells only
  std::vector<Vec<D>> u0_, v0_, us_, vs_, du_, dv_;  // RK4 stages (RK4 only)
  static constexpr long long kStiffnessInterval = 1000;
  // Steady state only.
  std::optional<StaticEquilibrium<D>> equilibrium_;
  std::optional<FitResidualControl<D>> fit_control_;  // hourglass_control of form fit_residual
  typename StaticEquilibrium<D>::Body static_body_;
  std::vector<char> prescribed_;  // per component: held by a constraint
  std::vector<Vec<D>> zero_velocity_, internal_force_;
  std::vector<Index> loaded_particles_;  // particles under a follower pressure
  std::vector<long long> loaded_slot_;   // their index in loaded_particles_ (-1: none)
  long long steady_increments_ = 0, steady_bisections_ = 0, newton_iterations_ = 0,
            residual_evaluations_ = 0, factorisations_ = 0, shifted_factorisations_ = 0;
  double steady_residual_ = 0.0;
  // Grid sequencing only: the same body at twice the spacing, and what interpolates its
  // displacements at this body's reference positions.
  std::unique_ptr<SolidModule> coarse_;
  std::optional<PointProbe<D>> prolongation_;
  long long smoothing_sweeps_ = 0, coarse_guesses_rejected_ = 0;
  bool coarse_failed_ = false;  // the coarse level did not converge: no more guesses
  double coarse_seconds_ = 0.0;
  double stiffness_eigenvalue_ = 0.0;
};

}  // namespace

std::unique_ptr<Module> make_solid_module(const proto::ModuleSpec& spec,
                                          const ModuleContext& context) {
  if (context.scene->dimension() == 2) return std::make_unique<SolidModule<2>>(spec, context);
  return std::make_unique<SolidModule<3>>(spec, context);
}

}  // namespace cosph
