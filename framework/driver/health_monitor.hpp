// The health monitor: every N steps (and at the end) it checks that every field of every body is
// finite, that particles are inside the scene's domain, and each module's own physical bounds
// (Module::check_health). A violation stops the run with a HealthError naming the module, the
// quantity, the particle, its position and the step — in normal runs as well as in tests.
#pragma once

#include <memory>
#include <vector>

#include "core/error.hpp"
#include "driver/module.hpp"

namespace cosph {

class HealthError : public RuntimeError {
 public:
  using RuntimeError::RuntimeError;
};

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
