// The Module contract (docs/ARCHITECTURE.md): every physics module and every coupler implements
// it, and the driver knows nothing else. Everything that crosses it is a plain value (field
// buffers, state records), so a module can later live in another process behind the same
// interface without any coupler noticing.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/domain.hpp"

namespace cosph {

// A named set of fields on a named point set, read or written by a module.
struct PortInfo {
  std::string name;
  std::vector<std::string> fields;
};

struct ModuleInfo {
  std::string type;  // registry name, e.g. "diffusion"
  std::string name;  // the scene's name for this instance
  std::vector<PortInfo> reads;
  std::vector<PortInfo> writes;
  // What this instance actually runs (forces, corrections, options), for the run summary: a
  // scene pays only for what it names, and the summary shows exactly that.
  std::vector<std::string> active_features;
  std::vector<std::string> children;  // modules a coupler owns
  int dimension = 0;                  // 2 or 3
  double spacing = 0.0;               // particle spacing of its main body (0: none)
  // Counters of what the run did, for the run summary (a steady-state solver's iterations and
  // residual); empty for most modules.
  std::map<std::string, double> statistics;
};

// Data through a port: `points` entries of each named array, `components` doubles per entry.
struct FieldBuffer {
  std::size_t points = 0;
  struct Array {
    int components = 1;
    std::vector<double> values;
  };
  std::map<std::string, Array> arrays;
};

// The complete state of a module, for checkpoints (bit-exact restart) and remote transport. A
// coupler's record holds its own state and one child record per module it owns (named by the
// child), so a coupled checkpoint is complete by construction and nests as couplers do.
struct StateRecord {
  std::string name;  // of the module whose state this is (set for child records)
  std::string type;
  std::map<std::string, std::vector<double>> arrays;
  std::map<std::string, double> scalars;
  std::map<std::string, long long> integers;
  std::vector<StateRecord> children;
};

// A violated physical bound, found by a module's own health check.
struct HealthProblem {
  std::string quantity;  // e.g. "concentration", "J", "density"
  long long particle = -1;
  double value = 0.0;
  std::string expected;  // e.g. "within [0, 1] (maximum principle)"
};

// What the driver may look at for output and probes: a module's bodies, in-process views.
template <int D>
struct BodyView {
  std::string module;
  const ParticleSet<D>* particles = nullptr;
  Kernel kernel{KernelType::WendlandC2, D, 1.0};
  Domain<D> domain;
};

struct BodyViews {
  std::vector<BodyView<2>> bodies2;
  std::vector<BodyView<3>> bodies3;
};

class Module {
 public:
  virtual ~Module() = default;

  virtual ModuleInfo info() const = 0;
  // Builds particles and precomputes what does not change. Configuration errors throw
  // ConfigError with the scene key path.
  virtual void initialize() = 0;
  // The largest step this module can take stably from its current state.
  virtual double max_dt() const = 0;
  // Advances from t to t + dt (a coupler sub-steps its children inside).
  virtual void advance(double dt) = 0;
  virtual double time() const = 0;

  // Staged advance: one step of Dt as sub-steps that a coupler drives and interleaves with its
  // exchanges (FSI exchanges forces at every acoustic sub-step of the fluid's advection step).
  // begin_step(Dt) opens the step; max_substep() is the largest next sub-step (0 once the step is
  // covered); substep(dt) advances by it; end_step() closes the step. Between begin_step and
  // end_step the module reads and writes its ports as usual; a checkpoint is taken only between
  // steps. Every call is a plain value exchange, so a remote module forwards it unchanged. A
  // module without inner sub-steps keeps the defaults: one sub-step that is its whole advance.
  virtual void begin_step(double Dt) { staged_remaining_ = Dt; }
  virtual double max_substep() const { return staged_remaining_; }
  virtual void substep(double dt) {
    advance(dt);
    staged_remaining_ = dt >= staged_remaining_ ? 0.0 : staged_remaining_ - dt;
  }
  virtual void end_step() { staged_remaining_ = 0.0; }

  virtual void write(const std::string& port, FieldBuffer& out) const = 0;
  virtual void read(const std::string& port, const FieldBuffer& in) = 0;

  virtual void save(StateRecord& state) const = 0;
  virtual void load(const StateRecord& state) = 0;

  // Called before the driver writes output or samples probes: a module computes its derived
  // output fields here (stresses, strains) instead of at every step.
  virtual void prepare_output() {}

  // Bodies for output and probes; particle counts for the summary.
  virtual void bodies(BodyViews& views) const = 0;
  virtual std::size_t particle_count() const = 0;

  // The module's own physical bounds (J > 0, density band, maximum principle...). The health
  // monitor checks finiteness and the domain for every module itself.
  virtual std::optional<HealthProblem> check_health() const { return std::nullopt; }

 private:
  double staged_remaining_ = 0.0;  // the default staging's open step
};

// A whole step through the staged calls: what advance() is for a module that implements stages.
inline void advance_in_substeps(Module& module, double Dt) {
  module.begin_step(Dt);
  for (double dt = module.max_substep(); dt > 0.0; dt = module.max_substep()) module.substep(dt);
  module.end_step();
}

}  // namespace cosph
