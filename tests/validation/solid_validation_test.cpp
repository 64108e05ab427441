// The solid module against references (../shared/reference/README.md): the 2D oscillating plate's
// period against linear theory and its undamped energy, the Land et al. (2015) beam's tip against
// 4.17 mm by Richardson extrapolation of two resolutions, and the 3D bending cantilever's period.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "../support/probe_csv.hpp"
#include "../support/reduced_run.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

std::string example(const std::string& name) {
  return std::string(COSPH_SOURCE_DIR) + "/examples/" + name;
}

// Runs a scene into a fresh temporary directory and returns it.
std::string run_scene(const std::string& scene, const std::vector<std::string>& overrides,
                      const std::string& tag) {
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + "cosph_solid_" + tag;
  Simulation simulation(load_scene_file(scene, overrides), builtin_modules(),
                        test::with_step_cap(options));
  simulation.initialize();
  simulation.run();
  return options.output_directory;
}

// Column `column` (0 = time) of a probe CSV.
using test::csv_column;

// Times where y crosses zero downwards (linear interpolation).
std::vector<double> downward_crossings(const std::vector<double>& t, const std::vector<double>& y) {
  std::vector<double> crossings;
  for (std::size_t k = 0; k + 1 < y.size(); ++k)
    if (y[k] > 0.0 && y[k + 1] <= 0.0)
      crossings.push_back(t[k] + y[k] * (t[k + 1] - t[k]) / (y[k] - y[k + 1]));
  return crossings;
}

// The spread of kinetic + elastic energy over a run (the probes kinetic_energy and elastic_energy),
// as a fraction of the initial energy.
double energy_band(const std::string& dir) {
  const auto kinetic = csv_column(dir + "/kinetic_energy.csv", 1);
  const auto elastic = csv_column(dir + "/elastic_energy.csv", 1);
  EXPECT_EQ(kinetic.size(), elastic.size());
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t k = 0; k < std::min(kinetic.size(), elastic.size()); ++k) {
    lo = std::min(lo, kinetic[k] + elastic[k]);
    hi = std::max(hi, kinetic[k] + elastic[k]);
  }
  return (hi - lo) / (kinetic[0] + elastic[0]);
}

TEST(SolidValidation, OscillatingPlatePeriodApproachesLinearTheoryAndKeepsItsEnergy) {
  const std::string dir = run_scene(example("solid_oscillating_plate.yaml"), {}, "plate");
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const auto t = csv_column(dir + "/tip.csv", 0), y = csv_column(dir + "/tip.csv", 1);
  const auto crossings = downward_crossings(t, y);
  // A precondition, not a bound: enough swings to average a period over (fewer means the plate
  // stopped swinging).
  ASSERT_GE(crossings.size(), 4u);
  const double period = (crossings.back() - crossings.front()) / (crossings.size() - 1);
  const double theory = 0.2541;  // omega^2 = E H^2 k^4 / (12 rho (1 - nu^2)), kL = 1.875
  std::cout << "plate period " << period << " (linear theory " << theory << ")\n";
  // Measured 0.269427 at H/dp = 10 (6.03% long) and 0.2600 at H/dp = 20 (2.3%): bench/studies.
  // Converging from above: bounded on both sides of the measured 6%.
  EXPECT_GT(period, 1.04 * theory);
  EXPECT_LT(period, 1.08 * theory);
  // Amplitude V_f c0 / omega = 0.01 * 57.03 / 24.73 = 0.02306.
  double amplitude = 0.0;
  for (double v : y) amplitude = std::max(amplitude, std::abs(v));
  std::cout << "plate amplitude " << amplitude << " (linear theory 0.02306)\n";
  EXPECT_NEAR(amplitude, 0.02306, 0.07 * 0.02306);  // measured 0.0241357 (+4.7%)

  // Undamped, no artificial viscosity: position Verlet keeps kinetic + elastic energy.
  const double band = energy_band(dir);
  std::cout << "energy band " << band << " of the initial energy\n";
  EXPECT_LT(band, 1.4e-5);  // measured 9.52e-6 over four periods
}

// The same plate with the energy integrated over the cells: the elastic energy the output reports
// (the mean over each particle's points, at the output's own displacements) is the energy the
// forces derive from, so Verlet keeps the sum as well.
TEST(SolidValidation, OscillatingPlateKeepsItsEnergyWithTheDualCellEnergy) {
  const std::string dir = run_scene(example("solid_oscillating_plate.yaml"),
                                    {"modules[0].solid.gradient_correction=quadratic",
                                     "modules[0].solid.energy_quadrature=dual_cell"},
                                    "plate_dual_cell");
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const double band = energy_band(dir);
  std::cout << "dual cells: energy band " << band << " of the initial energy\n";
  EXPECT_LT(band, 6.5e-6);  // measured 4.33e-6 over four periods
}

