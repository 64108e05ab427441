// The weakly-compressible fluid: the inter-particle Riemann solution's properties, momentum
// conservation of the pair forces, the hydrostatic tank (bottom pressure against rho g H, the
// water staying still, the force on its walls), moving and accelerating walls (Galilean
// invariance, the equivalence principle, restart) and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>
#include <vector>

#include "../support/probe_csv.hpp"
#include "../support/simulation_setup.hpp"
#include "core/error.hpp"
#include "driver/health_monitor.hpp"
#include "driver/simulation.hpp"
#include "fluid_wcsph/riemann.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace cosph {
namespace {

TEST(Riemann, EqualStatesGiveThemselves) {
  for (auto momentum :
       {MomentumDissipation::acoustic, MomentumDissipation::limited, MomentumDissipation::none}) {
    const RiemannSolver s{1000.0 * 20.0, 20.0, momentum};
    EXPECT_DOUBLE_EQ(s.pressure(5.0, 5.0, 0.3, 0.3), 5.0);
    EXPECT_DOUBLE_EQ(s.velocity(5.0, 5.0, 0.3, 0.3), 0.3);
  }
}

TEST(Riemann, DissipationActsOnApproachOnlyWhenLimited) {
  const RiemannSolver acoustic{1000.0 * 20.0, 20.0, MomentumDissipation::acoustic},
      limited{1000.0 * 20.0, 20.0, MomentumDissipation::limited};
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

TEST(Riemann, ContinuityOnlyKeepsTheDensityDiffusionAndDropsTheVelocityJump) {
  const RiemannSolver none{1000.0 * 20.0, 20.0, MomentumDissipation::none},
      acoustic{1000.0 * 20.0, 20.0, MomentumDissipation::acoustic};
  // P* is the mean pressure whatever the velocities, even for a fast impact.
  EXPECT_DOUBLE_EQ(none.pressure(3.0, 7.0, 10.0, -10.0), 5.0);
  EXPECT_DOUBLE_EQ(none.pressure(3.0, 7.0, -1.0, 1.0), 5.0);
  // U* still carries the pressure jump (p_L - p_R) / (2 Z), as the acoustic solver's does.
  EXPECT_DOUBLE_EQ(none.velocity(100.0, 0.0, 0.0, 0.0), 100.0 / (2.0 * 20000.0));
  EXPECT_DOUBLE_EQ(none.velocity(3.0, 7.0, 0.4, -0.2), acoustic.velocity(3.0, 7.0, 0.4, -0.2));
}

using test::make_simulation;
using test::particles_of;

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
  auto simulation = make_simulation(kPeriodicBox, {});
  const ParticleSet<2>& p = particles_of<2>(*simulation);
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

// A viscosity whose explicit limit (0.25 rho h^2 / eta) lies below the advection step is
// sub-cycled: the advection step (neighbour lists, density summation) and the acoustic sub-step
// stay what the flow and the sound speed allow, and the viscous force is applied in split steps
// within its limit. Here the acoustic sub-step is about 3.5 times the limit: applied in one
// explicit step the viscosity would amplify the checkerboard mode and add energy; sub-cycled it
// only removes energy, and its pair forces still conserve momentum. The accuracy of the
// sub-cycled viscous force is the Poiseuille transient's (fluid_validation_test: its viscous limit
// is below its advection step).
TEST(Fluid, ViscosityBelowTheAdvectionStepIsSubCycledNotTheStep) {
  auto thin = make_simulation(kPeriodicBox, {});
  auto thick = make_simulation(kPeriodicBox, {"modules[0].fluid.viscosity=1000"});
  Module& fluid = thick->module(0);
  const double Dt = fluid.max_dt();
  EXPECT_DOUBLE_EQ(Dt, thin->module(0).max_dt());
  const double h = 1.3 * 0.05, limit = 0.25 * h * h * 1000.0 / 1000.0;
  ASSERT_LT(4.0 * limit, Dt);
  const ParticleSet<2>& p = particles_of<2>(*thick);
  auto kinetic = [&] {
    double e = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
      e += 0.5 * p.scalar("mass")[i] * p.vector("velocity")[i].squaredNorm();
    return e;
  };
  auto momentum = [&] {
    Vec<2> sum = Vec<2>::Zero();
    for (std::size_t i = 0; i < p.size(); ++i) sum += p.scalar("mass")[i] * p.vector("velocity")[i];
    return sum;
  };
  const Vec<2> start = momentum();
  double energy = kinetic(), scale = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    scale += p.scalar("mass")[i] * p.vector("velocity")[i].norm();
  for (int step = 0; step < 5; ++step) {
    fluid.begin_step(fluid.max_dt());
    int substeps = 0;
    for (double dt; (dt = fluid.max_substep()) > 0.0; ++substeps) {
      // The sound speed's sub-step 0.6 h / (c + |v|max) = 3.7e-3 (|v|max <= 0.4 here), not the
      // viscous limit 1.06e-3.
      if (substeps == 0) {
        EXPECT_GT(dt, 3.0 * limit);
      }
      fluid.substep(dt);
    }
    fluid.end_step();
    EXPECT_LE(substeps, 5);  // Dt / acoustic = 4.3: not cut to the viscous limit (16 sub-steps)
    const double now = kinetic();
    EXPECT_LT(now, energy) << "step " << step;  // a viscosity this strong only removes energy
    energy = now;
  }
  EXPECT_LT((momentum() - start).norm(), 1e-12 * scale);
}

// whole_acoustic_substeps rounds the advection step up to a whole number of acoustic sub-steps
// of one length (SPHinXsys's loop) instead of cutting the last sub-step to the advection step:
// here 0.25 h / (c / 10) = 1.63e-2 holds 4.3 acoustic sub-steps of 0.6 h / (c + |v|max), so the
// cut scheme takes five sub-steps, the last a third long, and the rounded one five full ones.
// A step the driver cuts (an output time) is split into equal sub-steps within the limit.
TEST(Fluid, WholeAcousticSubstepsRoundTheAdvectionStepUp) {
  auto cut = make_simulation(kPeriodicBox, {});
  auto whole = make_simulation(kPeriodicBox, {"modules[0].fluid.whole_acoustic_substeps=true"});
  Module& fluid = whole->module(0);
  const double advection = cut->module(0).max_dt();
  cut->module(0).begin_step(advection);
  const double acoustic = cut->module(0).max_substep();
  ASSERT_GT(advection / acoustic, 4.1);
  ASSERT_LT(advection / acoustic, 4.9);
  const double Dt = fluid.max_dt();
  EXPECT_NEAR(Dt, 5.0 * acoustic, 1e-12 * Dt);
  auto substeps = [&](double step) {
    std::vector<double> taken;
    fluid.begin_step(step);
    for (double dt; (dt = fluid.max_substep()) > 0.0;) {
      taken.push_back(dt);
      fluid.substep(dt);
    }
    fluid.end_step();
    return taken;
  };
  const std::vector<double> full = substeps(Dt);
  ASSERT_EQ(full.size(), 5u);
  for (double dt : full) EXPECT_NEAR(dt, acoustic, 1e-3 * acoustic);  // |v|max moves a little
  const double limit = fluid.max_dt() / 5.0 * (1.0 + 1e-9);
  const std::vector<double> shortened = substeps(0.55 * fluid.max_dt());  // 2.75 sub-steps
  ASSERT_EQ(shortened.size(), 3u);
  for (double dt : shortened) {
    EXPECT_NEAR(dt, shortened[0], 1e-12 * dt);
    EXPECT_LE(dt, limit);
  }
}

// A viscosity that would take a million split steps in one acoustic sub-step is a broken scene:
// it stops with the module, the number of split steps and the viscosity named, instead of
// running for days.
TEST(Fluid, AViscosityNeedingAMillionSplitStepsStopsTheRun) {
  auto s = make_simulation(kPeriodicBox, {"modules[0].fluid.viscosity=1e10"});
  Module& fluid = s->module(0);
  fluid.begin_step(fluid.max_dt());
  try {
    fluid.substep(fluid.max_substep());
    ADD_FAILURE() << "no error";
  } catch (const RuntimeError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("module 'water': the viscous force would need"), std::string::npos) << what;
    EXPECT_NE(what.find("eta = 10000000000"), std::string::npos) << what;
  }
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

// The mean of a probe's column over its rows from time `from` on (past the acoustic start-up).
double mean_from(const std::string& directory, const std::string& probe, int column, double from) {
  const auto t = test::csv_column(directory + "/" + probe + ".csv", 0);
  const auto f = test::csv_column(directory + "/" + probe + ".csv", column);
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= from) sum += f[k], ++n;
  return sum / n;
}

TEST(Fluid, HydrostaticTankHoldsRhoGHAndStaysStill) {
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_tank").string();
  auto simulation = make_simulation(kTank, {"output.vtp=false"}, options);
  const RunSummary summary = simulation->run();  // the health monitor checks the density band
  // The water rings acoustically (period 4 H / c = 0.09, mid-depth standard deviation ~300 Pa):
  // one instant is a sample of that noise, so the pressures are time means past the start-up.
  const double bottom = mean_from(options.output_directory, "bottom", 1, 0.5);
  const double middle = mean_from(options.output_directory, "bottom", 2, 0.5);
  const double kinetic = summary.probes.at("kinetic_energy").at("kinetic_energy");
  const double potential = 1000.0 * 9.81 * 1.0 * 0.5;  // rho g H^2 W / 2 per unit depth
  std::cout << "mean bottom pressure " << bottom << " (rho g H = 9810), mid-depth " << middle
            << " (4905), kinetic energy " << kinetic << " J (" << kinetic / potential
            << " of the potential energy)\n";
  // Measured at dp = H/20 over t = 0.5-2: bottom (linear extrapolation to the wall) 10,112
  // (+3.1%), mid-depth 5,034 (+2.6%).
  EXPECT_NEAR(bottom, 9810.0, 1.5 * 0.031 * 9810.0);
  EXPECT_NEAR(middle, 4905.0, 1.5 * 0.026 * 4905.0);
  // The walls' acoustic dissipation along their normals damps the ringing: the mid-depth
  // pressure's standard deviation over t = 0.5-2 is 174 Pa (563 Pa with the dissipation along
  // the normal as each fluid particle sees it, which the wall lattice's roughness tilts).
  const auto t = test::csv_column(options.output_directory + "/bottom.csv", 0);
  const auto p = test::csv_column(options.output_directory + "/bottom.csv", 2);
  double square = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= 0.5) square += (p[k] - middle) * (p[k] - middle), ++n;
  std::cout << "mid-depth pressure standard deviation " << std::sqrt(square / n) << " Pa\n";
  EXPECT_LT(std::sqrt(square / n), 1.5 * 174.0);
  EXPECT_LT(kinetic, 1e-3 * potential);
}

