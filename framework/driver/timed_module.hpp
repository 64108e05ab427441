// A module seen through a stopwatch: forwards every call of the Module contract to the module it
// wraps and adds up the wall time of the calls that advance it. The driver wraps every module and
// coupler in one, so the run summary reports each module's advance time and each coupler's own
// time (exchange and mapping: its total less its children's) without any module or coupler
// measuring anything. A remote module will be the same kind of forwarding object.
#pragma once

#include <memory>
#include <utility>

#include "core/scoped_seconds.hpp"
#include "driver/module.hpp"

namespace cosph {

class TimedModule final : public Module {
 public:
  explicit TimedModule(std::unique_ptr<Module> module) : module_(std::move(module)) {}

  Module& wrapped() { return *module_; }
  const Module& wrapped() const { return *module_; }
  double advance_seconds() const { return seconds_; }

  ModuleInfo info() const override { return module_->info(); }
  void initialize() override { module_->initialize(); }
  double max_dt() const override { return module_->max_dt(); }
  void advance(double dt) override {
    timed([&] { module_->advance(dt); });
  }
  double time() const override { return module_->time(); }
  void begin_step(double Dt) override {
    timed([&] { module_->begin_step(Dt); });
  }
  double max_substep() const override { return module_->max_substep(); }
  void substep(double dt) override {
    timed([&] { module_->substep(dt); });
  }
  void end_step() override {
    timed([&] { module_->end_step(); });
  }
  void write(const std::string& port, FieldBuffer& out) const override {
    module_->write(port, out);
  }
  void read(const std::string& port, const FieldBuffer& in) override { module_->read(port, in); }
  void save(StateRecord& state) const override { module_->save(state); }
  void load(const StateRecord& state) override { module_->load(state); }
  void prepare_output() override { module_->prepare_output(); }
  void bodies(BodyViews& views) const override { module_->bodies(views); }
  std::size_t particle_count() const override { return module_->particle_count(); }
  std::optional<HealthProblem> check_health() const override { return module_->check_health(); }

 private:
  template <typename F>
  void timed(const F& f) {
    const ScopedSeconds timer(seconds_);
    f();
  }

  std::unique_ptr<Module> module_;
  double seconds_ = 0.0;
};

}  // namespace cosph
