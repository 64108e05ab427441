// The weakly-compressible fluid: the inter-particle Riemann solution's properties, momentum
// conservation of the pair forces, the hydrostatic tank (bottom pressure against rho g H, the
// water staying still) and bad input.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "driver/simulation.hpp"
#include "fluid_wcsph/riemann.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace cosph {
namespace {

TEST(Riemann, EqualStatesGiveThemselves) {
  for (bool limited : {false, true}) {
    const RiemannSolver s{1000.0 * 20.0, 20.0, limited};
    EXPECT_DOUBLE_EQ(s.pressure(5.0, 5.0, 0.3, 0.3), 5.0);
    EXPECT_DOUBLE_EQ(s.velocity(5.0, 5.0, 0.3, 0.3), 0.3);
  }
}

TEST(Riemann, DissipationActsOnApproachOnlyWhenLimited) {
  const RiemannSolver acoustic{1000.0 * 20.0, 20.0, false}, limited{1000.0 * 20.0, 20.0, true};
  // Approaching pair (u_L > u_R): both raise P* above the mean pressure; the acoustic solver by
  // Z (u_L - u_R) / 2 exactly.
  EXPECT_DOUBLE_EQ(acoustic.pressure(0.0, 0.0, 1.0, -1.0), 20000.0 * 2.0 / 2.0);
  EXPECT_GT(limited.pressure(0.0, 0.0, 1.0, -1.0), 0.0);
  EXPECT_LT(limited.pressure(0.0, 0.0, 1.0, -1.0), acoustic.pressure(0.0, 0.0, 1.0, -1.0));
  // Separating pair: the limiter removes the (negative) dissipation entirely.
  EXPECT_LT(acoustic.pressure(0.0, 0.0, -1.0, 1.0), 0.0);
  EXPECT_DOUBLE_EQ(limited.pressure(0.0, 0.0, -1.0, 1.0), 0.0);
  // A fast impact (jump above c / 3) gets the full acoustic dissipation.
  EXPECT_DOUBLE_EQ(limited.pressure(0.0, 0.0, 10.0, 0.0), acoustic.pressure(0.0, 0.0, 10.0, 0.0));
  // U* moves from high to low pressure.
  EXPECT_GT(acoustic.velocity(100.0, 0.0, 0.0, 0.0), 0.0);
  // Symmetry: swapping the sides (and the direction) gives the same P* and the opposite U*.
  EXPECT_DOUBLE_EQ(limited.pressure(3.0, 7.0, 0.4, -0.2), limited.pressure(7.0, 3.0, 0.2, -0.4));
  EXPECT_DOUBLE_EQ(acoustic.velocity(3.0, 7.0, 0.4, -0.2), -acoustic.velocity(7.0, 3.0, 0.2, -0.4));
}

std::unique_ptr<Simulation> make(const std::string& text, const std::vector<std::string>& set,
                                 const std::string& dir = "") {
  RunOptions options;
  options.progress = false;
  options.bench = dir.empty();
  options.output_directory = dir;
  auto simulation = std::make_unique<Simulation>(load_scene_text(text, "fluid.yaml", set),
                                                 builtin_modules(), options);
  simulation->initialize();
  return simulation;
}

const char* kPeriodicBox = R"yaml(
dimension: 2
end_time: 0.3
domain: {lower: [0, 0], upper: [1, 1], periodic: [true, true]}
modules:
  - name: water
    fluid:
      body: {spacing: 0.05, shape: {box: {lower: [0, 0], upper: [1, 1]}}}
      density: 1000
      sound_speed: 10
      viscosity: 1
      density_treatment: summation
      initial_velocity: ["0.3 * sin(6.283185307 * y) + 0.1 * cos(12.56637 * x * y)",
                         "0.2 * cos(6.283185307 * x)"]
)yaml";