// The transport-velocity shift in a free-surface flow: the tank at rest with one sweep per step.
// Shifting every particle (free_surface 0) pushes the surface's particles out of the water, and
// the run stops with one outside the domain before t = 1 (at t = 0.73). Leaving the particles
// whose number density is under 0.95 of a full neighbourhood's, the water stays in its tank; the
// layers under the surface are shifted up into it, which raises the level at x = 0.5 by 0.0076
// over t = 0.5-2 (0.15 of a spacing: the unshifted tank's 1.0082 against 1.0158), and the
// pressures at y = 0.1-0.9 read 250-475 Pa above hydrostatic (60-260 unshifted; mid-depth +7.6%,
// 5,278 Pa against 4,905, +2.6% unshifted) while the walls carry the weight within 0.07% over
// t = 0.5-2. The water sloshes less: mean kinetic energy 0.357 J against 0.430 J.
const std::string kShiftedTank = std::string(kTank) + R"yaml(  - name: level
    interval: 0.05
    reduce: {quantity: surface_height, axis: 1, at: [0.5, 0]}
)yaml";

// The tank tests' shift: one sweep per step, files off, and `more` on top.
std::vector<std::string> one_sweep_shift(std::initializer_list<std::string> more) {
  std::vector<std::string> set = {"modules[0].fluid.transport_velocity=true",
                                  "modules[0].fluid.transport_velocity_sweeps=1",
                                  "output.vtp=false"};
  set.insert(set.end(), more);
  return set;
}

