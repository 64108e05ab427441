#include "fsi/fsi_coupler.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.hpp"
#include "driver/state_reader.hpp"

namespace cosph {
namespace {

// A number with six significant digits: a step of 1e-9 s reads as such, not as 0.000000.
std::string significant(double x) {
  std::ostringstream out;
  out << x;
  return out.str();
}

// The full name of the port a child offers as `port`: its own port, or a nested child's
// ("solid.port" when the child is itself a coupler). Empty if none, or if two children offer it.
std::string find_port(const ModuleInfo& info, bool writes, const std::string& port,
                      const std::vector<std::string>& fields) {
  std::string found;
  for (const auto& p : writes ? info.writes : info.reads) {
    const bool named =
        p.name == port || (p.name.size() > port.size() + 1 && p.name.ends_with("." + port));
    if (!named) continue;
    bool complete = true;
    for (const auto& f : fields)
      complete = complete && std::find(p.fields.begin(), p.fields.end(), f) != p.fields.end();
    if (!complete) continue;
    if (!found.empty()) return {};
    found = p.name;
  }
  return found;
}

// One step of the coupler is one advection step of the fluid. At each of its acoustic sub-steps
// (seed 003 section 6.2):
//  1. the fluid takes the sub-step dt_ac, seeing the solid particles as a contact boundary with
//     the solid's velocity (and, if the scene asks, acceleration) averaged over the solid's
//     sub-steps of the previous acoustic step;
//  2. the fluid's force on every solid particle in that sub-step — the reaction of the Riemann
//     pressures the fluid used, plus the viscous force of the advection step (or of the
//     sub-step, where the fluid sub-cycles it) — goes to the solid's external force, so the
//     impulse balances to round-off;
//  3. the solid advances over dt_ac in kappa = floor(dt_ac / dt_solid) + 1 equal sub-steps with
//     that force held;
//  4. its average velocity (displacement / dt_ac) and acceleration (velocity change / dt_ac) over
//     them, with its new positions, go to the fluid's contact set.
// After the last sub-step the solid is handed the force averaged over the step's sub-steps (each
// weighted by its length), so that what it holds between steps — its `external_force` output, a
// drag or lift probe — carries the impulse it received over the step. The last sub-step's force
// alone is one phase of the fluid's cycle within the step. Every sub-step reads its own force
// before the solid moves, so the motion is unchanged by this.
// Checkpoints fall between coupler steps; the averages are the coupler's own state (they cannot
// be recomputed from the solid's), and every input is sent again after a restart.
class FsiCoupler final : public Coupler {
 public:
  FsiCoupler(const proto::CouplerSpec& spec, std::vector<std::unique_ptr<Module>> children,
             const CouplerContext& context)
      : Coupler("fsi", spec.name(), std::move(children)) {
    const std::string key = context.key_path + ".fsi";
    const ModuleInfo fluid = child(0).info(), solid = child(1).info();
    auto need = [&](const ModuleInfo& m, const std::string& role, bool writes,
                    const std::string& port, const std::vector<std::string>& fields) {
      std::string name = find_port(m, writes, port, fields);
      if (name.empty()) {
        std::string list;
        for (const auto& f : fields) list += (list.empty() ? "" : ", ") + f;
        throw ConfigError(key + "." + role, "module '" + m.name + "' (" + m.type + ") does not " +
                                                (writes ? "write" : "read") + " the port '" + port +
                                                "' (" + list + ") that FSI needs of a " + role);
      }
      return name;
    };
    contact_port_ = need(fluid, "fluid", false, "contact", {"position", "velocity", "volume"});
    force_port_ = need(fluid, "fluid", true, "contact_force", {"force"});
    particles_port_ =
        need(solid, "solid", true, "particles", {"position", "velocity", "acceleration", "volume"});
    external_force_port_ = need(solid, "solid", false, "external_force", {"force"});
    if (fluid.dimension != solid.dimension)
      throw ConfigError(key + ".solid", "module '" + solid.name + "' is " +
                                            std::to_string(solid.dimension) + "D, the fluid " +
                                            std::to_string(fluid.dimension) + "D");
    if (solid.spacing > fluid.spacing * (1.0 + 1e-12)) {
      std::ostringstream msg;
      msg << "the solid's spacing " << solid.spacing << " is coarser than the fluid's "
          << fluid.spacing << " (multi-resolution FSI needs h_solid <= h_fluid)";
      throw ConfigError(key + ".solid", msg.str());
    }
    dimension_ = fluid.dimension;
    solid_acceleration_in_pressure_ = spec.fsi().solid_acceleration_in_pressure();
    resolution_ratio_ = solid.spacing / fluid.spacing;
  }

