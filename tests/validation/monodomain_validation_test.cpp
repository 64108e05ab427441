// Monodomain against independent finite-difference references (bench/reference/monodomain_fd.py):
// the plane-wave conduction velocity and the Ratti-Verani propagation upstroke, each at two
// resolutions with the direction of convergence checked; the 3D slab against the 2D strip.
#include <gtest/gtest.h>

#include <cmath>

#include "../support/reduced_run.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

std::string example(const std::string& name) {
  return std::string(COSPH_SOURCE_DIR) + "/examples/" + name;
}

std::map<std::string, double> final_probe(const std::string& scene,
                                          const std::vector<std::string>& overrides,
                                          const std::string& probe) {
  RunOptions options;
  options.bench = true;
  options.progress = false;
  Simulation simulation(load_scene_file(scene, overrides), builtin_modules(),
                        test::with_step_cap(options));
  simulation.initialize();
  return simulation.run().probes.at(probe);
}

double conduction_velocity(double spacing) {
  auto p =
      final_probe(example("monodomain_conduction_velocity.yaml"),
                  {"modules[0].monodomain.body.spacing=" + std::to_string(spacing)}, "activation");
  return 2.0 / (p.at("activation_time@p1") - p.at("activation_time@p0"));
}

TEST(MonodomainValidation, ConductionVelocityMatchesTravellingFrontAndConverges) {
  const double coarse = conduction_velocity(0.05), fine = conduction_velocity(0.025);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout.precision(9);
  std::cout << "conduction velocity: dp 0.05 " << coarse << ", dp 0.025 " << fine
            << " (front 1.4)\n";
  // Against the finite-difference plane wave (bench/reference/monodomain_cv_fd.csv, Richardson
  // extrapolated: 1.39406197, uncertainty 1.3e-6), not the bistable front's 1.4 (the gate w
  // slows the wave by 0.4%). Measured: 1.39391104 (1.51e-4 low) and 1.39404866 (1.33e-5 low).
  constexpr double reference = 1.39406197;
  EXPECT_LT(coarse, reference);
  EXPECT_GT(coarse, reference - 2.3e-4);
  EXPECT_LT(fine, reference);
  EXPECT_GT(fine, reference - 2.0e-5);
  EXPECT_GT(fine, coarse);  // converges from below
}

// Anisotropy: D = d I + d_f f f^T with d = 1, d_f = 3. A plane wave along x (periodic in y) feels
// only D_xx, so with the fibres along x it must travel as in isotropic tissue with D = 4, across
// them as with D = 1, and with the fibres at 45 degrees as with D = 2.5 (the off-diagonal D_xy
// acts on y-derivatives, zero for a plane wave). At dp 0.05, measured relative differences
// +2.13e-5 (along), -1.39e-5 (across), -3.1e-6 (45 degrees): the discrete anisotropic operator
// differs from the isotropic one only near the strip's ends. (CV along / across is 1.959, not
// sqrt(4) = 2: the wider D = 4 front has not reached its steady speed between x = 3 and 5.)
TEST(MonodomainValidation, AnisotropicConductionFollowsTheFibres) {
  auto cv = [](const std::vector<std::string>& extra) {
    std::vector<std::string> overrides = {"modules[0].monodomain.body.spacing=0.05"};
    overrides.insert(overrides.end(), extra.begin(), extra.end());
    auto p = final_probe(example("monodomain_conduction_velocity.yaml"), overrides, "activation");
    return 2.0 / (p.at("activation_time@p1") - p.at("activation_time@p0"));
  };
  const std::vector<std::string> fibres = {"modules[0].monodomain.fibre_diffusivity=3"};
  auto with = [&](const std::string& fibre) {
    std::vector<std::string> o = fibres;
    o.push_back("modules[0].monodomain.fibre=" + fibre);
    return cv(o);
  };
  const double along = with("[1, 0]"), across = with("[0, 1]"), diagonal = with("[1, 1]");
  const double iso4 = cv({"modules[0].monodomain.diffusivity=4"}), iso1 = cv({}),
               iso25 = cv({"modules[0].monodomain.diffusivity=2.5"});
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout.precision(9);
  std::cout << "CV along " << along << " (isotropic D = 4: " << iso4 << "), across " << across
            << " (D = 1: " << iso1 << "), 45 degrees " << diagonal << " (D = 2.5: " << iso25
            << ")\n";
  EXPECT_NEAR(along / iso4, 1.0, 3.2e-5);
  EXPECT_NEAR(across / iso1, 1.0, 2.1e-5);
  EXPECT_NEAR(diagonal / iso25, 1.0, 4.7e-6);
}