TEST(Fluid, TheFreeSurfaceShiftLeavesTheSurfaceInTheWater) {
  EXPECT_THROW(
      make_simulation(
          kShiftedTank,
          one_sweep_shift({"modules[0].fluid.transport_velocity_free_surface=0", "end_time=1"}))
          ->run(),
      HealthError);

  const auto surface = one_sweep_shift({"modules[0].fluid.transport_velocity_free_surface=0.95"});
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_shifted_tank").string();
  auto simulation = make_simulation(kShiftedTank, surface, options);
  simulation->run();
  const double level = mean_from(options.output_directory, "level", 1, 0.5);
  const double middle = mean_from(options.output_directory, "bottom", 2, 0.5);
  const double kinetic = mean_from(options.output_directory, "kinetic_energy", 1, 0.5);
  std::cout << "shifted tank: level " << level << ", mid-depth " << middle << " Pa, kinetic energy "
            << kinetic << " J\n";
  EXPECT_NEAR(level, 1.0, 1.5 * 0.0158);              // measured 1.0158; unshifted 1.0082
  EXPECT_GT(level, 1.0082 + 0.5 * 0.0076);            // the layers under the surface were shifted
  EXPECT_NEAR(middle, 4905.0, 1.5 * 0.076 * 4905.0);  // measured 5,278
  EXPECT_LT(kinetic, 1.5 * 0.357);                    // measured 0.357 J
  const auto& features = simulation->module(0).info().active_features;
  EXPECT_NE(std::find(features.begin(), features.end(),
                      "transport velocity (1 sweeps, free surface left)"),
            features.end());
}

// Without a density summation (density_treatment: none) the shift sums the number density its
// hold test reads itself: the tank keeps its surface and its shifted layers (level 1.0175 over
// t = 0.5-2; holding every particle leaves the unshifted tank's 1.0072, shifting every one fails).
TEST(Fluid, TheFreeSurfaceShiftSumsItsOwnNumberDensityWithoutADensitySummation) {
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_shifted_tank_continuity").string();
  make_simulation(kShiftedTank,
                  one_sweep_shift({"modules[0].fluid.transport_velocity_free_surface=0.95",
                                   "modules[0].fluid.density_treatment=none"}),
                  options)
      ->run();
  const double level = mean_from(options.output_directory, "level", 1, 0.5);
  std::cout << "shifted tank without a density summation: level " << level << "\n";
  EXPECT_NEAR(level, 1.0, 1.5 * 0.0175);    // measured 1.0175
  EXPECT_GT(level, 1.0072 + 0.5 * 0.0103);  // the layers under the surface were shifted
}

// The hydrostatic band on the same tank: holding also the particles within two spacings' head
// of the surface (p < rho0 g 2 dp = 981 Pa) keeps the shifted layers below from crowding the
// layer under the surface up. Measured over t = 0.5-2: level 1.0138 (free-surface rule alone
// 1.0158, unshifted 1.0082), mid-depth 5,147 Pa (+4.9%; free-surface rule alone 5,278, +7.6%).
// Without gravity the band has no head to measure and is refused, naming the key.
TEST(Fluid, AHydrostaticBandKeepsTheLayerUnderTheSurfaceFromDilating) {
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_banded_tank").string();
  const auto band = one_sweep_shift({"modules[0].fluid.transport_velocity_free_surface=0.95",
                                     "modules[0].fluid.transport_velocity_hydrostatic_band=2"});
  auto simulation = make_simulation(kShiftedTank, band, options);
  simulation->run();
  const double level = mean_from(options.output_directory, "level", 1, 0.5);
  const double middle = mean_from(options.output_directory, "bottom", 2, 0.5);
  std::cout << "banded tank: level " << level << ", mid-depth " << middle << " Pa\n";
  EXPECT_NEAR(level, 1.0, 1.5 * 0.0138);              // measured 1.0138
  EXPECT_LT(level, 1.0158 - 0.5 * 0.0020);            // below the free-surface rule's level
  EXPECT_NEAR(middle, 4905.0, 1.5 * 0.049 * 4905.0);  // measured 5,147
  EXPECT_LT(middle, 5278.0 - 0.5 * 131.0);            // below the free-surface rule's 5,278
  const auto& features = simulation->module(0).info().active_features;
  EXPECT_NE(std::find(features.begin(), features.end(),
                      "transport velocity (1 sweeps, free surface left, hydrostatic band left)"),
            features.end());

  auto weightless = band;
  weightless.push_back("modules[0].fluid.gravity=[0, 0]");
  try {
    make_simulation(kShiftedTank, weightless);
    ADD_FAILURE() << "a hydrostatic band without gravity was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("modules[0].fluid.transport_velocity_hydrostatic_band"),
              std::string::npos)
        << e.what();
  }
}

