// Reduced ionic models of the monodomain equation (seed 001 section 3.1) behind one small
// interface. Each right-hand side is split as  dy/dt = q(V, w) - p(V, w) y  so that the
// quasi-steady-state update (seed 001 eq. 34) advances it: exact for frozen q and p, and
// unconditionally stable for p >= 0. A new model implements the two splits and its bounds; the
// integrator does not change.
#pragma once

#include <cmath>
#include <memory>
#include <string>

#include "scene.pb.h"

namespace cosph {

struct RateSplit {
  double production;  // q
  double loss;        // p
};

// y(t + dt) = y e^(-p dt) + q/p (1 - e^(-p dt)), written with expm1 so p -> 0 gives y + q dt.
inline double qss_update(double y, RateSplit r, double dt) {
  if (std::abs(r.loss * dt) < 1e-12) return y + (r.production - r.loss * y) * dt;
  const double decay = std::exp(-r.loss * dt);
  return y * decay + r.production / r.loss * (1.0 - decay);
}

class IonicModel {
 public:
  virtual ~IonicModel() = default;
  virtual std::string name() const = 0;
  // dV/dt (reaction part) = q - p V.
  virtual RateSplit voltage(double V, double w) const = 0;
  // dw/dt = q - p w.
  virtual RateSplit gate(double V, double w) const = 0;
  // Physical bounds for the health monitor (generous: a solution outside them is broken).
  virtual double voltage_min() const = 0;
  virtual double voltage_max() const = 0;
  virtual double gate_min() const = 0;
  virtual double gate_max() const = 0;
};

class FitzHughNagumo final : public IonicModel {
 public:
  explicit FitzHughNagumo(const proto::FitzHughNagumoSpec& p) : p_(p) {}
  std::string name() const override { return "FitzHugh-Nagumo"; }
  // I = -V (V - a)(V - 1) - w = [-V^3 + (a + 1) V^2 - w] - a V.
  RateSplit voltage(double V, double w) const override {
    return {-V * V * V + (p_.a() + 1.0) * V * V - w, p_.a()};
  }
  // g = epsilon0 (beta V - gamma w - sigma).
  RateSplit gate(double V, double) const override {
    return {p_.epsilon0() * (p_.beta() * V - p_.sigma()), p_.epsilon0() * p_.gamma()};
  }
  double voltage_min() const override { return -2.0; }
  double voltage_max() const override { return 2.0; }
  double gate_min() const override { return -2.0; }
  double gate_max() const override { return 2.0; }

 private:
  proto::FitzHughNagumoSpec p_;
};

class AlievPanfilov final : public IonicModel {
 public:
  explicit AlievPanfilov(const proto::AlievPanfilovSpec& p) : p_(p) {}
  std::string name() const override { return "Aliev-Panfilov"; }
  // I = -k V (V - a)(V - 1) - w V = [-k V^3 + k (a + 1) V^2] - (k a + w) V.
  RateSplit voltage(double V, double w) const override {
    const double k = p_.k(), a = p_.a();
    return {-k * V * V * V + k * (a + 1.0) * V * V, k * a + w};
  }
  // g = eps(V, w) (-k V (V - b - 1) - w), eps = epsilon0 + mu1 w / (mu2 + V).
  RateSplit gate(double V, double w) const override {
    const double eps = p_.epsilon0() + p_.mu1() * w / (p_.mu2() + V);
    return {eps * (-p_.k() * V * (V - p_.b() - 1.0)), eps};
  }
  double voltage_min() const override { return -0.5; }
  double voltage_max() const override { return 1.5; }
  double gate_min() const override { return -0.5; }
  double gate_max() const override { return 10.0; }

 private:
  proto::AlievPanfilovSpec p_;
};

// The two halves of the reaction-by-reaction Strang step around the diffusion (seed 001 eq. 32 with
// the errata order): R_V(dt/2) then R_w(dt/2) before it, R_w(dt/2) then R_V(dt/2) after it.
inline void react_before_diffusion(const IonicModel& model, double& V, double& w, double half_dt) {
  V = qss_update(V, model.voltage(V, w), half_dt);
  w = qss_update(w, model.gate(V, w), half_dt);
}
inline void react_after_diffusion(const IonicModel& model, double& V, double& w, double half_dt) {
  w = qss_update(w, model.gate(V, w), half_dt);
  V = qss_update(V, model.voltage(V, w), half_dt);
}

// The longest reaction step the split integrator takes: 1 / max |dq/dV| over the action
// potential's normalised range V in [0, 1], q the voltage's production term. The QSS update
// holds q frozen over a step, so q's cubic in V acts explicitly: beyond about 2 / |dq/dV| the
// update overshoots and the cubic runs away (FitzHugh-Nagumo at a coarse spacing, where the
// diffusion limit allows dt = 17, turns to NaN in a few steps). Longer reaction half steps are
// cut into equal sub-steps no longer than this; 1.25 for FitzHugh-Nagumo's table 2 and 0.179
// for Aliev-Panfilov's table 1, both above the steps of the examples, which stay unchanged.
double reaction_step_limit(const IonicModel& model);

// Builds the model of a spec (presets included). Throws std::invalid_argument for an unknown
// preset or an empty spec.
std::unique_ptr<IonicModel> make_ionic_model(const proto::IonicModelSpec& spec);

}  // namespace cosph
