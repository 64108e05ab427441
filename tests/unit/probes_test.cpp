// Point probes, whole-body reductions and the CSV time series.
#include "io/probes.hpp"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/particles.hpp"
#include "io/csv_time_series.hpp"
#include "io/reductions.hpp"
#include "io/text_format.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/domain.hpp"

namespace cosph {
namespace {

namespace fs = std::filesystem;

constexpr double kDx = 0.1;
constexpr int kCells = 20;  // lattice of kCells^D particles filling [0, kCells * kDx)^D

// The linear test field f = 2x + 3y (+ z).
template <int D>
double linear(const Vec<D>& x) {
  double f = 2.0 * x[0] + 3.0 * x[1];
  if constexpr (D == 3) f += x[2];
  return f;
}

// Reproducible pseudo-random numbers in [-1, 1) (splitmix64), independent of the standard
// library's distributions.
double noise(std::uint64_t k) {
  std::uint64_t z = k * 0x9e3779b97f4a7c15ull + 0x632be59bd9b4e019ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * 0x1.0p-52 - 1.0;
}

// Particles at the cell centres (i + 1/2) dx of a uniform lattice, each moved by up to
// `perturbation` * dx per axis, with the linear field "c", the vector field "u" = (x, -y[, z])
// and volumes dx^D.
template <int D>
ParticleSet<D> lattice(double perturbation = 0.0) {
  ParticleSet<D> body("fluid");
  std::size_t n = 1;
  for (int a = 0; a < D; ++a) n *= kCells;
  body.resize(n);
  body.add_vector("position");
  body.add_vector("u");
  body.add_scalar("c");
  body.add_scalar("volume");
  auto& x = body.vector("position");
  auto& u = body.vector("u");
  auto& c = body.scalar("c");
  auto& volume = body.scalar("volume");
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t rest = i;
    for (int a = 0; a < D; ++a) {
      const double cell = static_cast<double>(rest % kCells);
      rest /= kCells;
      x[i][a] = (cell + 0.5 + perturbation * noise(D * i + a)) * kDx;
    }
    u[i] = x[i];
    u[i][1] = -x[i][1];
    c[i] = linear<D>(x[i]);
    volume[i] = std::pow(kDx, D);
  }
  return body;
}

// Straightforward O(N) Shepard interpolation over all particles, the reference for the probe's
// neighbour-search version.
template <int D>
double brute_force(const ParticleSet<D>& body, const std::vector<double>& f, const Vec<D>& point,
                   const Kernel& kernel, const Domain<D>& domain) {
  double num = 0.0, den = 0.0;
  const auto& x = body.vector("position");
  const auto& volume = body.scalar("volume");
  for (std::size_t j = 0; j < body.size(); ++j) {
    const double w = volume[j] * kernel.value(domain.displacement(point, x[j]).norm());
    num += w * f[j];
    den += w;
  }
  return den > 0.0 ? num / den : std::numeric_limits<double>::quiet_NaN();
}

template <int D>
Kernel test_kernel() {
  return Kernel(KernelType::WendlandC2, D, 1.3 * kDx);  // support 2.6 dx: ~21 (2D) neighbours
}

// Interior points (more than a support away from the lattice's edges) where the lattice around
// the point is mirror-symmetric on every axis: lattice sites, midpoints between two sites and
// cell corners. There sum_j w_j (x_j - x) = 0, so Shepard interpolation of a linear field is
// exact up to round-off.
template <int D>
std::vector<Vec<D>> symmetric_points() {
  std::vector<Vec<D>> points;
  // Sites are at (k + 1/2) dx on every axis, midpoints at k dx.
  for (double offset : {0.5, 1.0}) {
    for (double base : {6.0, 10.0, 13.0}) {
      Vec<D> p = Vec<D>::Constant((base + offset) * kDx);
      points.push_back(p);
      p[0] = (base + 0.5) * kDx;  // mixed: a site along x, midway along y
      p[1] = (base + 1.0) * kDx;
      points.push_back(p);
    }
  }
  return points;
}

template <int D>
void check_linear_exact() {
  const ParticleSet<D> body = lattice<D>();
  const Kernel kernel = test_kernel<D>();
  const Domain<D> open;
  const auto points = symmetric_points<D>();
  const PointProbe<D> probe(points, {"c", "u.y"});
  const auto values = probe.sample(body, "volume", kernel, open);
  ASSERT_EQ(values.size(), 2 * points.size());
  for (std::size_t p = 0; p < points.size(); ++p) {
    EXPECT_NEAR(values[p], linear<D>(points[p]), 1e-12) << "point " << p;
    EXPECT_NEAR(values[points.size() + p], -points[p][1], 1e-12) << "point " << p;
  }
}

TEST(PointProbe, LinearFieldExactOnSymmetricLatticePoints2D) { check_linear_exact<2>(); }
TEST(PointProbe, LinearFieldExactOnSymmetricLatticePoints3D) { check_linear_exact<3>(); }

// On a lattice whose particles are moved randomly by up to 0.1 dx per axis the neighbourhood is
// no longer symmetric and Shepard interpolation of a linear field is only first-order accurate:
// the error is grad f . (xbar - x), with xbar = sum_j w_j x_j / sum_j w_j the weighted mean
// neighbour position. The perturbations shift xbar by at most 0.1 dx per axis directly, plus
// an indirect shift through the changed weights; the largest error measured here is
// 0.034 |grad f|_1 dx (2D) and 0.021 |grad f|_1 dx (3D). The tolerance 0.1 |grad f|_1 dx (the
// direct shift's bound) leaves a margin of three; a broken normalisation or kernel argument
// gives errors of order |grad f| h or more. That no neighbour is missed or doubled is checked
// separately against the brute-force sum, to round-off.
template <int D>
void check_linear_perturbed() {
  const ParticleSet<D> body = lattice<D>(0.1);
  const Kernel kernel = test_kernel<D>();
  const Domain<D> open;
  std::vector<Vec<D>> points;
  for (int k = 0; k < 20; ++k) {
    Vec<D> p;
    for (int a = 0; a < D; ++a) p[a] = (6.0 + 8.0 * (0.5 + 0.5 * noise(1000 + D * k + a))) * kDx;
    points.push_back(p);
  }
  const PointProbe<D> probe(points, {"c"});
  const auto values = probe.sample(body, "volume", kernel, open);
  const double gradient_l1 = D == 3 ? 6.0 : 5.0;
  for (std::size_t p = 0; p < points.size(); ++p) {
    EXPECT_NEAR(values[p], brute_force(body, body.scalar("c"), points[p], kernel, open), 1e-12);
    EXPECT_NEAR(values[p], linear<D>(points[p]), gradient_l1 * 0.1 * kDx) << "point " << p;
  }
}

TEST(PointProbe, LinearFieldApproximateOnPerturbedLattice2D) { check_linear_perturbed<2>(); }
TEST(PointProbe, LinearFieldApproximateOnPerturbedLattice3D) { check_linear_perturbed<3>(); }

TEST(PointProbe, ColumnsNameFieldThenPoint) {
  const PointProbe<2> unnamed({Vec<2>(0, 0), Vec<2>(1, 1)}, {"c", "u.x"});
  EXPECT_EQ(unnamed.columns(), (std::vector<std::string>{"c@p0", "c@p1", "u.x@p0", "u.x@p1"}));
  const PointProbe<2> named({Vec<2>(0, 0), Vec<2>(1, 1)}, {"p"}, {"inlet", "outlet"});
  EXPECT_EQ(named.columns(), (std::vector<std::string>{"p@inlet", "p@outlet"}));
  EXPECT_THROW(PointProbe<2>({Vec<2>(0, 0)}, {"p"}, {"a", "b"}), std::invalid_argument);
}

TEST(PointProbe, PointWithoutNeighboursIsNaN) {
  const ParticleSet<2> body = lattice<2>();
  const Kernel kernel = test_kernel<2>();
  const double support = kernel.support_radius();
  const double edge = kCells * kDx;
  const std::vector<Vec<2>> points = {
      Vec<2>(100.0, 100.0), Vec<2>(1e15, -1e15),       // far beyond any cell index
      Vec<2>(edge + support, 1.0),                     // just out of reach
      Vec<2>(0.5 * kDx - support * 0.99, 10.5 * kDx),  // just within reach, outside
      Vec<2>(std::numeric_limits<double>::quiet_NaN(), 1.0)};
  const auto values = PointProbe<2>(points, {"c"}).sample(body, "volume", kernel, Domain<2>{});
  EXPECT_TRUE(std::isnan(values[0]));
  EXPECT_TRUE(std::isnan(values[1]));
  EXPECT_TRUE(std::isnan(values[2]));
  EXPECT_FALSE(std::isnan(values[3])) << "a point outside the lattice but within the support";
  EXPECT_NEAR(values[3], brute_force(body, body.scalar("c"), points[3], kernel, Domain<2>{}),
              1e-12);
  EXPECT_TRUE(std::isnan(values[4]));

  ParticleSet<2> empty("empty");
  empty.add_vector("position");
  empty.add_scalar("c");
  empty.add_scalar("volume");
  EXPECT_TRUE(std::isnan(
      PointProbe<2>({Vec<2>(0, 0)}, {"c"}).sample(empty, "volume", kernel, Domain<2>{})[0]));
}

// A field that is 1 on the upper half of x and 0 on the lower: at x = 0 on a periodic axis the
// probe sees as many particles of each kind, mirror-symmetric, and returns 1/2; without the
// periodic images it would see only zeros.
TEST(PointProbe, PeriodicDomainSeesAcrossTheBoundary) {
  ParticleSet<2> body = lattice<2>();
  const double length = kCells * kDx;
  body.add_scalar("upper");
  auto& upper = body.scalar("upper");
  const auto& x = body.vector("position");
  for (std::size_t i = 0; i < body.size(); ++i) upper[i] = x[i][0] > 0.5 * length ? 1.0 : 0.0;
  Domain<2> domain;
  domain.lower = Vec<2>(0.0, 0.0);
  domain.upper = Vec<2>(length, length);
  domain.periodic = {true, false};
  const Kernel kernel = test_kernel<2>();
  const std::vector<Vec<2>> points = {
      Vec<2>(0.0, 10.5 * kDx), Vec<2>(length, 10.5 * kDx),  // both the boundary
      Vec<2>(0.25 * kDx, 7 * kDx), Vec<2>(-0.25 * kDx, 7 * kDx),
      Vec<2>(length - 0.25 * kDx, 7 * kDx)};  // == the previous one, wrapped
  const auto values = PointProbe<2>(points, {"upper", "c"}).sample(body, "volume", kernel, domain);
  const std::size_t n = points.size();
  EXPECT_NEAR(values[0], 0.5, 1e-12);
  EXPECT_NEAR(values[1], 0.5, 1e-12);
  EXPECT_GT(values[2], 0.0);
  EXPECT_LT(values[2], 0.5);
  EXPECT_EQ(values[3], values[4]) << "a point outside the domain is wrapped into it";
  // The reference sums over all particles with the domain's minimum-image displacement.
  for (std::size_t p = 0; p < n; ++p)
    EXPECT_NEAR(values[p], brute_force(body, upper, points[p], kernel, domain), 1e-12) << p;
  for (std::size_t p = 0; p < n; ++p)
    EXPECT_NEAR(values[n + p], brute_force(body, body.scalar("c"), points[p], kernel, domain),
                1e-12)
        << p;
  const auto open =
      PointProbe<2>({points[0]}, {"upper"}).sample(body, "volume", kernel, Domain<2>{});
  EXPECT_EQ(open[0], 0.0) << "without periodicity only the lower half is within reach";
}

TEST(PointProbe, VolumesFromSpanOrField) {
  const ParticleSet<2> body = lattice<2>(0.1);
  const Kernel kernel = test_kernel<2>();
  const PointProbe<2> probe({Vec<2>(1.0, 1.0)}, {"c"});
  std::vector<double> volumes = body.scalar("volume");
  EXPECT_EQ(probe.sample(body, volumes, kernel, Domain<2>{}),
            probe.sample(body, "volume", kernel, Domain<2>{}));
  // Weights scale with the volumes: a non-uniform choice changes the value.
  for (std::size_t i = 0; i < volumes.size(); ++i) volumes[i] *= 1.0 + (i % 7);
  const double weighted = probe.sample(body, volumes, kernel, Domain<2>{})[0];
  EXPECT_NE(weighted, probe.sample(body, "volume", kernel, Domain<2>{})[0]);
  volumes.pop_back();
  EXPECT_THROW(probe.sample(body, volumes, kernel, Domain<2>{}), std::invalid_argument);
}

template <typename F>
std::string runtime_error_message(const F& f) {
  try {
    f();
  } catch (const RuntimeError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected RuntimeError";
  return {};
}

TEST(PointProbe, BadFieldsAndKernelAreReported) {
  const ParticleSet<2> body = lattice<2>();
  const Kernel kernel = test_kernel<2>();
  const Domain<2> open;
  const auto sample = [&](const std::string& field) {
    return PointProbe<2>({Vec<2>(1, 1)}, {field}).sample(body, "volume", kernel, open);
  };
  const std::string missing = runtime_error_message([&] { sample("pressure"); });
  EXPECT_NE(missing.find("fluid"), std::string::npos) << missing;
  EXPECT_NE(missing.find("pressure"), std::string::npos) << missing;
  EXPECT_NE(runtime_error_message([&] { sample("u.z"); }).find("2D"), std::string::npos);
  EXPECT_NE(runtime_error_message([&] { sample("w.x"); }).find("'w'"), std::string::npos);
  runtime_error_message([&] { sample("u"); });  // a whole vector is not a scalar
  EXPECT_NE(runtime_error_message([&] {
              PointProbe<2>({Vec<2>(1, 1)}, {"c"}).sample(body, "mass", kernel, open);
            }).find("mass"),
            std::string::npos);
  EXPECT_THROW(PointProbe<2>({Vec<2>(1, 1)}, {"c"})
                   .sample(body, "volume", Kernel(KernelType::WendlandC2, 3, 0.1), open),
               std::invalid_argument);
}

// A body whose sums depend on the order of addition: magnitudes spread over 30 decades with
// random signs, so any change of block boundaries or combination order shows in the last bits.
template <int D>
ParticleSet<D> ill_conditioned(std::size_t n) {
  ParticleSet<D> body("cloud");
  body.resize(n);
  body.add_vector("position");
  body.add_vector("velocity");
  body.add_vector("force");
  body.add_scalar("mass");
  body.add_scalar("volume");
  body.add_scalar("c");
  auto& x = body.vector("position");
  auto& v = body.vector("velocity");
  auto& force = body.vector("force");
  auto& m = body.scalar("mass");
  auto& volume = body.scalar("volume");
  auto& c = body.scalar("c");
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = [&](int k) { return noise(7 * i + k); };
    for (int a = 0; a < D; ++a) {
      x[i][a] = r(a);
      v[i][a] = r(3 + a) * std::pow(10.0, 8 * r(4 + a));
      force[i][a] = r(5 + a) * std::pow(10.0, 15 * r(6 + a));
    }
    m[i] = std::pow(10.0, 5 * r(1));
    volume[i] = std::pow(10.0, 3 * r(2));
    c[i] = r(6) * std::pow(10.0, 15 * r(0));
  }
  return body;
}

struct Sums {
  double kinetic, integral, total_mass;
  Vec<3> total;
  std::vector<double> probe;
};

template <int D>
Sums sums_with_threads(const ParticleSet<D>& body, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
  Sums s;
  s.kinetic = total_kinetic_energy(body);
  s.integral = integral(body, "c");
  s.total_mass = total_scalar(body, "mass");
  s.total = Vec<3>::Zero();
  s.total.head<D>() = total_vector(body, "force");
  std::vector<Vec<D>> points;
  for (int k = 0; k < 300; ++k) points.push_back(Vec<D>::Constant(-0.9 + 0.006 * k));
  s.probe = PointProbe<D>(points, {"c"})
                .sample(body, "volume", Kernel(KernelType::WendlandC2, D, 0.02), Domain<D>{});
  return s;
}

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

template <int D>
void check_thread_independence() {
  const ParticleSet<D> body = ill_conditioned<D>(200000);
  const Sums one = sums_with_threads(body, 1);
  const Sums two = sums_with_threads(body, 2);
  EXPECT_TRUE(same_bits(one.kinetic, two.kinetic));
  EXPECT_TRUE(same_bits(one.integral, two.integral));
  EXPECT_TRUE(same_bits(one.total_mass, two.total_mass));
  for (int a = 0; a < 3; ++a) EXPECT_TRUE(same_bits(one.total[a], two.total[a])) << a;
  ASSERT_EQ(one.probe.size(), two.probe.size());
  for (std::size_t p = 0; p < one.probe.size(); ++p)
    EXPECT_TRUE(same_bits(one.probe[p], two.probe[p])) << p;
}

TEST(Reductions, BitIdenticalWithOneAndTwoThreads2D) { check_thread_independence<2>(); }
TEST(Reductions, BitIdenticalWithOneAndTwoThreads3D) { check_thread_independence<3>(); }

template <int D>
ParticleSet<D> three_particles() {
  ParticleSet<D> body("block");
  body.resize(3);
  body.add_vector("position");
  body.add_vector("velocity");
  body.add_vector("force");
  body.add_scalar("mass");
  body.add_scalar("volume");
  body.add_scalar("c");
  auto& x = body.vector("position");
  auto& v = body.vector("velocity");
  auto& force = body.vector("force");
  x[0][0] = -1.0;
  x[1][0] = 2.0;
  x[2][0] = 0.5;
  x[0][1] = 4.0;
  x[1][1] = 4.5;
  x[2][1] = 3.0;
  v[0][0] = 1.0;
  v[1][1] = 2.0;
  v[2][0] = 1.0;
  v[2][1] = 1.0;
  force[0][0] = 1.5;
  force[1][0] = -0.5;
  force[2][1] = 2.0;
  if constexpr (D == 3) {
    x[0][2] = 7.0;  // extent along z stays 0
    x[1][2] = 7.0;
    x[2][2] = 7.0;
    v[1][2] = 3.0;
    force[2][2] = -4.0;
  }
  body.scalar("mass") = {1.0, 2.0, 3.0};
  body.scalar("volume") = {0.5, 0.25, 2.0};
  body.scalar("c") = {2.0, 4.0, 1.0};
  return body;
}

TEST(Reductions, HandComputedValues2D) {
  const ParticleSet<2> body = three_particles<2>();
  // 0.5 (1 * 1 + 2 * 4 + 3 * 2)
  EXPECT_DOUBLE_EQ(total_kinetic_energy(body), 7.5);
  EXPECT_DOUBLE_EQ(extent(body, 0), 3.0);
  EXPECT_DOUBLE_EQ(extent(body, 1), 1.5);
  EXPECT_EQ(total_vector(body, "force"), Vec<2>(1.0, 2.0));
  EXPECT_DOUBLE_EQ(total_scalar(body, "mass"), 6.0);
  EXPECT_DOUBLE_EQ(integral(body, "c"), 0.5 * 2.0 + 0.25 * 4.0 + 2.0 * 1.0);
  EXPECT_THROW(extent(body, 2), std::invalid_argument);
  EXPECT_THROW(extent(body, -1), std::invalid_argument);
  // The leading edge: the largest x + V^(1/2) / 2, here particle 1's 2 + 0.25 (particle 2,
  // 0.5 + 0.707, is behind it); along y, 4.5 + 0.25.
  EXPECT_DOUBLE_EQ(front(body, 0), 2.25);
  EXPECT_DOUBLE_EQ(front(body, 1), 4.75);
  EXPECT_THROW(front(body, 2), std::invalid_argument);
}

TEST(Reductions, HandComputedValues3D) {
  const ParticleSet<3> body = three_particles<3>();
  // 0.5 (1 * 1 + 2 * (4 + 9) + 3 * 2)
  EXPECT_DOUBLE_EQ(total_kinetic_energy(body), 16.5);
  EXPECT_DOUBLE_EQ(extent(body, 0), 3.0);
  EXPECT_DOUBLE_EQ(extent(body, 1), 1.5);
  EXPECT_DOUBLE_EQ(extent(body, 2), 0.0);
  EXPECT_EQ(total_vector(body, "force"), Vec<3>(1.0, 2.0, -4.0));
  EXPECT_DOUBLE_EQ(integral(body, "c"), 4.0);
}

TEST(Reductions, EmptyBody) {
  ParticleSet<2> body("none");
  body.add_vector("position");
  body.add_vector("velocity");
  body.add_scalar("mass");
  EXPECT_EQ(total_kinetic_energy(body), 0.0);
  EXPECT_EQ(extent(body, 0), 0.0);
}

TEST(Reductions, MissingFieldsNameBodyAndField) {
  ParticleSet<2> body("wall");
  body.resize(2);
  body.add_vector("position");
  body.add_scalar("velocity");  // wrong kind
  const std::string no_mass = runtime_error_message([&] { total_kinetic_energy(body); });
  EXPECT_NE(no_mass.find("wall"), std::string::npos) << no_mass;
  EXPECT_NE(no_mass.find("'mass'"), std::string::npos) << no_mass;
  body.add_scalar("mass");
  const std::string wrong_kind = runtime_error_message([&] { total_kinetic_energy(body); });
  EXPECT_NE(wrong_kind.find("'velocity'"), std::string::npos) << wrong_kind;
  EXPECT_NE(wrong_kind.find("wall"), std::string::npos) << wrong_kind;
  EXPECT_NE(runtime_error_message([&] { integral(body, "mass"); }).find("'volume'"),
            std::string::npos);
  EXPECT_NE(runtime_error_message([&] { total_vector(body, "force"); }).find("'force'"),
            std::string::npos);
  ParticleSet<2> no_position("ghost");
  EXPECT_NE(runtime_error_message([&] { extent(no_position, 0); }).find("'position'"),
            std::string::npos);
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(CsvTimeSeries, HeaderAndRowsReadableWhileOpen) {
  const fs::path path = fs::temp_directory_path() / "cosph_probes_test_series.csv";
  {
    CsvTimeSeries csv(path.string(), {"kinetic_energy", "c@inlet", "a,b", "say \"hi\""});
    EXPECT_EQ(read_file(path), "time,kinetic_energy,c@inlet,\"a,b\",\"say \"\"hi\"\"\"\n");
    csv.append(0.0, {1.0, -2.5, 0.0, 3.0});
    csv.append(0.1, {1.0 / 3.0, std::numeric_limits<double>::quiet_NaN(), 1e-300, -0.0});
    // Still open: every row is already on disk.
    const std::string text = read_file(path);
    EXPECT_EQ(text,
              "time,kinetic_energy,c@inlet,\"a,b\",\"say \"\"hi\"\"\"\n"
              "0,1,-2.5,0,3\n"
              "0.1,0.3333333333333333,nan,1e-300,-0\n");
    // Full precision: what the series writes reads back to the same double, for any bit pattern
    // of a finite double (normal, subnormal, signed zero), not only the ones above.
    std::mt19937_64 bits(7);
    for (int k = 0; k < 20000; ++k) {
      const double x = std::bit_cast<double>(bits());
      if (!std::isfinite(x)) continue;
      const std::string text = format_double(x);
      ASSERT_EQ(std::bit_cast<std::uint64_t>(std::strtod(text.c_str(), nullptr)),
                std::bit_cast<std::uint64_t>(x))
          << text;
    }
    EXPECT_THROW(csv.append(0.2, {1.0}), std::invalid_argument);
  }
  fs::remove(path);
}

TEST(CsvTimeSeries, UnopenablePathThrowsNamingIt) {
  const std::string path = (fs::temp_directory_path() / "cosph_no_such_dir" / "x.csv").string();
  const std::string message = runtime_error_message([&] { CsvTimeSeries csv(path, {"a"}); });
  EXPECT_NE(message.find(path), std::string::npos) << message;
}

}  // namespace
}  // namespace cosph