  double max_dt() const override { return fluid().max_dt(); }

  void advance(double Dt) override {
    impulse_time_ = 0.0;  // the last step's impulse (or a step's that threw part-way) emptied
    fluid().begin_step(Dt);
    for (double dt = fluid().max_substep(); dt > 0.0; dt = fluid().max_substep()) {
      fluid().substep(dt);
      fluid().write(force_port_, force_);
      solid().read(external_force_port_, force_);
      add_impulse(dt);
      const double solid_dt = solid().max_dt();
      if (!(solid_dt > 0.0) || !std::isfinite(solid_dt))
        throw RuntimeError("FSI coupler: the solid's stable step is " + significant(solid_dt) +
                           " at t = " + significant(fluid().time()));
      // Thousands of sub-steps per acoustic step are normal for stiff gates (measured up to
      // ~400); a million means a broken state (a restored step limit gone wrong, or a solid gone
      // unstable), not physics.
      if (!(dt / solid_dt < kMaxSubsteps))
        throw RuntimeError("FSI coupler: the solid's stable step " + significant(solid_dt) +
                           " s would take more than " + std::to_string(long(kMaxSubsteps)) +
                           " sub-steps of the fluid's acoustic step " + significant(dt) +
                           " s at t = " + significant(fluid().time()) +
                           " (a solid gone unstable, or a step limit restored wrong)");
      const long long kappa = static_cast<long long>(std::floor(dt / solid_dt)) + 1;
      for (long long k = 0; k < kappa; ++k) solid().advance(dt / double(kappa));
      solid().write(particles_port_, after_);
      average(dt);
      send_contact();
      std::swap(before_, after_);
      ++acoustic_steps_;
      solid_substeps_ += kappa;
    }
    hand_mean_force();
    fluid().end_step();
  }

 protected:
  std::vector<std::string> features() const override {
    std::vector<std::string> f;
    f.push_back("fluid '" + child(0).info().name + "' sees solid '" + child(1).info().name +
                "' as a contact body (one-sided Riemann, velocity averaged over its sub-steps)");
    std::ostringstream sub;
    sub << "solid sub-stepping (kappa = floor(dt_acoustic / dt_solid) + 1";
    if (acoustic_steps_ > 0) sub << ", mean " << double(solid_substeps_) / double(acoustic_steps_);
    sub << ")";
    f.push_back(sub.str());
    if (solid_acceleration_in_pressure_)
      f.push_back("solid acceleration in the fluid's pressure extension");
    if (resolution_ratio_ < 1.0 - 1e-12) {
      std::ostringstream m;
      m << "multi-resolution (solid spacing / fluid spacing = " << resolution_ratio_ << ")";
      f.push_back(m.str());
    }
    return f;
  }

  // The solid as it is now, with the averages of the last acoustic step (at the start: its
  // current velocity and acceleration).
  void connect() override {
    solid().write(particles_port_, before_);
    if (velocity_average_.empty()) {
      velocity_average_ = before_.arrays.at("velocity").values;
      acceleration_average_ = before_.arrays.at("acceleration").values;
    }
    after_ = before_;
    send_contact();
  }

  void save_own(StateRecord& state) const override {
    state.arrays["velocity_average"] = velocity_average_;
    state.arrays["acceleration_average"] = acceleration_average_;
    state.integers["acoustic_steps"] = acoustic_steps_;
    state.integers["solid_substeps"] = solid_substeps_;
  }

