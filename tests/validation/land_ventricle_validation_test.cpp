// Land et al. (2015) problems 2 and 3 as steady states on the conforming nodes of the ventricle
// (examples/solid_land_ventricle_static.yaml, examples/solid_land_ventricle_active_static.yaml):
// the deformed apex against cosph's own finer solutions (the benchmark's FE values are not in
// ../shared/reference), converging monotonically, and the apex untangled (the largest hourglass
// measure of any particle).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>

#include "../support/probe_csv.hpp"
#include "../support/reduced_run.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

struct Apex {
  double endo = NAN, epi = NAN;  // deformed z, mm
  double hourglass = NAN;        // the largest hourglass measure
};

// Runs a steady ventricle at the spacing (m) and returns the apex. The sanitizer job's reduced
// run takes the coarse spacing and the load in small increments, so that its capped steps each
// converge quickly (the code paths are the same at any spacing).
Apex steady_apex(const std::string& scene, double spacing, const std::string& tag) {
  std::ostringstream set;
  set.precision(17);
  set << "modules[0].solid.body.spacing=" << (test::reduced_run() ? 1e-3 : spacing);
  std::vector<std::string> overrides{set.str(), "output.vtp=false", "checkpoint.at_end=false"};
  if (test::reduced_run()) overrides.push_back("modules[0].solid.steady_state.load_steps=40");
  RunOptions options;
  options.progress = false;
  options.output_directory = testing::TempDir() + "cosph_ventricle_" + tag;
  Simulation simulation(
      load_scene_file(std::string(COSPH_SOURCE_DIR) + "/examples/" + scene, overrides),
      builtin_modules(), test::with_step_cap(options));
  simulation.initialize();
  simulation.run();
  if (test::reduced_run()) return {};
  const std::string csv = options.output_directory + "/apex.csv";
  return {test::csv_column(csv, 1).back() * 1e3, test::csv_column(csv, 2).back() * 1e3,
          test::csv_column(options.output_directory + "/hourglass.csv", 1).back()};
}

TEST(LandVentricleValidation, InflationApexConvergesMonotonically) {
  const Apex coarse = steady_apex("solid_land_ventricle_static.yaml", 1e-3, "p2_1mm");
  // A reduced run would repeat the first at the same spacing (315 s under the sanitizers).
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const Apex fine = steady_apex("solid_land_ventricle_static.yaml", 0.75e-3, "p2_075mm");
  std::cout << "problem 2 apex z (mm): 1 mm endo " << coarse.endo << " epi " << coarse.epi
            << "; 0.75 mm endo " << fine.endo << " epi " << fine.epi
            << "; largest hourglass measure " << coarse.hourglass << ", " << fine.hourglass << "\n";
  // Both apices move down (further inflation) as the spacing shrinks.
  EXPECT_LT(fine.endo, coarse.endo);
  EXPECT_LT(fine.epi, coarse.epi);
  // Distances to the 0.6 mm solution (endo -26.5343, epi -28.2434 mm; 18,616 particles, the
  // seed's 18,486), measured 1 mm: 0.0881 and 0.0878; 0.75 mm: 0.0384 and 0.0318. Bounded on both
  // sides, about 1.5x: a placement or load that changed the convergence would leave these bands.
  const double endo_ref = -26.5343, epi_ref = -28.2434;
  EXPECT_GT(coarse.endo - endo_ref, 0.059);
  EXPECT_LT(coarse.endo - endo_ref, 0.132);
  EXPECT_GT(coarse.epi - epi_ref, 0.059);
  EXPECT_LT(coarse.epi - epi_ref, 0.132);
  EXPECT_GT(fine.endo - endo_ref, 0.026);
  EXPECT_LT(fine.endo - endo_ref, 0.058);
  EXPECT_GT(fine.epi - epi_ref, 0.021);
  EXPECT_LT(fine.epi - epi_ref, 0.048);
  // Untangled: measured 0.31 at 1 mm (median 0.097). Without the hourglass control the axis
  // particles near the apex drifted up to 8 mm sideways: 7.6 at 1 mm, 15 at 0.75 mm.
  EXPECT_LT(coarse.hourglass, 0.46);
  EXPECT_LT(fine.hourglass, 0.39);  // measured 0.26
}

// Problem 3 at 1 mm: fibres, pressure and active tension to their full values in one run. The
// apices rise (the fibres contract the ventricle against the pressure that inflates it); the
// distances to cosph's 0.75 mm solution (endo -12.173, epi -15.329 mm; 9,957 particles, 235 s),
// measured 0.155 and 0.517 mm, are bounded on both sides. The fibre rule has no circumferential
// direction on the axis, and the axis particles near the apex still carry the largest hourglass
// measure (2.78 against a median of 0.30); the coefficient of the hourglass control moves the
// apex by 0.7 mm between 0.1 and 1 here (problem 2: 5 um), so these are not yet the benchmark's
// answer, only what this scene gives.
TEST(LandVentricleValidation, ActiveContractionRaisesTheApex) {
  // The sanitizer job's reduced run would take 25 small increments at 1 mm (about 5 min, as
  // problem 2's above); its code paths are problem 2's with the fibres and active tension, which
  // the example's smoke run takes through one increment there.
  if (test::reduced_run()) GTEST_SKIP() << "reduced run: problem 3 runs in the release job only";
  const Apex coarse = steady_apex("solid_land_ventricle_active_static.yaml", 1e-3, "p3_1mm");
  std::cout << "problem 3 apex z (mm) at 1 mm: endo " << coarse.endo << " epi " << coarse.epi
            << ", largest hourglass measure " << coarse.hourglass << "\n";
  const double endo_ref = -12.173, epi_ref = -15.329;
  EXPECT_LT(coarse.endo - endo_ref, -0.10);
  EXPECT_GT(coarse.endo - endo_ref, -0.23);
  EXPECT_LT(coarse.epi - epi_ref, -0.34);
  EXPECT_GT(coarse.epi - epi_ref, -0.78);
  EXPECT_LT(coarse.hourglass, 4.2);  // measured 2.78
}

}  // namespace
}  // namespace cosph
