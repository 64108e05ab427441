// Stability suite for the fluid: the dam break through its violent impact and 20 time units of
// sloshing keeps every particle inside the tank with the density in a narrow band, and a
// hydrostatic tank run for a long time stays nearly still: with the low-dissipation Riemann
// solver the start-up transient at this coarse resolution (H/20) decays slowly (to 0.646 of its
// level after the start over 20 s), so the residual motion is bounded as well as its decay
// (measured at t = 20: kinetic energy 1.32 J, 2.69e-4 of the potential energy, largest particle
// speed 0.178 m/s = 5.7% of sqrt(g H)). The
// health monitor (finite fields, density within 30% of rho0, particles inside the domain) runs
// every 100 steps.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "../support/probe_csv.hpp"
#include "../support/reduced_run.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

const ParticleSet<2>& run(Simulation& simulation) {
  simulation.initialize();
  simulation.run();
  BodyViews views;
  simulation.module(0).bodies(views);
  return *views.bodies2.at(0).particles;
}

TEST(FluidStability, DamBreakKeepsEveryParticleInTheTankThroughTheImpact) {
  RunOptions options;
  options.bench = true;
  options.progress = false;
  const std::string scene = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_dambreak_2d.yaml";
  Simulation simulation(load_scene_file(scene, {"modules[0].fluid.body.spacing=0.05"}),
                        builtin_modules(), test::with_step_cap(options));
  const ParticleSet<2>& water = run(simulation);
  const auto& x = water.vector("position");
  const auto& rho = water.scalar("density");
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_GT(x[i][0], 0.0) << "particle " << i << " left through the left wall";
    ASSERT_LT(x[i][0], 5.366) << "particle " << i << " left through the right wall";
    ASSERT_GT(x[i][1], 0.0) << "particle " << i << " left through the floor";
  }
  COSPH_SKIP_CHECKS_IF_REDUCED();  // inside the tank at every step; the density band at the end
  const auto [lo, hi] = std::minmax_element(rho.begin(), rho.end());
  std::cout << "density after 20 time units in [" << *lo << ", " << *hi << "] rho0\n";
  // Measured [0.999704, 1.00118]: at rest the bottom of the spread layer (0.37 deep) would sit at
  // 1 + g h / c^2 = 1.0009 (with the dissipation along the normal as each fluid particle sees it
  // the water still sloshed at t = 20, [0.9998, 1.00218]; with the wall friction of the earlier
  // scheme it had settled to [1.00003, 1.00125]). The band allows 1.5x the measured excess above
  // rho0 and the deficit below it (reinitialisation keeps the free surface near rho0).
  EXPECT_GT(*lo, 1.0 - 1.5 * 0.000296);
  EXPECT_LT(*hi, 1.0 + 1.5 * 0.00118);
}

TEST(FluidStability, HydrostaticTankStaysStillForALongRun) {
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + "cosph_fluid_tank";
  const std::string scene = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_hydrostatic_tank.yaml";
  Simulation simulation(load_scene_file(scene, {"modules[0].fluid.body.spacing=0.05", "end_time=20",
                                                "output.interval=20"}),
                        builtin_modules(), test::with_step_cap(options));
  const ParticleSet<2>& water = run(simulation);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  double speed = 0.0, kinetic = 0.0;
  const auto& m = water.scalar("mass");
  const auto& v = water.vector("velocity");
  for (std::size_t i = 0; i < v.size(); ++i) {
    speed = std::max(speed, v[i].norm());
    kinetic += 0.5 * m[i] * v[i].squaredNorm();
  }
  const double potential = 1000.0 * 9.81 * 0.5;  // rho g H^2 W / 2, H = W = 1
  // The square start lattice rearranges under the pressure within the first 2 s (the kinetic
  // energy rises from 2e-5 to 6e-4 of the potential energy); then the motion decays.
  const std::string file = options.output_directory + "/kinetic_energy.csv";
  const auto t = test::csv_column(file, 0), e = test::csv_column(file, 1);
  auto mean = [&](double from, double to) {
    double sum = 0.0;
    int n = 0;
    for (std::size_t k = 0; k < t.size(); ++k)
      if (t[k] >= from && t[k] <= to) sum += e[k], ++n;
    return sum / n;
  };
  const double after_start = mean(1.5, 3.5), at_end = mean(18.0, 20.0);
  std::cout << "after 20 s: largest speed " << speed << " m/s (sqrt(g H) = 3.13), kinetic energy "
            << kinetic / potential << " of the potential energy; mean over t = 1.5-3.5 "
            << after_start / potential << ", over t = 18-20 " << at_end / potential << "\n";
  EXPECT_LT(speed, 1.5 * 0.0403 * std::sqrt(9.81));  // measured 4.03%
  EXPECT_LT(kinetic, 1.5 * 9.49e-5 * potential);     // measured 9.49e-5
  // Decaying: measured 0.797 (0.646 with the dissipation along the normal as each fluid particle
  // sees it, whose start-up motion was larger: the walls' own normals damp it from the start).
  EXPECT_LT(at_end, 0.9 * after_start);
}

// The 3D path end to end (coarse, H/10): the surge crosses the tank and stays in it. The walls
// slip (the water is inviscid): the jet that runs up the far wall reaches 2.4 H. With the walls'
// acoustic dissipation along their own normals no particle's centre passes the wall's face (the
// farthest at t = 4 is at 5.348, 0.18 spacings inside it); with the dissipation along the normal as
// each fluid particle sees it, the thin jet's particles, at nearly zero pressure, slid up with
// their centres up to 0.33 of a spacing past it.
TEST(FluidStability, DamBreak3DCrossesTheTankAndStaysInIt) {
  RunOptions options;
  options.bench = true;
  options.progress = false;
  const std::string scene = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_dambreak_3d.yaml";
  Simulation simulation(load_scene_file(scene), builtin_modules(), test::with_step_cap(options));
  simulation.initialize();
  simulation.run();
  BodyViews views;
  simulation.module(0).bodies(views);
  const ParticleSet<3>& water = *views.bodies3.at(0).particles;
  double front = 0.0;
  for (const auto& x : water.vector("position")) {
    ASSERT_GT(x[0], 0.0);
    ASSERT_LT(x[0], 5.366);
    ASSERT_GT(x[1], 0.0);
    ASSERT_LT(x[1], 1.0);
    ASSERT_GT(x[2], 0.0);
    front = std::max(front, x[0]);
  }
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout << "3D surge front at t = 4: " << front << " H\n";
  EXPECT_GT(front, 4.5);  // measured 5.348: the water reached the far wall
}

}  // namespace
}  // namespace cosph
