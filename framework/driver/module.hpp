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

// The complete state of a module, for checkpoints (bit-exact restart) and remote transport.
struct StateRecord {
  std::map<std::string, std::vector<double>> arrays;
  std::map<std::string, double> scalars;
  std::map<std::string, long long> integers;
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
};

}  // namespace cosph
