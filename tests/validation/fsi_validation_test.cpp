// The FSI coupler against its references: the rubber gate's free end (Antoci et al. 2007, with
// SPHinXsys's run of the same case as the best reference with numbers: 45.8 mm horizontally,
// 19.6 mm upwards) at fluid spacings 5 and 2.5 mm, converging towards the peer; and the
// hydrostatic plate (Fourey et al. 2017): the coupled, settled mid-span deflection equals the
// deflection of the same plate under the analytic water load rho g H, and both sit above the
// continuum value by what four particles through the thickness (quadratic gradient correction)
// cost in bending
// (bench/studies/fsi_hydrostatic_plate.yaml goes to eight and sixteen).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "../support/probe_csv.hpp"
#include "../support/reduced_run.hpp"
#include "../support/simulation_setup.hpp"

namespace cosph {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string example(const std::string& name) {
  return read_file(std::string(COSPH_SOURCE_DIR) + "/examples/" + name);
}

std::filesystem::path fresh_directory(const std::string& name) {
  const auto dir = std::filesystem::path(testing::TempDir()) / name;
  std::filesystem::remove_all(dir);
  return dir;
}

struct GatePeaks {
  double horizontal = 0.0, vertical = 0.0;  // largest -u_x and u_y of the free end
};

GatePeaks run_gate(double fluid_spacing) {
  RunOptions options;
  options.output_directory = fresh_directory("cosph_gate_" + std::to_string(fluid_spacing));
  auto s = test::make_simulation(example("fsi_elastic_gate.yaml"),
                                 {"modules[0].fluid.body.spacing=" + std::to_string(fluid_spacing),
                                  "output.vtp=false", "checkpoint.at_end=false"},
                                 test::with_step_cap(options));
  s->run();
  if (test::reduced_run()) return {};
  const std::string csv = options.output_directory + "/free_end.csv";
  const auto ux = test::csv_column(csv, 1), uy = test::csv_column(csv, 2);
  return {-*std::min_element(ux.begin(), ux.end()), *std::max_element(uy.begin(), uy.end())};
}

TEST(FsiValidation, ElasticGateFreeEndMatchesThePeer) {
  const double peer_x = 0.0458, peer_y = 0.0196;  // SPHinXsys, fluid 2.5 mm, gate 1.25 mm
  const GatePeaks coarse = run_gate(0.005), fine = run_gate(0.0025);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const double ex_coarse = coarse.horizontal / peer_x - 1, ex_fine = fine.horizontal / peer_x - 1;
  const double ey_coarse = coarse.vertical / peer_y - 1, ey_fine = fine.vertical / peer_y - 1;
  std::cout << "free end, fluid 5 mm: " << coarse.horizontal << " m, " << coarse.vertical
            << " m; fluid 2.5 mm: " << fine.horizontal << " m, " << fine.vertical << " m\n";
  // Measured with the quadratic gradient correction and the water slipping along the tank (the
  // dissipation along its particles' own normals) and along the gate (inviscid, as SPHinXsys's):
  // +0.56% and +0.19% horizontally, +3.9% and +3.7% vertically. With the dissipation along the
  // normal as each fluid particle sees it: -0.90%/-0.35% and +0.97%/+2.4%; with the wall friction
  // of the earlier scheme: +3.1%/+0.015% and +9.6%/+2.7%; with the linear correction, SPHinXsys's,
  // +10.8%/+6.8% and +31.9%/+19.6% (a gate four particles thick too soft in bending). The errors
  // are at the level of the two codes' differences, so each is bounded at 1.5x its size rather
  // than in a converging order.
  EXPECT_LT(std::abs(ex_coarse), 1.5 * 0.0056);
  EXPECT_LT(std::abs(ex_fine), 1.5 * 0.0019);
  EXPECT_LT(std::abs(ey_coarse), 1.5 * 0.039);
  EXPECT_GT(ey_fine, 0.025);
  EXPECT_LT(ey_fine, 1.5 * 0.037);
}

// The plate of the FSI scene alone, under the water's analytic load rho g H on its wetted span
// and damped to rest: what the coupled run must settle to if the coupler hands over the load.
const char* kPlateAlone = R"yaml(
dimension: 2
end_time: 0.3
modules:
  - name: plate
    solid:
      body:
        spacing: 0.0125
        shape: {box: {lower: [-0.15, -0.05], upper: [1.15, 0]}}
      material:
        density: 2700
        st_venant_kirchhoff: {young: 67.5e9, poisson: 0.34}
      gradient_correction: quadratic
      damping: 2000
      pressures:
        - region: {name: wetted, shape: {box: {lower: [0, -0.01], upper: [1, 0.01]}}}
          value: "1000 * 9.81 * 2"
          normal: [0, 1]
      constraints:
        - region: {name: left_clamp, shape: {box: {lower: [-0.16, -0.06], upper: [0, 0.01]}}}
          clamp: true
        - region: {name: right_clamp, shape: {box: {lower: [1, -0.06], upper: [1.16, 0.01]}}}
          clamp: true
probes:
  - name: mid_span
    configuration: reference
    interpolation: linear
    interval: 0.01
    points: {at: [{coordinates: [0.5, -0.025]}], fields: [displacement.y]}
)yaml";