// The same tank with the force of the water on its walls: in total it carries the weight
// rho g H W = 9810 N/m, and the left wall (with its corner) the thrust rho g H^2 / 2 = 4905 N/m.
// The water rings acoustically (period 4 H / c = 0.09): the forces are averaged over t = 0.5-1.
const std::string kTankWallForces = std::string(kTank) + R"yaml(  - name: all_walls
    body: water_walls
    interval: 0.005
    reduce: {quantity: total, field: force}
  - name: left_wall
    body: water_walls
    interval: 0.005
    reduce: {quantity: total, field: force, within: {lower: [-0.2, -0.2], upper: [0, 1.3]}}
)yaml";
const std::vector<std::string> kWallForceOutput = {"modules[0].fluid.outputs=[wall_force]",
                                                   "end_time=1", "output.vtp=false"};

TEST(Fluid, TankWallsCarryTheWeightAndTheHydrostaticThrust) {
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_wall_force").string();
  auto simulation = make_simulation(kTankWallForces, kWallForceOutput, options);
  simulation->run();
  auto mean = [&](const std::string& probe, int column) {
    return mean_from(options.output_directory, probe, column, 0.5);
  };

  const double fx = mean("all_walls", 1), fy = mean("all_walls", 2);
  const double thrust = mean("left_wall", 1);
  std::cout << "mean force on the walls (" << fx << ", " << fy << "), weight 9810; on the left "
            << "wall " << thrust << ", thrust 4905\n";
  // Measured -9,816 and -4,897 (+0.065% and -0.16%) with the output the step's mean force; the
  // last acoustic sub-step's force alone read -9,785 and -4,886 (-0.25% and -0.40%).
  EXPECT_NEAR(fy, -9810.0, 1.5 * 0.00066 * 9810.0);
  EXPECT_NEAR(fx, 0.0, 0.001 * 9810.0);  // symmetric tank
  EXPECT_NEAR(thrust, -4905.0, 1.5 * 0.0016 * 4905.0);
}

// The walls' force output is the advection step's mean over its acoustic sub-steps, so what it
// says the walls carry is what the water's momentum says they push it with: gravity and the
// walls are the only forces on the water, m dP/dt = F_walls - M g. The tank with the free-surface
// shift and its band (still settling at t = 0.5-1.25) sampled every step over t = 0.5-2: the
// output's mean is 0.99968 of the weight and the momentum's 0.99966 (0.002% apart; the last
// sub-step's force alone read 0.99230, 0.74% apart).
const std::string kTankMomentum = std::string(kTank) + R"yaml(  - name: all_walls
    body: water_walls
    interval: 0.001
    reduce: {quantity: total, field: force}
  - name: velocity_sum
    interval: 0.001
    reduce: {quantity: total, field: velocity}
)yaml";

TEST(Fluid, TheWallForceOutputCarriesTheImpulseTheWaterReceives) {
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_wall_impulse").string();
  auto overrides = one_sweep_shift({"modules[0].fluid.transport_velocity_free_surface=0.95",
                                    "modules[0].fluid.transport_velocity_hydrostatic_band=2",
                                    "modules[0].fluid.outputs=[wall_force]"});
  make_simulation(kTankMomentum, overrides, options)->run();
  const std::string dir = options.output_directory;
  const auto t = test::csv_column(dir + "/all_walls.csv", 0);
  const auto fy = test::csv_column(dir + "/all_walls.csv", 2);
  const auto tv = test::csv_column(dir + "/velocity_sum.csv", 0);
  const auto vy = test::csv_column(dir + "/velocity_sum.csv", 2);
  ASSERT_EQ(t.size(), tv.size());
  const double weight = 1000.0 * 9.81 * 1.0, particle_mass = 1000.0 * 0.05 * 0.05;
  std::size_t first = 0, last = 0;
  double force = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= 0.5 && t[k] <= 2.0) {
      if (n == 0) first = k;
      last = k, force -= fy[k], ++n;
    }
  ASSERT_GT(n, 100);
  const double carried = force / n / weight;  // the walls' push on the water, by the output
  const double momentum_rate = particle_mass * (vy[last] - vy[first]) / (tv[last] - tv[first]);
  const double balance = 1.0 + momentum_rate / weight;  // the same, by the water's momentum
  std::cout << "walls carry " << carried << " of the weight by their force output, " << balance
            << " by the water's momentum\n";
  EXPECT_NEAR(carried, balance, 1.5 * 2.0e-5);  // measured 2.0e-5 apart
  EXPECT_NEAR(balance, 1.0, 1.5 * 3.4e-4);      // measured 0.99966
}

// A probe of the total of a wall field over the channel's walls, sampled every 0.01.
std::string walls_total_probe(const std::string& name, const std::string& field) {
  return "  - name: " + name + "\n    body: channel_walls\n    interval: 0.01\n" +
         "    reduce: {quantity: total, field: " + field + "}\n";
}

