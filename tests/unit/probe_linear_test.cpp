// Point probes with linear moving-least-squares interpolation (exact for linear fields also at a
// corner, where the Shepard average is biased by the one-sided neighbourhood) and in the
// reference configuration of a moving body (positions from a second vector field); the scene's
// `configuration` and `interpolation` keys reach them.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/particles.hpp"
#include "driver/simulation.hpp"
#include "io/probes.hpp"
#include "io/reductions.hpp"
#include "kernels/kernel.hpp"
#include "module_catalogue.hpp"
#include "neighbour/domain.hpp"

namespace cosph {
namespace {

constexpr double kDx = 0.1;
constexpr int kCells = 12;  // particles at (k + 1/2) dx, k < kCells: the box [0, 1.2]^D

template <int D>
double field(const Vec<D>& x) {
  double f = 2.0 * x[0] + 3.0 * x[1] + 0.5;
  if constexpr (D == 3) f += 1.5 * x[2];
  return f;
}

// A lattice body with "position" (optionally moved by `motion`), "reference_position" (the
// lattice), the scalar "c" = field(reference position) and the vector "u" = (c, -c[, 2c]).
template <int D>
ParticleSet<D> body(double jitter, const Mat<D>& rotation = Mat<D>::Identity(),
                    const Vec<D>& shift = Vec<D>::Zero()) {
  ParticleSet<D> p("block");
  const std::size_t n = D == 2 ? kCells * kCells : kCells * kCells * kCells;
  p.resize(n);
  auto& x = p.add_vector("position");
  auto& X = p.add_vector("reference_position");
  auto& u = p.add_vector("u");
  auto& c = p.add_scalar("c");
  auto& volume = p.add_scalar("volume");
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> noise(-jitter * kDx, jitter * kDx);
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t rest = i;
    for (int a = 0; a < D; ++a) {
      X[i][a] = (static_cast<double>(rest % kCells) + 0.5) * kDx + noise(rng);
      rest /= kCells;
    }
    x[i] = rotation * X[i] + shift;
    c[i] = field<D>(X[i]);
    u[i] = Vec<D>::Constant(c[i]);
    u[i][1] = -c[i];
    volume[i] = std::pow(kDx, D);
  }
  return p;
}

template <int D>
Kernel kernel() {
  return Kernel(KernelType::WendlandC2, D, 1.3 * kDx);
}

template <int D>
void check_corner(double jitter) {
  const ParticleSet<D> p = body<D>(jitter);
  // The box corner, the corner particle's site, and an edge midpoint.
  std::vector<Vec<D>> points = {Vec<D>::Zero(), Vec<D>::Constant(0.5 * kDx),
                                Vec<D>::Constant(kCells * kDx)};
  Vec<D> edge = Vec<D>::Zero();
  edge[0] = 0.5 * kCells * kDx;
  points.push_back(edge);
  const double range = field<D>(Vec<D>::Constant(kCells * kDx)) - field<D>(Vec<D>::Zero());
  const Domain<D> free;
  const PointProbe<D> linear(points, {"c", "u.y"}, {},
                             ProbeOptions{.interpolation = ProbeOptions::Interpolation::linear});
  const PointProbe<D> shepard(points, {"c"});
  const auto exact = linear.sample(p, "volume", kernel<D>(), free);
  const auto average = shepard.sample(p, "volume", kernel<D>(), free);
  const std::size_t np = points.size();
  for (std::size_t k = 0; k < np; ++k) {
    EXPECT_NEAR(exact[k], field<D>(points[k]), 1e-10) << D << "D point " << k;
    EXPECT_NEAR(exact[np + k], -field<D>(points[k]), 1e-10) << D << "D point " << k;
  }
  // At the box corner the average is biased by much more (the test has teeth).
  EXPECT_GT(std::abs(average[0] - field<D>(points[0])), 1e-3 * range) << D << "D";
  std::cout << D << "D jitter " << jitter << ": corner linear error "
            << std::abs(exact[0] - field<D>(points[0])) << ", Shepard error "
            << std::abs(average[0] - field<D>(points[0])) << " (range " << range << ")\n";
}

TEST(PointProbeLinear, ExactForLinearFieldAtCorner2D) {
  check_corner<2>(0.0);
  check_corner<2>(0.2);
}
TEST(PointProbeLinear, ExactForLinearFieldAtCorner3D) {
  check_corner<3>(0.0);
  check_corner<3>(0.2);
}

// A curved field: the quadratic fit reads it exactly wherever the neighbourhood spans three
// layers in every direction (here 1.5 dp inside the faces and deeper), where the linear fit is
// off by its O(h^2) smoothing; at a corner the fit is singular and it falls back to the linear
// one (or, where the fit is just well posed, is exact there too).
template <int D>
double curved(const Vec<D>& x) {
  double f = 1.0 + x[0] - 2.0 * x[1] + 3.0 * x[0] * x[0] - x[0] * x[1] + 2.0 * x[1] * x[1];
  if constexpr (D == 3) f += 0.5 * x[2] - 1.5 * x[2] * x[2] + x[1] * x[2];
  return f;
}

template <int D>
void check_quadratic(double jitter) {
  ParticleSet<D> p = body<D>(jitter);
  auto& c = p.scalar("c");
  const auto& X = p.vector("reference_position");
  for (std::size_t i = 0; i < p.size(); ++i) c[i] = curved<D>(X[i]);
  const std::vector<Vec<D>> points = {Vec<D>::Constant(1.5 * kDx),
                                      Vec<D>::Constant(0.5 * kCells * kDx), Vec<D>::Constant(0.37),
                                      Vec<D>::Zero()};
  const Domain<D> free;
  using I = ProbeOptions::Interpolation;
  const auto quadratic = PointProbe<D>(points, {"c"}, {}, {.interpolation = I::quadratic})
                             .sample(p, "volume", kernel<D>(), free);
  const auto linear = PointProbe<D>(points, {"c"}, {}, {.interpolation = I::linear})
                          .sample(p, "volume", kernel<D>(), free);
  for (std::size_t k = 0; k + 1 < points.size(); ++k) {
    EXPECT_NEAR(quadratic[k], curved<D>(points[k]), 1e-9) << D << "D point " << k;
    // The linear fit is biased by the curvature times the kernel's second moment (~ 0.01 here).
    EXPECT_GT(std::abs(linear[k] - curved<D>(points[k])), 1e-3) << D << "D point " << k;
  }
  const double corner = curved<D>(points.back());
  EXPECT_TRUE(quadratic.back() == linear.back() || std::abs(quadratic.back() - corner) < 1e-9)
      << D << "D corner: " << quadratic.back() << " against " << corner;
}

TEST(PointProbeQuadratic, ExactForQuadraticFieldAtCornerEdgeAndInside) {
  check_quadratic<2>(0.0);
  check_quadratic<2>(0.2);
  check_quadratic<3>(0.0);
  check_quadratic<3>(0.2);
}

TEST(PointProbeLinear, SamplesAtReferencePositions) {
  // The body is turned by 30 degrees and moved; the points are material points of the reference.
  const double a = 30.0 * 3.14159265358979323846 / 180.0;
  Mat<2> R;
  R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
  const ParticleSet<2> p = body<2>(0.1, R, Vec<2>(0.4, -0.1));
  const std::vector<Vec<2>> points = {Vec<2>(0.6, 0.6), Vec<2>(0.0, 0.0), Vec<2>(1.2, 0.3)};
  const Domain<2> free;
  for (bool linear : {false, true}) {
    const PointProbe<2> reference(points, {"c"}, {},
                                  {.position_field = "reference_position",
                                   .interpolation = linear ? ProbeOptions::Interpolation::linear
                                                           : ProbeOptions::Interpolation::shepard});
    const PointProbe<2> current(points, {"c"}, {},
                                {.interpolation = linear ? ProbeOptions::Interpolation::linear
                                                         : ProbeOptions::Interpolation::shepard});
    const auto at_reference = reference.sample(p, "volume", kernel<2>(), free);
    const auto at_current = current.sample(p, "volume", kernel<2>(), free);
    // The interior point: close for the average (jittered lattice), exact for the linear fit.
    EXPECT_NEAR(at_reference[0], field<2>(points[0]), linear ? 1e-10 : 0.05);
    for (std::size_t k = 0; linear && k < points.size(); ++k)
      EXPECT_NEAR(at_reference[k], field<2>(points[k]), 1e-10) << "point " << k;
    // In the current configuration the same point is another material point (or none).
    EXPECT_FALSE(std::abs(at_current[0] - field<2>(points[0])) < 0.1) << at_current[0];
  }
  // A position field that does not exist is named.
  const PointProbe<2> missing(points, {"c"}, {}, {.position_field = "initial_position"});
  try {
    missing.sample(p, "volume", kernel<2>(), free);
    ADD_FAILURE() << "missing position field accepted";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("initial_position"), std::string::npos) << e.what();
  }
}

