// Active stress: the ODE of seed 001 eqs. 17-18 with the QSS update, and prescribed laws.
#include <gtest/gtest.h>

#include <cmath>

#include "active_stress/active_stress_law.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

proto::ActiveStressOdeSpec ode() {
  proto::ActiveStressOdeSpec p;
  p.set_k_a(47.9);
  p.set_v_rest(-0.1);
  p.set_epsilon_minus_inf(1.0);
  p.set_epsilon_inf(0.1);
  p.set_xi(1.0);
  p.set_v_bar(0.0);
  return p;
}

TEST(ActiveStress, ActivationRateSwitchesBetweenItsLimits) {
  const auto p = ode();
  EXPECT_NEAR(active_stress_rate(p, -20.0), 1.0, 1e-12);  // far below V_bar: eps_-inf
  EXPECT_NEAR(active_stress_rate(p, 40.0), 0.1, 1e-12);   // far above: eps_inf
  // At V = V_bar the Gompertz switch is at exp(-1) of the way.
  EXPECT_NEAR(active_stress_rate(p, 0.0), 1.0 + (0.1 - 1.0) * std::exp(-1.0), 1e-14);
}

TEST(ActiveStress, QssStepIsExactForConstantVoltage) {
  // dT/dt = eps (k_a (V - V_r) - T), V constant: T(t) = target + (T0 - target) e^(-eps t).
  const auto p = ode();
  const double V = 0.8, eps = active_stress_rate(p, V), target = p.k_a() * (V - p.v_rest());
  double T = 2.0;
  for (int k = 0; k < 37; ++k) T = active_stress_step(p, T, V, 0.05);
  EXPECT_NEAR(T, target + (2.0 - target) * std::exp(-eps * 37 * 0.05), 1e-10);
}

TEST(ActiveStress, QssMatchesFineRk4ForTimeVaryingVoltageAndConverges) {
  const auto p = ode();
  auto V = [](double t) { return std::sin(t); };
  auto rhs = [&](double t, double T) {
    return active_stress_rate(p, V(t)) * (p.k_a() * (V(t) - p.v_rest()) - T);
  };
  double ref = 0.0;
  const double h = 1e-4, end = 3.0;
  for (int k = 0; k < 30000; ++k) {
    const double t = k * h;
    const double k1 = rhs(t, ref), k2 = rhs(t + h / 2, ref + h / 2 * k1),
                 k3 = rhs(t + h / 2, ref + h / 2 * k2), k4 = rhs(t + h, ref + h * k3);
    ref += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  auto qss = [&](double dt) {
    double T = 0.0;
    const int n = static_cast<int>(std::round(end / dt));
    for (int k = 0; k < n; ++k) T = active_stress_step(p, T, V(k * dt), dt);
    return std::abs(T - ref);
  };
  const double e1 = qss(0.01), e2 = qss(0.005);
  EXPECT_LT(e2, 0.6 * e1);  // first order: V frozen over the step
  EXPECT_LT(e2, 0.05 * std::abs(ref));
}

TEST(ActiveStress, ModuleAppliesPrescribedLawAndOde) {
  // The active cube of Garcia-Blanco et al.: V linear from 0 (bottom) to 30 (top), T_a = -0.5 V.
  const char* const text = R"yaml(
dimension: 3
end_time: 1.0
modules:
  - name: cube
    active_stress:
      body:
        spacing: 0.1
        shape: {box: {lower: [0, 0, 0], upper: [1, 1, 1]}}
      voltage: "30 * z"
      prescribed: "-0.5 * V"
)yaml";
  RunOptions options;
  options.bench = true;
  options.progress = false;
  Simulation simulation(load_scene_text(text, "cube.yaml"), builtin_modules(), options);
  simulation.initialize();
  simulation.run();
  BodyViews views;
  simulation.module(0).bodies(views);
  const auto& p = *views.bodies3.at(0).particles;
  for (std::size_t i = 0; i < p.size(); ++i)
    EXPECT_NEAR(p.scalar("active_stress")[i], -0.5 * 30.0 * p.vector("position")[i][2], 1e-12);
  FieldBuffer out;
  simulation.module(0).write("active_stress", out);
  EXPECT_EQ(out.points, p.size());
  EXPECT_THROW(simulation.module(0).read("voltage", out), RuntimeError);  // prescribed voltage

  // Both laws at once is a scene error.
  const std::string ode_law =
      "modules[0].active_stress.ode={k_a: 2, v_rest: 0, epsilon_minus_inf: 1, epsilon_inf: 0.5, "
      "xi: 1, v_bar: 0}";
  EXPECT_THROW(load_scene_text(text, "cube.yaml", {ode_law}), SceneError);

  // The ODE at constant V = 0.5 relaxes to k_a (V - V_r) = 1 at the rate eps(0.5).
  std::string ode_text = text;
  const std::string prescribed_line = "      prescribed: \"-0.5 * V\"\n";
  ode_text.replace(ode_text.find(prescribed_line), prescribed_line.size(), "");
  Simulation relax(
      load_scene_text(ode_text, "cube.yaml", {ode_law, "modules[0].active_stress.voltage=0.5"}),
      builtin_modules(), options);
  relax.initialize();
  relax.run();
  BodyViews v;
  relax.module(0).bodies(v);
  const double eps = 1.0 + (0.5 - 1.0) * std::exp(-std::exp(-0.5));
  for (double T : v.bodies3.at(0).particles->scalar("active_stress"))
    EXPECT_NEAR(T, 1.0 - std::exp(-eps * 1.0), 1e-10);
}

}  // namespace
}  // namespace cosph