// Transient Poiseuille flow (examples/fluid_poiseuille.yaml, periodic along x, body force g = 0.8,
// nu = 0.1, plates at y = 0 and 1, 2 long) with the walls' force and its viscous share as
// outputs. Over t = 1.5-2 the walls carry the analytic wall shear of both plates,
// 2 x 2 x rho nu du/dy(0, t) = 2 rho g L - sum_n 16 rho g L / (pi^2 (2n+1)^2) e^(-(2n+1)^2 pi^2 nu
// t).
double poiseuille_wall_shear(double t) {
  const double g = 0.8, nu = 0.1, L = 1.0, pi = std::acos(-1.0);
  double f = 2.0 * g * L;
  for (int n = 0; n < 200; ++n) {
    const double k = 2 * n + 1;
    f -= 16.0 * g * L / (pi * pi * k * k) * std::exp(-k * k * pi * pi * nu * t / (L * L));
  }
  return f;
}

// Runs the Poiseuille channel with the given fluid outputs and extra probes; returns the output
// directory.
std::string run_poiseuille_with(const std::string& outputs, const std::string& probes,
                                const std::string& name) {
  const std::string path = std::string(COSPH_SOURCE_DIR) + "/examples/fluid_poiseuille.yaml";
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  // The example's last key is `probes:`, so these join its list.
  const std::string scene =
      std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()) + probes;
  RunOptions options;
  options.output_directory = (std::filesystem::path(testing::TempDir()) / name).string();
  make_simulation(
      scene, {"modules[0].fluid.outputs=" + outputs, "output.vtp=false", "checkpoint.at_end=false"},
      options)
      ->run();
  return options.output_directory;
}

TEST(Fluid, TheWallsViscousForceOutputIsTheWallShearsShare) {
  const std::string dir =
      run_poiseuille_with("[wall_force, wall_viscous_force]",
                          walls_total_probe("walls_force", "force") +
                              walls_total_probe("walls_viscous_force", "viscous_force"),
                          "cosph_fluid_viscous_share");
  const auto t = test::csv_column(dir + "/walls_force.csv", 0);
  const auto total = test::csv_column(dir + "/walls_force.csv", 1);
  const auto viscous = test::csv_column(dir + "/walls_viscous_force.csv", 1);
  ASSERT_EQ(t.size(), viscous.size());
  double total_gap = 0.0, viscous_gap = 0.0, friction = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= 1.5) {
      const double shear = poiseuille_wall_shear(t[k]);
      total_gap += total[k] / shear - 1.0;
      viscous_gap += viscous[k] / shear - 1.0;
      friction += (total[k] - viscous[k]) / shear;
      ++n;
    }
  ASSERT_GT(n, 25);
  total_gap /= n, viscous_gap /= n, friction /= n;
  std::cout << "over t = 1.5-2, against the analytic wall shear: total " << total_gap
            << ", viscous share " << viscous_gap << ", the rest (pressure path) " << friction
            << "\n";
  // Measured: the walls carry the shear to -0.38%; the viscous term's share is 4.2% short of it
  // and the Riemann dissipation's numerical friction (the no-slip rule's mirrored velocity along
  // each pair) carries the other 3.8%. A viscous output that were the total (or zero) fails.
  EXPECT_LT(std::abs(total_gap), 1.5 * 0.0038);
  EXPECT_GT(viscous_gap, -1.5 * 0.042);
  EXPECT_LT(viscous_gap, -0.042 / 1.5);

  // Asked for alone (its walls then record for it), the viscous output is the same.
  const std::string alone = run_poiseuille_with(
      "[wall_viscous_force]", walls_total_probe("walls_viscous_force", "viscous_force"),
      "cosph_fluid_viscous_alone");
  EXPECT_EQ(test::csv_column(alone + "/walls_viscous_force.csv", 1), viscous);
}

// The same tank's walls read by wall sensors (the mean pressure over a face from the force on the
// wall behind it): rho g (H - y) on the side walls and rho g H on the floor, averaged over the
// acoustic ringing (t = 0.5-1).
const std::string kTankSensors = std::string(kTank) + R"yaml(  - name: sensors
    body: water_walls
    interval: 0.005
    sensor: {at: [[0, 0.25], [0, 0.5], [0, 0.75]], normal: [1, 0], diameter: 0.1}
  - name: floor_sensor
    body: water_walls
    interval: 0.005
    sensor: {at: [[0.5, 0]], normal: [0, 1], diameter: 0.1}
  - name: foot_sensor
    body: water_walls
    interval: 0.005
    sensor: {at: [[0, 0.025]], normal: [1, 0], diameter: 0.05}
  - name: floor_corner_sensor
    body: water_walls
    interval: 0.005
    sensor: {at: [[0.025, 0]], normal: [0, 1], diameter: 0.05}
)yaml";

