// The health monitor: every N steps (and at the end) it checks that every field of every body is
// finite, that particles are inside the scene's domain, and each module's own physical bounds
// (Module::check_health). A violation stops the run with a HealthError naming the module, the
// quantity, the particle, its position and the step — in normal runs as well as in tests.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "driver/module.hpp"

namespace cosph {

class HealthError : public RuntimeError {
 public:
  using RuntimeError::RuntimeError;
};

// The one wording of a health failure, for the monitor and for a module that checks a bound
// between the monitor's checks (the fluid's sound speed, at every acoustic sub-step): "health
// check failed at step S (t = T): module 'M', body 'B': quantity = value at particle i, position
// (x); expected ...". The step is the driver's; a module that does not know it passes nullopt.
struct HealthContext {
  std::optional<unsigned long long> step;
  double time = 0.0;
  std::string module, body;  // body empty: the module's own quantity
  std::string position;      // "x y z" of the particle, or empty
};
std::string health_failure_message(const HealthContext& where, const HealthProblem& problem);

class HealthMonitor {
 public:
  HealthMonitor(int interval_steps, bool check_domain)
      : interval_(interval_steps), check_domain_(check_domain) {}

  bool due(unsigned long long step) const { return interval_ > 0 && step % interval_ == 0; }
  bool enabled() const { return interval_ > 0; }
  // Throws HealthError on the first problem found.
  // Every scene module (the leaves of the coupler tree: their health is their own).
  void check(const std::vector<const Module*>& modules, unsigned long long step, double time) const;

 private:
  int interval_;
  bool check_domain_;
};

}  // namespace cosph