TEST(FsiValidation, HydrostaticPlateSettlesAtTheDeflectionOfItsWaterLoad) {
  // Clamped-clamped plate in plane strain under q = rho g H = 19,620 Pa: Euler-Bernoulli
  // q L^4 / (384 D) = 6.43e-5 m plus shear q L^2 / (8 kappa G h) = 2.34e-6 m.
  const double E = 67.5e9, nu = 0.34, h = 0.05, L = 1.0, q = 1000 * 9.81 * 2.0;
  const double D = E * h * h * h / (12 * (1 - nu * nu)), G = E / (2 * (1 + nu));
  const double analytic = q * std::pow(L, 4) / (384 * D) + q * L * L / (8 * (5.0 / 6) * G * h);

  RunOptions options;
  options.output_directory = fresh_directory("cosph_hydrostatic_plate").string();
  auto coupled = test::make_simulation(example("fsi_hydrostatic_plate.yaml"),
                                       {"output.vtp=false", "checkpoint.at_end=false"},
                                       test::with_step_cap(options));
  coupled->run();
  RunOptions alone_options;
  alone_options.output_directory = fresh_directory("cosph_plate_alone").string();
  auto alone = test::make_simulation(kPlateAlone, {}, test::with_step_cap(alone_options));
  alone->run();
  COSPH_SKIP_CHECKS_IF_REDUCED();
  const std::string csv = options.output_directory + "/mid_span.csv";
  const auto t = test::csv_column(csv, 0), w = test::csv_column(csv, 1);
  // Settled: the last tenth of the run drifts by under 0.038% (measured 0.025%).
  double low = INFINITY, high = -INFINITY, sum = 0.0;
  int n = 0;
  for (std::size_t k = 0; k < t.size(); ++k)
    if (t[k] >= 0.9 * t.back()) {
      low = std::min(low, -w[k]);
      high = std::max(high, -w[k]);
      sum -= w[k];
      ++n;
    }
  const double settled = sum / n;  // the mean over the last tenth
  const double loaded =
      -test::csv_column(alone_options.output_directory + "/mid_span.csv", 1).back();
  std::cout << "mid-span deflection: coupled " << settled << " m (last tenth " << low << " - "
            << high << "), plate under rho g H " << loaded << " m, continuum " << analytic
            << " m\n";
  // Measured: the last tenth spans 0.025%; its mean is 0.060% below the plate under the
  // analytic load (0.99940); 4 layers through the thickness with the quadratic gradient correction
  // bend 18.5% more than the continuum (measured 1.18535; 66% with the linear one).
  EXPECT_LT((high - low) / settled, 1.5 * 2.5e-4);
  EXPECT_NEAR(settled / loaded, 1.0, 1.5 * 6.0e-4);
  EXPECT_GT(settled / analytic, 1.16);
  EXPECT_LT(settled / analytic, 1.22);
}

}  // namespace
}  // namespace cosph