TEST(Fluid, WallSensorsReadTheHydrostaticPressure) {
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_wall_sensors").string();
  auto simulation = make_simulation(kTankSensors, kWallForceOutput, options);
  simulation->run();
  auto mean = [&](const std::string& probe, int column) {
    return mean_from(options.output_directory, probe, column, 0.5);
  };

  const double floor = mean("floor_sensor", 1);
  std::cout << "floor " << floor << " (9810)";
  const double heights[] = {0.25, 0.5, 0.75};
  // Measured at H/20: -0.59%, -0.56%, -0.25% on the side wall, -0.22% on the floor (the water
  // still rings a little; -0.71%, -0.55%, -0.61% and -0.32% from the last acoustic sub-step's
  // force alone, before the walls' output was the step's mean).
  const double bounds[] = {1.5 * 0.0059, 1.5 * 0.0056, 1.5 * 0.0025};
  for (int k = 0; k < 3; ++k) {
    const double expected = 1000.0 * 9.81 * (1.0 - heights[k]);
    const double side = mean("sensors", k + 1);
    std::cout << ", side wall at y = " << heights[k] << ": " << side << " (" << expected << ")";
    EXPECT_NEAR(side, expected, bounds[k] * expected) << "side wall at y = " << heights[k];
  }
  std::cout << "\n";
  EXPECT_NEAR(floor, 9810.0, 1.5 * 0.0022 * 9810.0);
  const double foot = mean("foot_sensor", 1), corner_floor = mean("floor_corner_sensor", 1);
  std::cout << "foot of the side wall " << foot << " (" << 1000.0 * 9.81 * 0.975
            << "), floor in the corner " << corner_floor << " (9810)\n";
  // Sensors one spacing wide in the corner, against the side wall's foot and on the floor next
  // to it: measured +1.05% and +2.63% (+0.59% and +2.08% from the last sub-step's force alone).
  // The water pushes the corner's particles along the pairs' diagonals; the sensors take that
  // push (WallSensor: the corner's particles pass their force to the face's end). Without it
  // they read -22.8% and -19.9%.
  EXPECT_NEAR(foot, 1000.0 * 9.81 * 0.975, 1.5 * 0.0105 * 1000.0 * 9.81 * 0.975);
  EXPECT_NEAR(corner_floor, 9810.0, 1.5 * 0.0263 * 9810.0);
}

// A sensor that cannot read: its normal pointing into the wall (no wall particle behind its face),
// a zero normal, a body without the fluid's force on it. Each error names the key.
TEST(Fluid, WallSensorMistakesNameTheirKey) {
  auto message = [&](const std::vector<std::string>& set) -> std::string {
    try {
      make_simulation(kTankSensors, set);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  std::vector<std::string> flipped = kWallForceOutput, zero = kWallForceOutput;
  flipped.push_back("probes[2].sensor.normal=[-1, 0]");
  zero.push_back("probes[3].sensor.normal=[0, 0]");
  const std::string behind = message(flipped);
  EXPECT_NE(behind.find("probes[2].sensor.at[0]"), std::string::npos) << behind;
  EXPECT_NE(behind.find("normal"), std::string::npos) << behind;
  EXPECT_NE(message(zero).find("probes[3].sensor.normal"), std::string::npos);
  const std::string no_force = message({"end_time=1"});
  EXPECT_NE(no_force.find("probes[2].body"), std::string::npos) << no_force;
  EXPECT_NE(no_force.find("wall_force"), std::string::npos) << no_force;
}

// Water hammer: a water slab (rho0 = 1, c = 10, periodic across it) hits a wall at U = 0.5 and the
// wall's pressure jumps to that of the reflected shock, p1 = rho0 (U + s) U with the shock speed
// s = (-U + sqrt(U^2 + 4 c^2)) / 2 for p = c^2 (rho - rho0): 5.1266 (rho0 c U = 5 to first order),
// until the wave returns from the slab's free end (t = 0.2). The sensor's face spans the periodic
// seam, so it also checks that the sensor reads across it.
const std::string kWaterHammer = R"yaml(
dimension: 2
end_time: 0.18
domain: {lower: [-0.2, 0], upper: [1.4, 0.4], periodic: [false, true]}
modules:
  - name: water
    fluid:
      body:
        spacing: 0.05
        shape: {box: {lower: [0, 0], upper: [1, 0.4]}}
      density: 1
      max_velocity: 1
      initial_velocity: ["0.5", "0"]
      walls:
        - name: wall
          shape: {box: {lower: [1, 0], upper: [1.15, 0.4]}}
      outputs: [wall_force]
probes:
  - name: sensor
    body: water_walls
    interval: 0.005
    sensor: {at: [[1, 0]], normal: [-1, 0], diameter: 0.2}
)yaml";

TEST(Fluid, AWaterSlabHittingAWallLoadsItWithTheWaterHammerPressure) {
  RunOptions options;
  options.output_directory =
      (std::filesystem::path(testing::TempDir()) / "cosph_fluid_water_hammer").string();
  auto simulation = make_simulation(kWaterHammer, {"output.vtp=false"}, options);
  simulation->run();
  const auto t = test::csv_column(options.output_directory + "/sensor.csv", 0);
  const auto p = test::csv_column(options.output_directory + "/sensor.csv", 1);
  double sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= 0.03 && t[k] <= 0.17) sum += p[k], ++n;
  const double s = 0.5 * (-0.5 + std::sqrt(0.25 + 400.0)), expected = (0.5 + s) * 0.5;
  std::cout << "water hammer on the wall: " << sum / n << " (" << expected << ")\n";
  // Measured 5.1358, +0.18% (5.0269, -1.94%, from the last acoustic sub-step's force alone).
  EXPECT_NEAR(sum / n, expected, 1.5 * 0.0018 * expected);
}

// The same slab's sensor across its period of 0.4, its wall particles' share 0.05: a face of
// 0.34 (with a share, 0.39) is read; one of 0.38 (0.43), under which two periodic images of a
// column would lie, is refused with the key named.
TEST(Fluid, AWallSensorTooWideForItsPeriodIsRefused) {
  EXPECT_NO_THROW(make_simulation(kWaterHammer, {"probes[0].sensor.diameter=0.34"}));
  try {
    make_simulation(kWaterHammer, {"probes[0].sensor.diameter=0.38"});
    ADD_FAILURE() << "a sensor too wide for its period was accepted";
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("probes[0].sensor"), std::string::npos) << message;
    EXPECT_NE(message.find("periodic axis 1"), std::string::npos) << message;
  }
}

