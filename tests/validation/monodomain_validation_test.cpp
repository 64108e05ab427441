// Monodomain against references: the plane-wave conduction velocity against the travelling front
// of the bistable reaction (c = sqrt(2 D k)(1/2 - a) = 1.4), converging with resolution; the
// Ratti-Verani propagation upstroke at two resolutions.
#include <gtest/gtest.h>

#include <cmath>

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
  Simulation simulation(load_scene_file(scene, overrides), builtin_modules(), options);
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
  std::cout << "conduction velocity: dp 0.05 " << coarse << ", dp 0.025 " << fine
            << " (front 1.4)\n";
  EXPECT_NEAR(fine, 1.4, 0.01);  // measured 1.3941; the gate w slows the front slightly
  EXPECT_NEAR(coarse, fine, 0.002);
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
  std::cout << "upstroke time at (0.3, 0.7): dp 0.05 " << coarse << ", dp 0.025 " << fine << "\n";
  EXPECT_GT(fine, 0.5);
  EXPECT_LT(fine, 2.0);
  EXPECT_NEAR(coarse, fine, 0.02 * fine);
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
    Simulation simulation(load_scene_text(text, "slab.yaml"), builtin_modules(), options);
    simulation.initialize();
    const auto p = simulation.run().probes.at("activation");
    return 2.0 / (p.at("activation_time@p1") - p.at("activation_time@p0"));
  };
  const double two = cv(2), three = cv(3);
  std::cout << "plane wave speed, 2D strip " << two << ", 3D slab " << three << "\n";
  EXPECT_NEAR(three, two, 0.005 * two);
  EXPECT_NEAR(two, 1.37, 0.02);  // 1.373 between x = 1 and 3 in a 4-long strip (see the example)
}

}  // namespace
}  // namespace cosph
