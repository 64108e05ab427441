// Each module's own health check, and the domain check, triggered by a scene built to violate it:
// the run stops with a HealthError that names the module, the quantity, its value, the particle
// and what was expected (the diffusion module's maximum principle and non-finite values are
// tested in tests/stability/diffusion_stability_test.cpp).
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "../support/simulation_setup.hpp"
#include "driver/health_monitor.hpp"

namespace cosph {
namespace {

// Runs the scene and returns the health error's message; fails the test if the run finishes.
std::string health_error(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    test::make_simulation(text, overrides)->run();
  } catch (const HealthError& e) {
    std::cout << e.what() << "\n";
    return e.what();
  }
  ADD_FAILURE() << "the run should have been stopped by the health monitor";
  return {};
}

void expect_contains(const std::string& message, const std::vector<std::string>& parts) {
  for (const auto& part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
}

const char* const kTissue = R"yaml(
dimension: 2
end_time: 0.1
run: {health_interval: 1}
modules:
  - name: tissue
    monodomain:
      body: {spacing: 0.1, shape: {box: {lower: [0, 0], upper: [1, 1]}}}
      diffusivity: 1.0
      ionic_model: {preset: aliev_panfilov_table1}
)yaml";

TEST(HealthChecks, MonodomainVoltageOutsideTheModelsRange) {
  // Aliev-Panfilov's voltage range is [-0.5, 1.5] (ionic_model.hpp).
  const std::string message = health_error(kTissue, {"modules[0].monodomain.initial_voltage=3"});
  expect_contains(message, {"health check failed at step 0 ", "module 'tissue'", "voltage = 3",
                            "at particle 0", "position (", "expected within [-0.5, 1.5]"});
}

TEST(HealthChecks, MonodomainGateOutsideTheModelsRange) {
  const std::string message = health_error(kTissue, {"modules[0].monodomain.initial_gate=-1"});
  expect_contains(message, {"module 'tissue'", "gate = -1", "at particle 0"});
}

TEST(HealthChecks, SolidInvertedNeighbourhood) {
  // The prescribed displacement u_x = -2 x mirrors the block: F = diag(-1, 1), J = -1.
  const std::string message = health_error(R"yaml(
dimension: 2
end_time: 1.0e-3
run: {health_interval: 1}
modules:
  - name: block
    solid:
      body: {spacing: 0.1, shape: {box: {lower: [0, 0], upper: [1, 1]}}}
      material:
        density: 1000
        neo_hookean: {young: 1.0e4, poisson: 0.3}
      constraints:
        - region: {name: all, shape: {box: {lower: [-1, -1], upper: [2, 2]}}}
          displacement: {values: ["-2 * x", "0"]}
)yaml");
  expect_contains(message, {"module 'block'", "J = -1", "tangled particles"});
}

// A block of water, 0.5 x 0.5 at spacing 0.05, c = 10 m/s, checked at every step.
const char* const kWater = R"yaml(
dimension: 2
end_time: 0.3
domain: {lower: [-1, -0.05], upper: [2, 1]}
run: {health_interval: 1}
modules:
  - name: water
    fluid:
      body: {spacing: 0.05, shape: {box: {lower: [0, 0], upper: [0.5, 0.5]}}}
      density: 1000
      sound_speed: 10
)yaml";

TEST(HealthChecks, FluidDensityOutsideTheWeaklyCompressibleBand) {
  // p = c^2 (rho - rho0): 2e5 Pa at c = 10 m/s is rho = 3 rho0.
  const std::string message = health_error(kWater, {"modules[0].fluid.initial_pressure=2.0e5"});
  expect_contains(message, {"module 'water'", "density = 3000", "within 30% of rho0"});
}

TEST(HealthChecks, ParticleLeavingTheDomain) {
  // In free fall above the domain's floor, the lowest particles (y = 0.025) cross y = -0.05
  // after sqrt(2 0.075 / 9.81) = 0.124 s.
  const std::string message = health_error(kWater, {"modules[0].fluid.gravity=[0, -9.81]"});
  expect_contains(message, {"module 'water'", "position.y = -0.0", "inside the domain"});
  const auto at = message.find("(t = ");
  ASSERT_NE(at, std::string::npos) << message;
  const double t = std::stod(message.substr(at + 5));
  EXPECT_GT(t, 0.120) << message;
  EXPECT_LT(t, 0.130) << message;
}

// A particle past the sound speed stops the run at the sub-step that sees it, not on the
// monitor's schedule (every 1000 steps here): past c the acoustic step 0.6 h / (c + |v|) would
// shrink without bound inside one advection step. u = 40 x is 19 m/s at the right-most column
// (x = 0.475), against c = 10 m/s.
TEST(HealthChecks, FluidParticlePastTheSoundSpeed) {
  const std::string message = health_error(
      kWater,
      {"run.health_interval=1000", "modules[0].fluid.initial_velocity=[\"40 * x\", \"0\"]"});
  expect_contains(message, {"health check failed at t = 0:", "module 'water'", "speed = 19 ",
                            "expected below the sound speed 10", "raise max_velocity"});
}

}  // namespace
}  // namespace cosph
