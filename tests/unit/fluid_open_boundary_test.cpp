// Open boundaries of the fluid: an inflow buffer and an outflow plane keep a channel (2D) and a
// duct (3D) full and flowing at the prescribed speed; restart and thread count stay bit-identical
// while particles are created and removed; bad open-boundary input names the key.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "../support/simulation_setup.hpp"
#include "core/error.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace cosph {
namespace {

namespace fs = std::filesystem;

using test::make_simulation;
using test::particles_of;

// A channel 2 long and 1 high: uniform inflow U = 1 through a buffer 0.2 long at x < 0, outflow
// at x = 2, no-slip walls above and below.
const char* kChannel = R"yaml(
dimension: 2
end_time: 3.0
domain: {lower: [-0.3, -0.2], upper: [2.3, 1.2]}
modules:
  - name: channel
    fluid:
      body: {spacing: 0.05, shape: {box: {lower: [-0.2, 0], upper: [2, 1]}}}
      density: 1
      max_velocity: 1
      viscosity: 0.001
      density_treatment: summation
      transport_velocity: true
      inflow:
        buffer: {lower: [-0.2, 0], upper: [0, 1]}
        velocity: ["1", "0"]
      outflow: {position: 2}
      walls:
        - name: bottom
          shape: {box: {lower: [-0.3, -0.2], upper: [2.3, 0]}}
        - name: top
          shape: {box: {lower: [-0.3, 1], upper: [2.3, 1.2]}}
checkpoint: {interval: 0.5}
)yaml";

TEST(FluidOpenBoundary, ChannelStaysFullAndFlowsAtTheInflowSpeed) {
  auto simulation = make_simulation(kChannel, {});
  const std::size_t initial = particles_of<2>(*simulation).size();
  simulation->run();  // 1.5 flow-through times: every starting particle has left
  const ParticleSet<2>& p = particles_of<2>(*simulation);
  const auto& x = p.vector("position");
  const auto& v = p.vector("velocity");
  double lowest = INFINITY, highest = -INFINITY, u = 0.0;
  int middle = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    lowest = std::min(lowest, x[i][0]);
    highest = std::max(highest, x[i][0]);
    if (x[i][0] > 0.5 && x[i][0] < 1.5) {
      u += v[i][0];
      ++middle;
    }
  }
  u /= middle;
  std::cout << "particles " << initial << " -> " << p.size() << ", x in [" << lowest << ", "
            << highest << "], mean u over the cross-section " << u << "\n";
  EXPECT_NEAR(double(p.size()), double(initial), 0.05 * initial);
  EXPECT_GE(lowest, -0.2);  // nothing leaks upstream out of the buffer
  EXPECT_GT(highest, 1.9);  // the channel is full up to the outflow plane
  EXPECT_GT(middle, 300);
  EXPECT_NEAR(u, 1.0, 0.05);  // the flux through the channel is the inflow's
}

// The same in 3D: a square duct 1 x 0.5 x 0.5, coarse (dp = 0.1), walls all round.
const char* kDuct = R"yaml(
dimension: 3
end_time: 1.5
domain: {lower: [-0.5, -0.4, -0.4], upper: [1.5, 0.9, 0.9]}
modules:
  - name: duct
    fluid:
      body: {spacing: 0.1, shape: {box: {lower: [-0.3, 0, 0], upper: [1, 0.5, 0.5]}}}
      density: 1
      max_velocity: 1
      viscosity: 0.001
      density_treatment: summation
      transport_velocity: true
      inflow:
        buffer: {lower: [-0.3, 0, 0], upper: [0, 0.5, 0.5]}
        velocity: ["1", "0", "0"]
      outflow: {position: 1}
      walls:
        - name: duct
          shape:
            difference:
              base: {box: {lower: [-0.4, -0.3, -0.3], upper: [1.4, 0.8, 0.8]}}
              subtract: {box: {lower: [-0.4, 0, 0], upper: [1.4, 0.5, 0.5]}}
)yaml";

TEST(FluidOpenBoundary, DuctIn3DStaysFullAndFlows) {
  auto simulation = make_simulation(kDuct, {});
  const std::size_t initial = particles_of<3>(*simulation).size();
  simulation->run();  // 1.5 flow-through times
  const ParticleSet<3>& p = particles_of<3>(*simulation);
  double u = 0.0, lowest = INFINITY, highest = -INFINITY;
  int middle = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec<3>& x = p.vector("position")[i];
    lowest = std::min(lowest, x[0]);
    highest = std::max(highest, x[0]);
    if (x[0] > 0.3 && x[0] < 0.7) {
      u += p.vector("velocity")[i][0];
      ++middle;
    }
  }
  u /= middle;
  std::cout << "duct: particles " << initial << " -> " << p.size() << ", mean u " << u << "\n";
  EXPECT_NEAR(double(p.size()), double(initial), 0.08 * initial);
  EXPECT_GE(lowest, -0.3);
  EXPECT_GT(highest, 0.85);  // full up to the outflow plane
  EXPECT_NEAR(u, 1.0, 0.1);
}