// Through a scene: a 2D solid block translating at unit speed; the probe at the reference corner
// (configuration: reference, interpolation: linear) reads the displacement t, exactly.
TEST(PointProbeLinear, SceneKeysReachTheProbe) {
  const char* const text = R"yaml(
dimension: 2
end_time: 0.5
modules:
  - name: block
    solid:
      body:
        spacing: 0.1
        shape: {box: {lower: [0, 0], upper: [1, 0.6]}}
      material:
        density: 1000
        neo_hookean: {young: 1.0e5, poisson: 0.3}
      initial_velocity: ["1", "0.5"]
probes:
  - name: corner
    configuration: reference
    interpolation: linear
    points: {at: [[0, 0], [1, 0.6]], fields: [displacement.x, displacement.y]}
)yaml";
  RunOptions options;
  options.bench = true;
  options.progress = false;
  Simulation simulation(load_scene_text(text, "probe.yaml"), builtin_modules(), options);
  simulation.initialize();
  const RunSummary summary = simulation.run();
  const auto& values = summary.probes.at("corner");
  ASSERT_EQ(values.size(), 4u);
  for (const auto& [column, value] : values) {
    const double expected = column.rfind("displacement.x", 0) == 0 ? 0.5 : 0.25;
    EXPECT_NEAR(value, expected, 1e-10) << column;
  }
  // A body that does not move has no reference configuration.
  const char* const still = R"yaml(