TEST(Fluid, PairForcesConserveMomentumInAPeriodicBox) {
  auto simulation = make(kPeriodicBox, {});
  BodyViews views;
  simulation->module(0).bodies(views);
  const ParticleSet<2>& p = *views.bodies2.at(0).particles;
  auto momentum = [&] {
    Vec<2> sum = Vec<2>::Zero();
    double scale = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      sum += p.scalar("mass")[i] * p.vector("velocity")[i];
      scale += p.scalar("mass")[i] * p.vector("velocity")[i].norm();
    }
    return std::pair{sum, scale};
  };
  const auto [before, scale] = momentum();
  const RunSummary summary = simulation->run();
  const auto [after, unused] = momentum();
  EXPECT_GT(summary.steps, 5u);
  std::cout << "momentum change " << (after - before).norm() / scale << " of sum |m v|\n";
  EXPECT_LT((after - before).norm(), 1e-12 * scale);
}

const char* kTank = R"yaml(
dimension: 2
end_time: 2.0
domain: {lower: [-0.2, -0.2], upper: [1.2, 1.4]}
modules:
  - name: water
    fluid:
      body: {spacing: 0.05, shape: {box: {lower: [0, 0], upper: [1, 1]}}}
      density: 1000
      max_velocity: 4.43
      gravity: [0, -9.81]
      initial_pressure: "1000 * 9.81 * (1 - y)"
      walls:
        - name: tank
          shape:
            difference:
              base: {box: {lower: [-0.2, -0.2], upper: [1.2, 1.3]}}
              subtract: {box: {lower: [0, 0], upper: [1, 1.3]}}
probes:
  - name: bottom
    interval: 0.05
    interpolation: linear
    points: {at: [[0.5, 0.0], [0.5, 0.5]], fields: [pressure]}
  - name: kinetic_energy
    interval: 0.05
    reduce: {quantity: kinetic_energy}
)yaml";

TEST(Fluid, HydrostaticTankHoldsRhoGHAndStaysStill) {
  auto simulation = make(kTank, {});
  const RunSummary summary = simulation->run();  // the health monitor checks the density band
  const double bottom = summary.probes.at("bottom").at("pressure@p0");
  const double middle = summary.probes.at("bottom").at("pressure@p1");
  const double kinetic = summary.probes.at("kinetic_energy").at("kinetic_energy");
  const double potential = 1000.0 * 9.81 * 1.0 * 0.5;  // rho g H^2 W / 2 per unit depth
  std::cout << "bottom pressure " << bottom << " (rho g H = 9810), mid-depth " << middle
            << " (4905), kinetic energy " << kinetic << " J (" << kinetic / potential
            << " of the potential energy)\n";
  // Measured at dp = H/20: bottom (linear extrapolation to the wall) 9,143 (-6.8%), mid-depth
  // 5,064 (+3.2%); at H/40 the bottom reads 9,975.
  EXPECT_NEAR(bottom, 9810.0, 0.1 * 9810.0);
  EXPECT_NEAR(middle, 4905.0, 0.05 * 4905.0);
  EXPECT_LT(kinetic, 1e-3 * potential);
}

TEST(Fluid, BadInputNamesTheKey) {
  const std::string text = kTank;
  auto message = [&](const std::vector<std::string>& set) -> std::string {
    try {
      make(text, set);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  const std::string no_speed = [&] {
    std::string t = text;
    t.replace(t.find("      max_velocity: 4.43\n"), 25, "");
    try {
      make(t, {});
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_NE(no_speed.find("modules[0].fluid"), std::string::npos) << no_speed;
  EXPECT_NE(no_speed.find("max_velocity"), std::string::npos) << no_speed;
  EXPECT_NE(message({"modules[0].fluid.density=-1"}).find("density"), std::string::npos);
  EXPECT_NE(message({"modules[0].fluid.riemann_solver=hllc"}).find("riemann_solver"),
            std::string::npos);
  EXPECT_NE(message({"modules[0].fluid.initial_pressure=1 +"}).find("initial_pressure"),
            std::string::npos);
}

}  // namespace
}  // namespace cosph