TEST(MonodomainValidation, PropagationUpstrokeAtTwoResolutions) {
  auto upstroke = [](double spacing) {
    auto p = final_probe(example("monodomain_propagation.yaml"),
                         {"modules[0].monodomain.body.spacing=" + std::to_string(spacing),
                          "end_time=3", "probes[0].points.fields=[activation_time]"},
                         "voltage");
    return p.at("activation_time@p0");
  };
  const double coarse = upstroke(0.05), fine = upstroke(0.025);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout.precision(9);
  std::cout << "upstroke time at (0.3, 0.7): dp 0.05 " << coarse << ", dp 0.025 " << fine << "\n";
  // Against the finite-difference upstroke at (0.3, 0.7) (bench/reference/
  // monodomain_propagation_fd.csv: 1.17696 extrapolated, dx = 0.01 within 4.8e-6 of it).
  // Measured: 1.17749421 (5.34e-4 late) and 1.17707486 (1.15e-4 late).
  constexpr double reference = 1.17696;
  EXPECT_GT(coarse, reference);
  EXPECT_LT(coarse, reference + 8.0e-4);
  EXPECT_GT(fine, reference);
  EXPECT_LT(fine, reference + 1.7e-4);
  EXPECT_LT(fine, coarse);  // converges from above
}

}  // namespace
}  // namespace cosph

namespace cosph {
namespace {

// The 3D path: a plane wave in a slab periodic across both transverse axes travels like the same
// wave in a 2D strip (its speed does not depend on the dimension).
TEST(MonodomainValidation, PlaneWaveIn3DSlabMatchesTheSame2DStrip) {
  auto cv = [](int dimension) {
    const std::string d3 = dimension == 3 ? ", 0.4" : "";
    const std::string p3 = dimension == 3 ? ", true" : "";
    const std::string z3 = dimension == 3 ? ", 0.2" : "";
    const std::string text = "dimension: " + std::to_string(dimension) +
                             "\nend_time: 3.0\n"
                             "domain: {lower: [0, 0" +
                             std::string(dimension == 3 ? ", 0" : "") + "], upper: [4, 0.4" + d3 +
                             "], periodic: [false, true" + p3 +
                             "]}\n"
                             "modules:\n"
                             "  - name: slab\n"
                             "    monodomain:\n"
                             "      body:\n"
                             "        spacing: 0.05\n"
                             "        shape: {box: {lower: [0, 0" +
                             std::string(dimension == 3 ? ", 0" : "") + "], upper: [4, 0.4" + d3 +
                             "]}}\n"
                             "      diffusivity: 1.0\n"
                             "      ionic_model: {preset: aliev_panfilov_table1}\n"
                             "      stimuli:\n"
                             "        - region: {name: end, shape: {box: {lower: [0, 0" +
                             std::string(dimension == 3 ? ", 0" : "") + "], upper: [0.2, 0.4" + d3 +
                             "]}}}\n"
                             "          duration: 0.5\n"
                             "probes:\n"
                             "  - name: activation\n"
                             "    points: {at: [[1.0, 0.2" +
                             z3 + "], [3.0, 0.2" + z3 + "]], fields: [activation_time]}\n";
    RunOptions options;
    options.bench = true;
    options.progress = false;
    Simulation simulation(load_scene_text(text, "slab.yaml"), builtin_modules(),
                          test::with_step_cap(options));
    simulation.initialize();
    const auto p = simulation.run().probes.at("activation");
    return 2.0 / (p.at("activation_time@p1") - p.at("activation_time@p0"));
  };
  const double two = cv(2), three = cv(3);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  std::cout.precision(9);
  std::cout << "plane wave speed, 2D strip " << two << ", 3D slab " << three << "\n";
  // Measured: 1.37318407 (2D) and 1.37317752 (3D), 4.8e-6 apart relative.
  EXPECT_NEAR(three, two, 7.0e-6 * two);
  // The same strip by 1D finite differences (bench/reference/monodomain_fd.py's
  // conduction_velocity with CV_LENGTH = 4, CV_POINTS = (1, 3)): 1.3721716, 1.3719712 and
  // 1.3718536 at dx = 0.02, 0.01, 0.005, extrapolated 1.371815 at second order. Their
  // differences (2.00e-4, 1.18e-4) show order 0.77, which extrapolates to 1.371686 instead: the
  // reference is uncertain by 1.3e-4, a tenth of the measured 1.37e-3 above it (1.50e-3 above
  // the order-0.77 value; the upper bound is 1.46x and 1.33x of them).
  EXPECT_GT(two, 1.371815);
  EXPECT_LT(two, 1.371815 + 2.0e-3);
}

}  // namespace
}  // namespace cosph