struct State {
  std::vector<Vec<2>> x, v;
};

State final_state(const std::vector<std::string>& set, RunOptions options) {
  auto simulation = make_simulation(kChannel, set, options);
  simulation->run();
  const ParticleSet<2>& p = particles_of<2>(*simulation);
  return {p.vector("position"), p.vector("velocity")};
}

void expect_bit_identical(const State& a, const State& b, const std::string& what) {
  ASSERT_EQ(a.x.size(), b.x.size()) << what;
  for (std::size_t i = 0; i < a.x.size(); ++i)
    for (int c = 0; c < 2; ++c) {
      ASSERT_EQ(a.x[i][c], b.x[i][c]) << what << ": position, particle " << i;
      ASSERT_EQ(a.v[i][c], b.v[i][c]) << what << ": velocity, particle " << i;
    }
}

TEST(FluidOpenBoundary, RestartAndThreadsAreBitIdenticalWhileParticlesComeAndGo) {
  const fs::path dir = fs::path(testing::TempDir()) / "cosph_fluid_open_restart";
  fs::remove_all(dir);
  const std::vector<std::string> set = {"end_time=1.5"};
  RunOptions full;
  full.threads = 1;
  full.output_directory = (dir / "full").string();
  const State uninterrupted = final_state(set, full);
  const fs::path checkpoint = dir / "full" / "checkpoint_000002.ckpt";  // t = 1
  ASSERT_TRUE(fs::exists(checkpoint));
  RunOptions restart = full;
  restart.output_directory = (dir / "restart").string();
  restart.restart_file = checkpoint.string();
  expect_bit_identical(uninterrupted, final_state(set, restart), "restart");

  RunOptions one, two;
  one.threads = 1;
  two.threads = 2;
  expect_bit_identical(final_state({"end_time=1"}, one), final_state({"end_time=1"}, two),
                       "1 vs 2 threads");
}

TEST(FluidOpenBoundary, BadInputNamesTheKey) {
  auto message = [&](const std::vector<std::string>& set) -> std::string {
    try {
      make_simulation(kChannel, set);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  // A buffer shorter than the kernel support (0.13) would let free particles see its open end.
  const std::string short_buffer = message({"modules[0].fluid.inflow.buffer.lower=[-0.1, 0]"});
  EXPECT_NE(short_buffer.find("modules[0].fluid.inflow.buffer"), std::string::npos) << short_buffer;
  EXPECT_NE(message({"modules[0].fluid.inflow.axis=2"}).find("inflow.axis"), std::string::npos);
  EXPECT_NE(message({"modules[0].fluid.inflow.buffer.upper=[0, 0]"}).find("lower < upper"),
            std::string::npos);
  EXPECT_NE(message({"modules[0].fluid.outflow.axis=2"}).find("outflow.axis"), std::string::npos);
  EXPECT_NE(message({"modules[0].fluid.inflow.velocity[0]=1 +"}).find("inflow.velocity[0]"),
            std::string::npos);
}

// An inflow that accelerates past the sound speed (c = 10 max_velocity = 10 here) within an
// advection step used to shrink the acoustic step without bound, 0.6 h / (c + |v|): a fuzzed
// cylinder scene with a factor -9.2e18 in its inflow ran for hours inside its second step. Now
// the run stops at the first sub-step past c, naming the key, the speed, the time and the place.
TEST(FluidOpenBoundary, InflowPastTheSoundSpeedIsRefusedWithItsKey) {
  std::string key, message;
  try {
    make_simulation(kChannel, {"modules[0].fluid.inflow.velocity[0]=1e6 * t^2"})->run();
  } catch (const ConfigError& e) {
    key = e.key_path();
    message = e.what();
  }
  std::cout << key << ": " << message << "\n";
  EXPECT_EQ(key, "modules[0].fluid.inflow.velocity");
  for (const char* part :
       {"the prescribed speed is ", "must stay below the sound speed 10", "raise max_velocity"})
    EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' not in: " << message;
  // Past c at t = sqrt(1e-5) = 3.16e-3 s, within the first advection steps.
  const auto at = message.find(" at t = ");
  ASSERT_NE(at, std::string::npos) << message;
  const double t = std::stod(message.substr(at + 8));
  EXPECT_GT(t, std::sqrt(1e-5));
  EXPECT_LT(t, std::sqrt(1e-5) + 2e-3);
}

}  // namespace
}  // namespace cosph