// Walls resist the fluid's approach, not its sliding: an inviscid layer of water sliding along a
// floor (periodic along it) keeps its momentum. The Riemann dissipation along each pair's
// direction with the whole velocity mirrored, as before, braked it to 65% of its speed within
// 1 s; with the dissipation along the wall particles' own normals the layer loses 2.4e-4 of it
// (7.2e-5 along the normal as each fluid particle sees it).
TEST(Fluid, AnInviscidLayerSlidesAlongTheFloorWithoutFriction) {
  const std::string text = R"yaml(
dimension: 2
end_time: 1.0
domain: {lower: [0, -0.2], upper: [1, 0.6], periodic: [true, false]}
modules:
  - name: water
    fluid:
      body:
        spacing: 0.05
        shape: {box: {lower: [0, 0], upper: [1, 0.2]}}
      density: 1000
      max_velocity: 4.43
      gravity: [0, -9.81]
      initial_velocity: ["1", "0"]
      initial_pressure: "1000 * 9.81 * (0.2 - y)"
      walls:
        - name: floor
          shape: {box: {lower: [0, -0.15], upper: [1, 0]}}
)yaml";
  auto simulation = make_simulation(text, {"output.vtp=false"});
  simulation->run();
  const ParticleSet<2>& water = particles_of<2>(*simulation);
  double momentum = 0.0, mass = 0.0;
  for (std::size_t i = 0; i < water.size(); ++i) {
    momentum += water.scalar("mass")[i] * water.vector("velocity")[i][0];
    mass += water.scalar("mass")[i];
  }
  std::cout << "mean velocity along the floor after 1 s: " << momentum / mass << " (1)\n";
  EXPECT_NEAR(momentum / mass, 1.0, 1.5 * 2.43e-4);  // measured 0.999757
}

// Moving walls: the whole tank of the hydrostatic test moves sideways at 0.5 m/s with the water.
// Galilean invariance: relative to the tank, the water moves exactly as in the tank at rest (the
// mirrored wall velocity 2 v_w - v_i, the moving wall particles and their rebuilt cell list).
TEST(Fluid, WaterInATankMovingSidewaysMovesWithIt) {
  std::string text = kTank;
  text.replace(text.find("upper: [1.2, 1.4]"), 17, "upper: [2.2, 1.4]");
  text.replace(text.find("      initial_pressure"), 0,
               "      initial_velocity: [\"0.5\", \"0\"]\n");
  text.replace(text.find("        - name: tank\n"), 21,
               "        - name: tank\n          velocity: [\"0.5\", \"0\"]\n");
  auto moving = make_simulation(text, {"end_time=1"});
  auto still = make_simulation(kTank, {"end_time=1"});
  moving->run();
  still->run();
  // Kinetic energy relative to the tank, and the water's mean velocity.
  auto relative = [](Simulation& simulation, const Vec<2>& frame) {
    const ParticleSet<2>& water = particles_of<2>(simulation);
    double kinetic = 0.0, mass = 0.0, lowest = INFINITY;
    Vec<2> momentum = Vec<2>::Zero();
    for (std::size_t i = 0; i < water.size(); ++i) {
      const double m = water.scalar("mass")[i];
      const Vec<2> v = water.vector("velocity")[i];
      kinetic += 0.5 * m * (v - frame).squaredNorm();
      momentum += m * v;
      mass += m;
      lowest = std::min(lowest, water.vector("position")[i][0]);
    }
    return std::tuple{kinetic, Vec<2>(momentum / mass), lowest};
  };
  const auto [moving_kinetic, moving_mean, lowest] = relative(*moving, Vec<2>(0.5, 0.0));
  const auto [still_kinetic, still_mean, unused] = relative(*still, Vec<2>::Zero());
  double wall_left = INFINITY;
  for (const auto& x : particles_of<2>(*moving, 1).vector("position"))
    wall_left = std::min(wall_left, x[0]);
  std::cout << "moving tank at t = 1: water mean velocity (" << moving_mean.transpose()
            << "), kinetic energy relative to the tank " << moving_kinetic
            << " J; tank at rest: " << still_kinetic << " J\n";
  EXPECT_NEAR(wall_left, -0.175 + 0.5, 1e-9);  // the walls moved 0.5 m
  EXPECT_GT(lowest, 0.5);                      // none of the water is left behind
  EXPECT_NEAR(moving_mean[0], 0.5, 0.01);      // it moves with the tank
  EXPECT_NEAR(moving_mean[1], still_mean[1], 0.01);
  // As still as the tank at rest: measured 2.7721 J against 2.7724 J.
  EXPECT_NEAR(moving_kinetic, still_kinetic, 0.05 * still_kinetic);
}

// An accelerating tank: the equivalence principle. Water with its free surface tilted by a/g in a
// tank accelerating at a = 1 m/s^2 moves like the same water in a tank at rest under gravity
// tilted to (-a, -g): the walls' pressure extension uses g - a_w. Both start in equilibrium.
std::string tilted_tank(const std::string& gravity, const std::string& wall_velocity,
                        double upper_x) {
  // The surface y = 0.650968 - (a / g) x, a / g = 0.1019368, holds 0.6 m^3 of water per metre.
  return R"yaml(
dimension: 2
end_time: 1.0
domain: {lower: [-0.2, -0.2], upper: [)yaml" +
         std::to_string(upper_x) + R"yaml(, 1.4]}
modules:
  - name: water
    fluid:
      body:
        spacing: 0.05
        shape: {polygon: {vertices: [[0, 0], [1, 0], [1, 0.549031], [0, 0.650968]]}}
      density: 1000
      max_velocity: 4.43
      gravity: )yaml" +
         gravity + R"yaml(
      initial_pressure: "1000 * (9.81 * (0.650968 - y) - 1.0 * x)"
      walls:
        - name: tank
          velocity: )yaml" +
         wall_velocity + R"yaml(
          shape:
            difference:
              base: {box: {lower: [-0.2, -0.2], upper: [1.2, 1.3]}}
              subtract: {box: {lower: [0, 0], upper: [1, 1.3]}}
