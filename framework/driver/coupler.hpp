// The Coupler contract: a coupler is a Module that owns the modules (or couplers) it couples, so
// couplers nest and the driver advances one root per coupled group without knowing what is
// inside. A coupler talks to its children only through the Module contract — ports and the
// staged advance — never through their types, so any child can later live in another process.
//
// The base class does what every coupler does alike: it owns the children, aggregates their
// bodies, particle counts and output preparation, and nests their checkpoint records under its
// own (`StateRecord::children`, in child order). A concrete coupler adds its step (advance), its
// own state (save_own / load_own), and the exchange it makes once its children are ready
// (connect, also called after a restart so that every input is sent again).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "driver/module.hpp"

namespace cosph {

class Coupler : public Module {
 public:
  Coupler(std::string type, std::string name, std::vector<std::unique_ptr<Module>> children);

  ModuleInfo info() const override;
  // The children are initialised by whoever built them; the coupler then makes its first
  // exchange.
  void initialize() override { connect(); }
  double time() const override;
  void write(const std::string& port, FieldBuffer& out) const override;
  void read(const std::string& port, const FieldBuffer& in) override;
  void save(StateRecord& state) const override;
  void load(const StateRecord& state) override;
  void prepare_output() override;
  void bodies(BodyViews& views) const override;
  std::size_t particle_count() const override;

  std::size_t child_count() const { return children_.size(); }
  Module& child(std::size_t k) { return *children_[k]; }
  const Module& child(std::size_t k) const { return *children_[k]; }

 protected:
  // What this coupler runs, for the run summary.
  virtual std::vector<std::string> features() const = 0;
  // Sends every input the children need from the current state (after initialisation and after
  // a restart: inputs are not state, they are sent again).
  virtual void connect() = 0;
  virtual void save_own(StateRecord&) const {}
  virtual void load_own(const StateRecord&) {}

 private:
  // The child that has the port (a child's port "name" or "child.name"); throws if none or two.
  const Module& port_owner(const std::string& port, bool writes, std::string& local) const;

  std::string type_, name_;
  std::vector<std::unique_ptr<Module>> children_;
};

}  // namespace cosph