dimension: 2
end_time: 0.1
modules:
  - name: sheet
    diffusion:
      body:
        spacing: 0.1
        shape: {box: {lower: [0, 0], upper: [1, 1]}}
      diffusivity: 1.0e-3
probes:
  - name: p
    configuration: reference
    points: {at: [[0.5, 0.5]], fields: [concentration]}
)yaml";
  try {
    Simulation s(load_scene_text(still, "still.yaml"), builtin_modules(), options);
    s.initialize();
    ADD_FAILURE() << "reference configuration accepted on a static body";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("probes[0].configuration"), std::string::npos) << e.what();
  }
}

// Wave gauge: the top of the continuous water column under the gauge, where the kernel-summed
// volume fraction falls to 1/2; a drop above the column does not count; the base when dry.
TEST(SurfaceHeight, GaugeReadsTheTopOfTheWaterColumnUnderIt) {
  const double dp = 0.05;
  const Kernel kernel(KernelType::WendlandC2, 2, 1.3 * dp);
  auto block = [&](double height, bool drop) {
    ParticleSet<2> water("water");
    std::vector<Vec<2>> x;
    for (int i = 0; i < 40; ++i)
      for (int j = 0; (j + 0.5) * dp < height; ++j)
        x.push_back(Vec<2>((i + 0.5) * dp, (j + 0.5) * dp));
    if (drop) x.push_back(Vec<2>(1.0 + 0.5 * dp, height + 0.5));  // a lone drop 0.5 above
    water.resize(x.size());
    water.add_vector("position") = x;
    water.add_scalar("volume").assign(x.size(), dp * dp);
    return water;
  };
  for (double height : {1.0, 0.6}) {
    const ParticleSet<2> water = block(height, false);
    const double level = surface_height<2>(water, kernel, Vec<2>(1.0, 0.0), 1);
    std::cout << "column " << height << ": gauge reads " << level << "\n";
    EXPECT_NEAR(level, height, 0.25 * dp);
    EXPECT_NEAR(surface_height<2>(block(height, true), kernel, Vec<2>(1.0, 0.0), 1), level, 1e-12);
  }
  // Dry: beyond the water, and a gauge whose base is given at y = -0.3.
  EXPECT_EQ(surface_height<2>(block(1.0, false), kernel, Vec<2>(3.0, 0.0), 1), 0.0);
  EXPECT_EQ(surface_height<2>(block(1.0, false), kernel, Vec<2>(3.0, -0.3), 1), -0.3);
}

}  // namespace
}  // namespace cosph