probes:
  - name: kinetic_energy
    interval: 0.05
    reduce: {quantity: kinetic_energy}
checkpoint: {interval: 0.5}
)yaml";
}

TEST(Fluid, WaterInAnAcceleratingTankMovesLikeWaterUnderTiltedGravity) {
  auto accelerating = make_simulation(tilted_tank("[0, -9.81]", "[\"1.0 * t\", \"0\"]", 2.0), {});
  auto tilted = make_simulation(tilted_tank("[-1.0, -9.81]", "[\"0\", \"0\"]", 1.2), {});
  accelerating->run();
  tilted->run();
  auto kinetic = [](Simulation& simulation, double frame) {
    const ParticleSet<2>& water = particles_of<2>(simulation);
    double e = 0.0;
    for (std::size_t i = 0; i < water.size(); ++i)
      e += 0.5 * water.scalar("mass")[i] *
           (water.vector("velocity")[i] - Vec<2>(frame, 0.0)).squaredNorm();
    return e;
  };
  const double moving = kinetic(*accelerating, 1.0), at_rest = kinetic(*tilted, 0.0);
  std::cout << "accelerating tank at t = 1: kinetic energy relative to the tank " << moving
            << " J; tank at rest under tilted gravity " << at_rest << " J\n";
  // Measured 0.5368 J against 0.5321 J (with the wall friction of the earlier scheme 0.514 J
  // against 0.510 J); without the walls' acceleration in the pressure extension the accelerating
  // tank sloshed: 0.585 J.
  EXPECT_NEAR(moving, at_rest, 0.05 * at_rest);
}

// Moved walls restart where they were, with their last velocity and acceleration: a restart of
// the accelerating tank from its checkpoint at t = 0.5 ends bit for bit where the uninterrupted
// run ends.
TEST(Fluid, RestartWithMovingWallsIsBitIdentical) {
  namespace fs = std::filesystem;
  const std::string text = tilted_tank("[0, -9.81]", "[\"1.0 * t\", \"0\"]", 2.0);
  const fs::path dir = fs::path(testing::TempDir()) / "cosph_fluid_moving_restart";
  fs::remove_all(dir);
  auto run = [&](const std::string& name, const std::string& restart) {
    RunOptions options;
    options.threads = 1;
    options.output_directory = (dir / name).string();
    options.restart_file = restart;
    auto simulation = make_simulation(text, {}, options);
    simulation->run();
    return std::pair{particles_of<2>(*simulation).vector("position"),
                     particles_of<2>(*simulation, 1).vector("position")};
  };
  const auto full = run("full", "");
  const fs::path checkpoint = dir / "full" / "checkpoint_000001.ckpt";
  ASSERT_TRUE(fs::exists(checkpoint));
  const auto continued = run("restart", checkpoint.string());
  ASSERT_EQ(full.first.size(), continued.first.size());
  for (std::size_t i = 0; i < full.first.size(); ++i)
    ASSERT_EQ(full.first[i], continued.first[i]) << "water particle " << i;
  for (std::size_t i = 0; i < full.second.size(); ++i)
    ASSERT_EQ(full.second[i], continued.second[i]) << "wall particle " << i;
  EXPECT_NEAR(full.second[0][0], -0.175 + 0.5, 1e-6);  // the tank moved a t^2 / 2 = 0.5 m
}

TEST(Fluid, BadInputNamesTheKey) {
  const std::string text = kTank;
  auto message = [&](const std::vector<std::string>& set) -> std::string {
    try {
      make_simulation(text, set);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  const std::string no_speed = [&] {
    std::string t = text;
    t.replace(t.find("      max_velocity: 4.43\n"), 25, "");
    try {
      make_simulation(t, {});
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
  const std::string vertex = message({"modules[0].fluid.body.placement=vertex"});
  EXPECT_NE(vertex.find("modules[0].fluid.body.placement"), std::string::npos) << vertex;
  EXPECT_NE(vertex.find("equal particle volumes"), std::string::npos) << vertex;
  EXPECT_NE(message({"modules[0].fluid.body.placement=nodes"}).find("placement"),
            std::string::npos);
  // The tank's water is inviscid: it has no viscous share of the walls' force to write.
  const std::string inviscid = message({"modules[0].fluid.outputs=[wall_viscous_force]"});
  EXPECT_NE(inviscid.find("modules[0].fluid.outputs"), std::string::npos) << inviscid;
  EXPECT_NE(inviscid.find("viscous fluid"), std::string::npos) << inviscid;
  const std::string within = [&] {
    std::vector<std::string> set = kWallForceOutput;
    set.insert(set.end(), {"probes[3].reduce.quantity=maximum", "probes[3].reduce.field=volume"});
    try {
      make_simulation(kTankWallForces, set);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_NE(within.find("probes[3].reduce.within"), std::string::npos) << within;
}

}  // namespace
}  // namespace cosph