  void load_own(const StateRecord& state) override {
    const StateReader read(state, "coupler '" + info().name + "'");
    const std::size_t values = velocity_average_.size();  // the solid's interface, built by connect
    velocity_average_ = read.array("velocity_average", values);
    acceleration_average_ = read.array("acceleration_average", values);
    acoustic_steps_ = read.integer("acoustic_steps");
    solid_substeps_ = read.integer("solid_substeps");
  }

 private:
  Module& fluid() { return child(0); }
  const Module& fluid() const { return child(0); }
  Module& solid() { return child(1); }
  const Module& solid() const { return child(1); }

  // Velocity and acceleration of each solid particle averaged over the acoustic step dt.
  void average(double dt) {
    const auto& x0 = before_.arrays.at("position").values;
    const auto& x1 = after_.arrays.at("position").values;
    const auto& v0 = before_.arrays.at("velocity").values;
    const auto& v1 = after_.arrays.at("velocity").values;
    if (x0.size() != x1.size())
      throw RuntimeError("FSI: the solid's particle count changed during the run");
    velocity_average_.resize(x1.size());
    acceleration_average_.resize(x1.size());
    for (std::size_t c = 0; c < x1.size(); ++c) {
      velocity_average_[c] = (x1[c] - x0[c]) / dt;
      acceleration_average_[c] = (v1[c] - v0[c]) / dt;
    }
  }

  // The force of the sub-step just taken, times its length, added to the step's impulse.
  void add_impulse(double dt) {
    const auto& f = force_.arrays.at("force").values;
    if (impulse_time_ == 0.0) impulse_.assign(f.size(), 0.0);
    if (impulse_.size() != f.size())
      throw RuntimeError("FSI: the fluid's contact force changed its size within a step");
    for (std::size_t c = 0; c < f.size(); ++c) impulse_[c] += f[c] * dt;
    impulse_time_ += dt;
  }

  // The step's mean force to the solid (advance empties the impulse at the next step's start).
  void hand_mean_force() {
    if (!(impulse_time_ > 0.0)) return;
    auto& f = force_.arrays.at("force").values;
    for (std::size_t c = 0; c < f.size(); ++c) f[c] = impulse_[c] / impulse_time_;
    solid().read(external_force_port_, force_);
  }

  void send_contact() {
    contact_.points = after_.points;
    contact_.arrays["position"] = after_.arrays.at("position");
    contact_.arrays["volume"] = after_.arrays.at("volume");
    // Its masses, where the solid offers them, bound the fluid's exchange interval under a
    // sub-cycled viscous force (the fluid's contact_viscous_dt).
    if (auto m = after_.arrays.find("mass"); m != after_.arrays.end())
      contact_.arrays["mass"] = m->second;
    contact_.arrays["velocity"] = {dimension_, velocity_average_};
    // Without it the fluid extends its pressure to the solid with gravity alone.
    if (solid_acceleration_in_pressure_)
      contact_.arrays["acceleration"] = {dimension_, acceleration_average_};
    fluid().read(contact_port_, contact_);
  }

  std::string contact_port_, force_port_, particles_port_, external_force_port_;
  int dimension_ = 2;
  bool solid_acceleration_in_pressure_ = false;
  double resolution_ratio_ = 1.0;
  FieldBuffer before_, after_, force_, contact_;
  static constexpr double kMaxSubsteps = 1e6;
  std::vector<double> velocity_average_, acceleration_average_;
  std::vector<double> impulse_;  // the open step's force times time, per force component
  double impulse_time_ = 0.0;
  long long acoustic_steps_ = 0, solid_substeps_ = 0;
};

}  // namespace

std::unique_ptr<Coupler> make_fsi_coupler(const proto::CouplerSpec& spec,
                                          std::vector<std::unique_ptr<Module>> children,
                                          const CouplerContext& context) {
  return std::make_unique<FsiCoupler>(spec, std::move(children), context);
}

}  // namespace cosph
