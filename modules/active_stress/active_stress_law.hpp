// Active stress laws (seed 001 section 3.2): the ODE of eqs. 17-18 with its smooth activation
// function, advanced by the quasi-steady-state update (exact for V constant over a step), and
// prescribed laws T_a = f(V, x, t).
#pragma once

#include <cmath>

#include "scene.pb.h"

namespace cosph {

// eps(V) = eps_-inf + (eps_inf - eps_-inf) exp(-exp(-xi (V - V_bar))): eps_-inf for V far below
// V_bar, eps_inf far above, a Gompertz switch in between.
inline double active_stress_rate(const proto::ActiveStressOdeSpec& p, double V) {
  return p.epsilon_minus_inf() +
         (p.epsilon_inf() - p.epsilon_minus_inf()) * std::exp(-std::exp(-p.xi() * (V - p.v_bar())));
}

// One QSS step of dT/dt = eps(V) [k_a (V - V_r) - T]: T relaxes to k_a (V - V_r) at rate eps(V).
inline double active_stress_step(const proto::ActiveStressOdeSpec& p, double T, double V,
                                 double dt) {
  const double eps = active_stress_rate(p, V);
  const double target = p.k_a() * (V - p.v_rest());
  return target + (T - target) * std::exp(-eps * dt);
}

}  // namespace cosph