TEST(SolidValidation, LandBeamConvergesAtSecondOrderTo417Millimetres) {
  auto tip = [](double spacing, const std::string& tag) {
    std::ostringstream set;
    set.precision(17);
    set << "modules[0].solid.body.spacing=" << spacing;
    const std::string dir = run_scene(example("solid_land_beam.yaml"),
                                      {set.str(), "end_time=0.36", "output.interval=0.36"}, tag);
    if (test::reduced_run()) return double{NAN};
    return csv_column(dir + "/tip.csv", 1).back() * 1e3;  // deformed z in mm
  };
  const double coarse = tip(0.25e-3, "beam4"), fine = tip(0.25e-3 / 1.5, "beam6");
  COSPH_SKIP_CHECKS_IF_REDUCED();
  // Second order in the spacing: z(dp) = z* + C dp^2, so z* = (2.25 fine - coarse) / 1.25.
  const double extrapolated = (2.25 * fine - coarse) / 1.25;
  std::cout << "Land beam tip z: dp 0.25 mm " << coarse << ", dp 0.167 mm " << fine
            << ", extrapolated " << extrapolated << " (reference 4.17)\n";
  EXPECT_LT(fine, coarse);  // converging from above (coarse TL-SPH is too soft in bending)
  EXPECT_GT(fine, 4.17);
  // Measured 5.85392 and 4.91495 mm (+40%, +18%), extrapolated 4.16377 (-0.15%).
  EXPECT_GT(fine, 4.85);
  EXPECT_LT(fine, 4.98);
  EXPECT_NEAR(extrapolated, 4.17, 0.01);
}

// Seed 000's placement (the nodes of a grid, 41 x 5 x 5 = 1,025 and 51 x 6 x 6 = 1,836), solved as
// a steady state (examples/solid_land_beam_static.yaml). With the energy at the nodes the beam is
// too stiff (the trapezoidal rule across the thickness); integrated over the dual cells it is
// within half a percent at 1,025 particles, converging from above. The seed: 4.707 and 4.404 mm.
TEST(SolidValidation, LandBeamOnTheSeedsNodesIsWithinHalfAPercentWithTheDualCellEnergy) {
  // A steady run is one step: the reduced run could not shorten its three solves (149 s under the
  // sanitizers); the example's smoke run and the unit tests take the dual-cell path there.
  if (test::reduced_run()) GTEST_SKIP() << "reduced run: the steady beam runs in the release job";
  auto tip = [](double spacing, const std::string& quadrature) {
    std::ostringstream set;
    set.precision(17);
    set << "modules[0].solid.body.spacing=" << spacing;
    const std::string dir =
        run_scene(example("solid_land_beam_static.yaml"),
                  {set.str(), "modules[0].solid.energy_quadrature=" + quadrature},
                  "static_" + quadrature + std::to_string(int(1e6 * spacing)));
    if (test::reduced_run()) return double{NAN};
    return csv_column(dir + "/tip.csv", 1).back() * 1e3;  // deformed z in mm
  };
  const double nodal = tip(0.25e-3, "particle");
  const double coarse = tip(0.25e-3, "dual_cell"), fine = tip(0.2e-3, "dual_cell");
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout << "Land beam tip z on the seed's nodes: nodal energy " << nodal
            << " mm at 1,025 particles; dual cells " << coarse << " mm at 1,025, " << fine
            << " mm at 1,836 (reference 4.17)\n";
  // Measured 3.99493 mm (-4.2%).
  EXPECT_GT(nodal, 4.17 * (1.0 - 1.5 * 0.042));
  EXPECT_LT(nodal, 4.17 * (1.0 - 0.042 / 1.5));
  // Measured 4.18692 (+0.41%) and 4.17434 mm (+0.10%).
  EXPECT_GT(fine, 4.17);
  EXPECT_LT(fine, coarse);
  EXPECT_LT(coarse, 4.17 * (1.0 + 1.5 * 0.0041));
  EXPECT_LT(fine, 4.17 * (1.0 + 1.5 * 0.0010));
}

TEST(SolidValidation, BendingCantileverSwingsWithTheFirstModePeriod) {
  const std::string dir =
      run_scene(example("solid_bending_cantilever.yaml"), {"output.interval=3"}, "cantilever");
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const auto t = csv_column(dir + "/tip.csv", 0);
  const auto x = csv_column(dir + "/tip.csv", 1), y = csv_column(dir + "/tip.csv", 2);
  std::vector<double> lateral(x.size());  // along the initial velocity (sqrt 3, 1, 0) / 2
  for (std::size_t k = 0; k < x.size(); ++k) lateral[k] = 0.5 * std::sqrt(3.0) * x[k] + 0.5 * y[k];
  const auto crossings = downward_crossings(t, lateral);
  // A precondition, not a bound: one full swing to measure (the run covers a little more).
  ASSERT_GE(crossings.size(), 2u);
  const double period = crossings[1] - crossings[0];
  std::cout << "cantilever period " << period << " s (Euler-Bernoulli 1.79 s)\n";
  // Measured 1.90455 s, 6.4% above the small-amplitude Euler-Bernoulli period: the swing is
  // large (tip 4 m sideways), which lengthens it. No large-amplitude reference: bounded on both
  // sides around the measured value (a stiffness off by 10% moves it by 5%).
  EXPECT_GT(period, 1.87);
  EXPECT_LT(period, 1.94);
}

}  // namespace
}  // namespace cosph
