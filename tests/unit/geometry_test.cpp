// Shapes, lattice filling, point-cloud files, regions and surface detection.
#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "geometry/lattice.hpp"
#include "geometry/point_cloud_csv.hpp"
#include "geometry/regions.hpp"
#include "geometry/shapes.hpp"
#include "geometry/surface.hpp"

namespace cosph {
namespace {

constexpr double kPi = std::numbers::pi;

template <int D>
double total_volume(const ParticleCloud<D>& cloud) {
  double v = 0.0;
  for (double x : cloud.volumes) v += x;
  return v;
}

// Predicate for EXPECT_PRED2: `text` contains `part` (gtest only; gmock is not linked).
bool has_substr(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Runs f and returns the message of the exception of type E it throws (fails if none).
template <typename E, typename F>
std::string message_of(const F& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected an exception";
  return {};
}

// ---- Shapes -------------------------------------------------------------------------------

TEST(Shapes, BoxIsClosedAndBoundsAreItsCorners) {
  const Box<2> box(Vec<2>(0, 0), Vec<2>(1, 0.5));
  EXPECT_TRUE(box.contains(Vec<2>(0.5, 0.25)));
  EXPECT_TRUE(box.contains(Vec<2>(1.0, 0.5)));  // corner belongs to the box
  EXPECT_FALSE(box.contains(Vec<2>(1.0 + 1e-12, 0.25)));
  EXPECT_FALSE(box.contains(Vec<2>(0.5, -1e-12)));
  const auto [lo, hi] = box.bounds();
  EXPECT_EQ(lo, Vec<2>(0, 0));
  EXPECT_EQ(hi, Vec<2>(1, 0.5));
}

TEST(Shapes, EllipsoidContainsExactlyTheQuadricInterior) {
  const Ellipsoid<3> e(Vec<3>(1, 2, 3), Vec<3>(1, 2, 4));
  EXPECT_TRUE(e.contains(Vec<3>(1, 2, 3)));
  EXPECT_TRUE(e.contains(Vec<3>(1, 2, 6.999)));
  EXPECT_FALSE(e.contains(Vec<3>(1, 2, 7.001)));
  EXPECT_TRUE(e.contains(Vec<3>(1, 3.99, 3)));
  EXPECT_FALSE(e.contains(Vec<3>(1.8, 3.3, 3)));  // 0.64 + 0.4225 > 1
  const auto [lo, hi] = e.bounds();
  EXPECT_EQ(lo, Vec<3>(0, 0, -1));
  EXPECT_EQ(hi, Vec<3>(2, 4, 7));
}

std::vector<Vec<2>> reversed(std::vector<Vec<2>> v) {
  std::reverse(v.begin(), v.end());
  return v;
}

TEST(Shapes, ConvexPolygonContainsInsideInBothOrientations) {
  const std::vector<Vec<2>> triangle{{0, 0}, {4, 0}, {0, 3}};
  for (const auto& vertices : {triangle, reversed(triangle)}) {
    const Polygon p(vertices);
    EXPECT_TRUE(p.contains(Vec<2>(1, 1)));
    EXPECT_TRUE(p.contains(Vec<2>(3.9, 0.05)));
    EXPECT_FALSE(p.contains(Vec<2>(3, 1)));  // beyond the hypotenuse 3x + 4y = 12
    EXPECT_FALSE(p.contains(Vec<2>(-0.1, 1)));
    EXPECT_FALSE(p.contains(Vec<2>(1, 3)));  // same height as a vertex, outside
    EXPECT_TRUE(p.contains(Vec<2>(2, 0)));   // on an edge
    EXPECT_TRUE(p.contains(Vec<2>(0, 3)));   // a vertex
  }
}

TEST(Shapes, ConcaveLShapedPolygonExcludesTheNotchInBothOrientations) {
  // L: the unit-2 square minus its upper right unit square.
  const std::vector<Vec<2>> l_shape{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  for (const auto& vertices : {l_shape, reversed(l_shape)}) {
    const Polygon p(vertices);
    EXPECT_TRUE(p.contains(Vec<2>(0.5, 0.5)));
    EXPECT_TRUE(p.contains(Vec<2>(1.5, 0.5)));
    EXPECT_TRUE(p.contains(Vec<2>(0.5, 1.5)));
    EXPECT_FALSE(p.contains(Vec<2>(1.5, 1.5)));  // the notch
    EXPECT_FALSE(p.contains(Vec<2>(1.5, 1.0 + 1e-9)));
    EXPECT_TRUE(p.contains(Vec<2>(0.5, 1.0)));  // ray through the reflex vertex (1, 1)
    EXPECT_FALSE(p.contains(Vec<2>(-0.5, 1.0)));
    EXPECT_FALSE(p.contains(Vec<2>(2.5, 0.5)));
  }
}

TEST(Shapes, PolygonLatticeFillCountsTheLShapeArea) {
  // Vertices on lattice lines: the filled area must be the L's area (3) exactly.
  const Polygon p({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}});
  const auto cloud = lattice_fill<2>(p, 0.1);
  EXPECT_EQ(cloud.positions.size(), 300u);
  EXPECT_NEAR(total_volume(cloud), 3.0, 1e-12);
}

TEST(Shapes, UnionAndDifferenceCombineMembership) {
  auto a = std::make_shared<Box<2>>(Vec<2>(0, 0), Vec<2>(1, 1));
  auto b = std::make_shared<Box<2>>(Vec<2>(0.5, 0.5), Vec<2>(1.5, 1.5));
  const Union<2> u({a, b});
  const Difference<2> d(a, b);
  EXPECT_TRUE(u.contains(Vec<2>(0.25, 0.25)));
  EXPECT_TRUE(u.contains(Vec<2>(1.25, 1.25)));
  EXPECT_FALSE(u.contains(Vec<2>(1.25, 0.25)));
  EXPECT_TRUE(d.contains(Vec<2>(0.25, 0.25)));
  EXPECT_FALSE(d.contains(Vec<2>(0.75, 0.75)));
  EXPECT_FALSE(d.contains(Vec<2>(1.25, 1.25)));
  EXPECT_EQ(u.bounds().first, Vec<2>(0, 0));
  EXPECT_EQ(u.bounds().second, Vec<2>(1.5, 1.5));
  EXPECT_EQ(d.bounds().second, Vec<2>(1, 1));
}

TEST(Shapes, UnionAndDifferenceLatticeCounts) {
  // Two overlapping 10x10-site boxes sharing a 5x5-site corner: 100 + 100 - 25.
  auto a = std::make_shared<Box<2>>(Vec<2>(0, 0), Vec<2>(1, 1));
  auto b = std::make_shared<Box<2>>(Vec<2>(0.5, 0.5), Vec<2>(1.5, 1.5));
  EXPECT_EQ(lattice_fill<2>(Union<2>({a, b}), 0.1).positions.size(), 175u);
  // Frame: 10x10 box minus the centred 6x6-site box.
  auto inner = std::make_shared<Box<2>>(Vec<2>(0.2, 0.2), Vec<2>(0.8, 0.8));
  const auto frame = lattice_fill<2>(Difference<2>(a, inner), 0.1);
  EXPECT_EQ(frame.positions.size(), 64u);
  for (const auto& x : frame.positions)
    EXPECT_TRUE(x[0] < 0.2 || x[0] > 0.8 || x[1] < 0.2 || x[1] > 0.8);
  // 3D: a cube shell of 10^3 - 8^3 sites.
  auto cube = std::make_shared<Box<3>>(Vec<3>(0, 0, 0), Vec<3>(1, 1, 1));
  auto core = std::make_shared<Box<3>>(Vec<3>(0.1, 0.1, 0.1), Vec<3>(0.9, 0.9, 0.9));
  EXPECT_EQ(lattice_fill<3>(Difference<3>(cube, core), 0.1).positions.size(), 1000u - 512u);
}

TEST(Shapes, ConstructorsRejectInvalidArgumentsWithAClearMessage) {
  using E = std::invalid_argument;
  EXPECT_PRED2(has_substr, message_of<E>([] { Box<2>(Vec<2>(0, 0), Vec<2>(1, 0)); }), "axis 1");
  EXPECT_PRED2(has_substr, message_of<E>([] { Box<3>(Vec<3>(0, 0, 0), Vec<3>(-1, 1, 1)); }),
               "must exceed lower");
  EXPECT_PRED2(has_substr, message_of<E>([] { Ellipsoid<2>(Vec<2>(0, 0), Vec<2>(1, 0)); }),
               "radii must be positive");
  EXPECT_PRED2(has_substr, message_of<E>([] { Ellipsoid<3>(Vec<3>(0, 0, 0), Vec<3>(1, -1, 1)); }),
               "radii must be positive");
  EXPECT_PRED2(has_substr, message_of<E>([] { Polygon({{0, 0}, {1, 0}}); }), "at least 3");
  EXPECT_PRED2(has_substr, message_of<E>([] { Polygon({{0, 0}, {1, 0}, {2, 0}}); }), "no area");
  EXPECT_PRED2(has_substr, message_of<E>([] {
                 Polygon({{0, 0}, {2, 2}, {2, 0}, {0, 1}});
               }),
               "not a simple polygon");  // bow tie
  EXPECT_PRED2(has_substr, message_of<E>([] {
                 Polygon({{0, 0}, {1, 0}, {1, 0}, {0, 1}});
               }),
               "coincide");
  EXPECT_PRED2(has_substr, message_of<E>([] { TruncatedEllipsoidalShell(7, 17, 6, 20, 5); }),
               "inner ellipsoid must lie inside");
  EXPECT_PRED2(has_substr, message_of<E>([] { TruncatedEllipsoidalShell(7, 21, 10, 20, 5); }),
               "inner ellipsoid must lie inside");
  EXPECT_PRED2(has_substr, message_of<E>([] { TruncatedEllipsoidalShell(7, 17, 10, 0, 5); }),
               "radii must be positive");
  EXPECT_PRED2(has_substr, message_of<E>([] { TruncatedEllipsoidalShell(7, 17, 10, 20, -20); }),
               "leaves nothing");
  EXPECT_PRED2(has_substr, message_of<E>([] { Union<2>({}); }), "at least one");
  EXPECT_PRED2(has_substr, message_of<E>([] { Union<3>({nullptr}); }), "null");
  EXPECT_PRED2(has_substr, message_of<E>([] { Difference<2>(nullptr, nullptr); }), "null");
}

// ---- Lattice ------------------------------------------------------------------------------

TEST(Lattice, BoxCountAndVolumeAreExact) {
  const auto cloud = lattice_fill<2>(Box<2>(Vec<2>(0, 0), Vec<2>(1, 0.5)), 0.1);
  ASSERT_EQ(cloud.positions.size(), 50u);
  ASSERT_EQ(cloud.volumes.size(), 50u);
  EXPECT_NEAR(total_volume(cloud), 0.5, 1e-14);
  const auto cloud3 = lattice_fill<3>(Box<3>(Vec<3>(0, 0, 0), Vec<3>(1, 0.5, 0.3)), 0.1);
  EXPECT_EQ(cloud3.positions.size(), 150u);
  EXPECT_NEAR(total_volume(cloud3), 0.15, 1e-14);
}

TEST(Lattice, SitesAreAnchorPlusHalfSpacingOffsetsInXFastestOrder) {
  const Vec<2> anchor(0.03, -0.02);
  const auto cloud = lattice_fill<2>(Box<2>(Vec<2>(0, 0), Vec<2>(0.3, 0.2)), 0.1, anchor);
  // Sites with x in {0.08, 0.18, 0.28}, y in {0.03, 0.13}; 0.38 and 0.23 are outside the box.
  ASSERT_EQ(cloud.positions.size(), 6u);
  for (std::size_t k = 0; k < cloud.positions.size(); ++k) {
    EXPECT_NEAR(cloud.positions[k][0], 0.08 + 0.1 * static_cast<double>(k % 3), 1e-15);
    EXPECT_NEAR(cloud.positions[k][1], 0.03 + 0.1 * static_cast<double>(k / 3), 1e-15);
  }
}

TEST(Lattice, AdjacentBodiesWithTheSameAnchorInterleaveWithoutGapOrOverlap) {
  // Two boxes touching at x = 0.5 (the boundary falls between sites): together they are exactly
  // the lattice of the combined box, so no site is duplicated and none is missing.
  const double s = 0.05;
  const Vec<3> anchor(0.01, 0.02, 0.03);
  const auto left = lattice_fill<3>(Box<3>(Vec<3>(0, 0, 0), Vec<3>(0.5, 0.4, 0.3)), s, anchor);
  const auto right = lattice_fill<3>(Box<3>(Vec<3>(0.5, 0, 0), Vec<3>(1, 0.4, 0.3)), s, anchor);
  const auto both = lattice_fill<3>(Box<3>(Vec<3>(0, 0, 0), Vec<3>(1, 0.4, 0.3)), s, anchor);
  EXPECT_EQ(left.positions.size() + right.positions.size(), both.positions.size());
  for (const auto& x : left.positions)
    for (const auto& y : right.positions) ASSERT_GE((x - y).norm(), s * (1 - 1e-12));
  const auto key = [&](const Vec<3>& x) {
    return std::array<long, 3>{std::lround(x[0] / s * 1e3), std::lround(x[1] / s * 1e3),
                               std::lround(x[2] / s * 1e3)};
  };
  std::set<std::array<long, 3>> sites;
  for (const auto* c : {&left, &right})
    for (const auto& x : c->positions) sites.insert(key(x));
  for (const auto& x : both.positions) EXPECT_EQ(sites.count(key(x)), 1u);
}

TEST(Lattice, ResultDoesNotDependOnTheThreadCount) {
  const Ellipsoid<3> e(Vec<3>(0.1, 0, 0), Vec<3>(1, 0.8, 0.6));
  const auto many = lattice_fill<3>(e, 0.04);
  ParticleCloud<3> one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = lattice_fill<3>(e, 0.04);
  }
  EXPECT_EQ(one.positions, many.positions);
}

double relative_volume_error_disc(double spacing) {
  const Ellipsoid<2> disc(Vec<2>(0.0123, -0.0456), Vec<2>(1, 1));
  return std::abs(total_volume(lattice_fill<2>(disc, spacing)) / kPi - 1.0);
}

TEST(Lattice, DiscAreaConvergesToTheAnalyticArea) {
  const double coarse = relative_volume_error_disc(0.1);
  const double medium = relative_volume_error_disc(0.03);
  const double fine = relative_volume_error_disc(0.01);
  std::cout << "disc area relative error: " << coarse << " (h 0.1), " << medium << " (0.03), "
            << fine << " (0.01)\n";
  EXPECT_LT(fine, 0.002);
  EXPECT_LT(fine, medium);
  EXPECT_LT(medium, coarse);
}

TEST(Lattice, EllipsoidVolumeConvergesToTheAnalyticVolume) {
  const Vec<3> radii(1.0, 0.7, 0.5);
  const double exact = 4.0 / 3.0 * kPi * radii.prod();
  const Ellipsoid<3> e(Vec<3>(0.011, 0.023, -0.017), radii);
  std::vector<double> error;
  for (double s : {0.1, 0.05, 0.02})
    error.push_back(std::abs(total_volume(lattice_fill<3>(e, s)) / exact - 1.0));
  std::cout << "ellipsoid volume relative error: " << error[0] << " (0.1), " << error[1]
            << " (0.05), " << error[2] << " (0.02)\n";
  EXPECT_LT(error[2], 0.02);
  EXPECT_LT(error[2], error[0]);
}

TEST(Lattice, RejectsBadSpacingTooManySitesAndEmptyResults) {
  using E = std::invalid_argument;
  const Box<3> box(Vec<3>(0, 0, 0), Vec<3>(1, 1, 1));
  EXPECT_PRED2(has_substr, message_of<E>([&] { lattice_fill<3>(box, 0.0); }), "spacing must be");
  EXPECT_PRED2(has_substr, message_of<E>([&] { lattice_fill<3>(box, -0.1); }), "spacing must be");
  EXPECT_PRED2(has_substr, message_of<E>([&] { lattice_fill<3>(box, std::nan("")); }),
               "spacing must be");
  EXPECT_PRED2(has_substr, message_of<E>([&] { lattice_fill<3>(box, 1e-3); }), "more than");
  // A sphere of radius 0.01 centred between lattice sites holds none of them.
  const Ellipsoid<2> tiny(Vec<2>(0, 0), Vec<2>(0.01, 0.01));
  EXPECT_PRED2(has_substr, message_of<E>([&] { lattice_fill<2>(tiny, 0.1); }), "no lattice site");
}

// ---- Truncated ellipsoidal shell (Land et al. 2015 left ventricle) ------------------------

// Volume of {(x^2 + y^2) / a^2 + z^2 / c^2 <= 1, z <= t}: integral of the disc area
// pi a^2 (1 - z^2 / c^2) from -c to min(t, c).
double truncated_ellipsoid_volume(double a, double c, double t) {
  t = std::min(t, c);
  return kPi * a * a * ((t + c) - (t * t * t + c * c * c) / (3.0 * c * c));
}

TEST(TruncatedShell, LatticeVolumeMatchesTheAnalyticVolumeAndRespectsTheBase) {
  const TruncatedEllipsoidalShell lv(7, 17, 10, 20, 5);
  const double exact = truncated_ellipsoid_volume(10, 20, 5) - truncated_ellipsoid_volume(7, 17, 5);
  EXPECT_NEAR(exact, 3234.73, 0.01);  // by hand: pi (1822.917 - 793.269)
  const auto cloud = lattice_fill<3>(lv, 0.5);
  const double error = std::abs(total_volume(cloud) / exact - 1.0);
  std::cout << "LV shell: " << cloud.positions.size() << " particles at 0.5 mm, volume "
            << total_volume(cloud) << " vs " << exact << " mm^3 (relative error " << error << ")\n";
  EXPECT_LT(error, 0.02);
  double z_max = -1e9;
  for (const auto& x : cloud.positions) {
    z_max = std::max(z_max, x[2]);
    const double rho2 = x[0] * x[0] + x[1] * x[1];
    ASSERT_GE(rho2 / 49 + x[2] * x[2] / 289, 1.0);
    ASSERT_LE(rho2 / 100 + x[2] * x[2] / 400, 1.0);
  }
  EXPECT_LE(z_max, 5.0);
  EXPECT_GT(z_max, 4.5);  // the base layer is there
  const auto [lo, hi] = lv.bounds();
  EXPECT_EQ(lo, Vec<3>(-10, -10, -20));
  EXPECT_EQ(hi, Vec<3>(10, 10, 5));
}

TEST(TruncatedShell, ContainsFollowsTheThreeSurfaces) {
  const TruncatedEllipsoidalShell lv(7, 17, 10, 20, 5);
  EXPECT_FALSE(lv.contains(Vec<3>(0, 0, 0)));     // cavity
  EXPECT_TRUE(lv.contains(Vec<3>(8.5, 0, 0)));    // mid-wall at the equator
  EXPECT_FALSE(lv.contains(Vec<3>(10.5, 0, 0)));  // outside the epicardium
  EXPECT_TRUE(lv.contains(Vec<3>(0, 0, -18.5)));  // apex wall
  EXPECT_FALSE(lv.contains(Vec<3>(0, 0, -20.5)));
  EXPECT_FALSE(lv.contains(Vec<3>(0, 8.5, 5.5)));  // above the base
  EXPECT_TRUE(lv.contains(Vec<3>(0, 8.5, 4.9)));
}

// ---- Point-cloud CSV ----------------------------------------------------------------------

class PointCloudCsv : public ::testing::Test {
 protected:
  std::string write(const std::string& name, const std::string& text) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("cosph_geometry_test_" + std::to_string(::getpid()) + "_" + name + ".csv");
    std::ofstream(path) << text;
    paths_.push_back(path);
    return path.string();
  }
  void TearDown() override {
    for (const auto& p : paths_) std::filesystem::remove(p);
  }

 private:
  std::vector<std::filesystem::path> paths_;
};

TEST_F(PointCloudCsv, RoundTripKeepsPositionsVolumesAndOrder) {
  const auto cloud = lattice_fill<3>(Ellipsoid<3>(Vec<3>(0, 0, 0), Vec<3>(1, 0.5, 0.3)), 0.1);
  std::ostringstream text;
  text.precision(17);
  text << "# exported by a test\nid, volume ,z,y,x,material\n";
  for (std::size_t i = 0; i < cloud.positions.size(); ++i) {
    const auto& x = cloud.positions[i];
    text << i << "," << cloud.volumes[i] << "," << x[2] << "," << x[1] << "," << x[0]
         << ",muscle\r\n";  // Windows line ends are accepted
    if (i == 3) text << "\n   # a comment between data lines\n";
  }
  const auto read = read_point_cloud_csv<3>(write("roundtrip", text.str()));
  EXPECT_EQ(read.positions, cloud.positions);
  EXPECT_EQ(read.volumes, cloud.volumes);
}

TEST_F(PointCloudCsv, TwoDimensionalReadIgnoresAZColumnAndAcceptsQuotedNames) {
  const auto read = read_point_cloud_csv<2>(
      write("2d", "\"X\",\"Y\",\"Z\",\"Volume\"\n1.5,-2,7,0.25\n+3,4e-1,8,1E-2\n"));
  ASSERT_EQ(read.positions.size(), 2u);
  EXPECT_EQ(read.positions[0], Vec<2>(1.5, -2));
  EXPECT_EQ(read.positions[1], Vec<2>(3, 0.4));
  EXPECT_EQ(read.volumes, (std::vector<double>{0.25, 0.01}));
}

TEST_F(PointCloudCsv, EveryErrorNamesTheFileAndTheLine) {
  const auto error_of = [&](const std::string& name, const std::string& text) {
    const std::string path = write(name, text);
    const std::string message = message_of<RuntimeError>([&] { read_point_cloud_csv<3>(path); });
    EXPECT_PRED2(has_substr, message, path) << name;
    return message;
  };
  EXPECT_PRED2(has_substr, error_of("missing", "# c\nx,y,volume\n1,2,3\n"),
               ":2: missing column 'z'");
  EXPECT_PRED2(has_substr, error_of("repeated", "x,y,z,volume,x\n"),
               ":1: column 'x' appears twice");
  EXPECT_PRED2(has_substr, error_of("text", "x,y,z,volume\n1,2,3,4\n1,abc,3,4\n"),
               ":3: column 'y': 'abc' is not a finite number");
  EXPECT_PRED2(has_substr, error_of("partial", "x,y,z,volume\n1,2,3,4\n\n1,2.5q,3,4\n"),
               ":4: column 'y'");
  EXPECT_PRED2(has_substr, error_of("empty_field", "x,y,z,volume\n1,,3,4\n"), ":2: column 'y'");
  EXPECT_PRED2(has_substr, error_of("nan", "x,y,z,volume\n1,2,nan,4\n"), ":2: column 'z'");
  EXPECT_PRED2(has_substr, error_of("zero_volume", "x,y,z,volume\n1,2,3,0\n"),
               ":2: volume must be positive, got 0");
  EXPECT_PRED2(has_substr, error_of("negative_volume", "x,y,z,volume\n1,2,3,4\n1,2,3,-1e-3\n"),
               ":3: volume must be positive");
  EXPECT_PRED2(has_substr, error_of("too_few", "x,y,z,volume,id\n1,2,3,4,5\n1,2,3,4\n"),
               ":3: expected 5 comma-separated fields (as in the header), found 4");
  EXPECT_PRED2(has_substr, error_of("too_many", "x,y,z,volume\n1,2,3,4,5\n"), ":2: expected 4");
  EXPECT_PRED2(has_substr, error_of("header_only", "x,y,z,volume\n"), ": no data");
  EXPECT_PRED2(has_substr, error_of("no_header", "# nothing\n\n"), ": no header line");

  const std::string absent = "/nonexistent_dir_cosph/points.csv";
  EXPECT_EQ(message_of<RuntimeError>([&] { read_point_cloud_csv<2>(absent); }),
            absent + ": cannot open point-cloud file for reading");
}

// ---- Regions ------------------------------------------------------------------------------

TEST(Regions, SelectsTheContainedIndicesInIncreasingOrder) {
  const auto cloud = lattice_fill<2>(Box<2>(Vec<2>(0, 0), Vec<2>(1, 1)), 0.1);
  const Ellipsoid<2> region(Vec<2>(0.5, 0.5), Vec<2>(0.3, 0.2));
  const auto selected = select_region<2>(cloud.positions, region);
  std::vector<Index> expected;
  for (std::size_t i = 0; i < cloud.positions.size(); ++i)
    if (region.contains(cloud.positions[i])) expected.push_back(static_cast<Index>(i));
  EXPECT_EQ(selected, expected);
  EXPECT_EQ(selected.size(), 20u);  // rows y = 0.35, 0.45, 0.55, 0.65 hold 4, 6, 6, 4 sites
  EXPECT_TRUE(std::is_sorted(selected.begin(), selected.end()));
  EXPECT_TRUE(select_region<2>(cloud.positions, Box<2>(Vec<2>(2, 2), Vec<2>(3, 3))).empty());
  // Base layer of a 3D box.
  const auto cloud3 = lattice_fill<3>(Box<3>(Vec<3>(0, 0, 0), Vec<3>(1, 1, 1)), 0.1);
  const auto base =
      select_region<3>(cloud3.positions, Box<3>(Vec<3>(-1, -1, -1), Vec<3>(2, 2, 0.1)));
  ASSERT_EQ(base.size(), 100u);
  for (std::size_t k = 0; k < base.size(); ++k) EXPECT_EQ(base[k], k);  // z slowest
}

// ---- Surface ------------------------------------------------------------------------------

// Lattice particles with at least one axis-neighbour site outside the shape: the outermost layer.
template <int D>
std::set<Index> exposed_sites(const ParticleCloud<D>& cloud, const Shape<D>& shape, double s) {
  std::set<Index> exposed;
  for (std::size_t i = 0; i < cloud.positions.size(); ++i)
    for (int a = 0; a < D; ++a)
      for (double sign : {-1.0, 1.0}) {
        Vec<D> y = cloud.positions[i];
        y[a] += sign * s;
        if (!shape.contains(y)) exposed.insert(static_cast<Index>(i));
      }
  return exposed;
}

double angle_degrees(const auto& a, const auto& b) {
  return std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)) * 180.0 / kPi;
}

// Box of n[a] lattice sites (spacing 1) per axis: the surface is exactly the outermost layer;
// normals are exact on face particles at least `clear` sites away from every other face, and
// the corner normals are the diagonals.
template <int D>
void check_box_surface(const std::array<int, D>& n) {
  Vec<D> upper;
  for (int a = 0; a < D; ++a) upper[a] = n[a];
  const Box<D> box(Vec<D>::Zero(), upper);
  const auto cloud = lattice_fill<D>(box, 1.0);
  const auto surface = detect_surface<D>(cloud.positions, cloud.volumes, 1.0);
  const auto exposed = exposed_sites<D>(cloud, box, 1.0);
  EXPECT_EQ(std::set<Index>(surface.particles.begin(), surface.particles.end()), exposed);
  ASSERT_EQ(surface.normals.size(), surface.particles.size());
  EXPECT_TRUE(std::is_sorted(surface.particles.begin(), surface.particles.end()));

  // Beyond 5 spacings from another face, the nearest missing site across it is 5.5 + 0.5
  // away, outside the normal kernel's support (5.2 spacings).
  constexpr int clear = 5;
  int checked = 0, corners = 0;
  double worst_face = 0.0;
  for (std::size_t k = 0; k < surface.particles.size(); ++k) {
    const Vec<D>& x = cloud.positions[surface.particles[k]];
    const Vec<D>& normal = surface.normals[k];
    EXPECT_NEAR(normal.norm(), 1.0, 1e-12);
    Vec<D> outward = Vec<D>::Zero();
    int faces = 0;
    bool clear_of_edges = true;
    for (int a = 0; a < D; ++a) {
      const double below = x[a], above = upper[a] - x[a];
      if (below < 1.0) outward[a] = -1.0, ++faces;
      if (above < 1.0) outward[a] = 1.0, ++faces;
      if (std::min(below, above) > 1.0 && std::min(below, above) < clear) clear_of_edges = false;
    }
    if (faces == 1 && clear_of_edges) {
      worst_face = std::max(worst_face, (normal - outward).norm());
      ++checked;
    }
    if (faces == D) {
      EXPECT_LT((normal - outward.normalized()).norm(), 1e-9) << x.transpose();
      ++corners;
    }
  }
  EXPECT_GT(checked, 0);
  EXPECT_EQ(corners, 1 << D);
  EXPECT_LT(worst_face, 1e-12);
  std::cout << D << "D box: " << surface.particles.size() << " surface particles of "
            << cloud.positions.size() << ", max face-normal error " << worst_face << " on "
            << checked << " face particles\n";
}

TEST(Surface, BoxSurfaceIsExactlyTheOutermostLayerWithAxisNormals2D) {
  check_box_surface<2>({20, 15});
}

TEST(Surface, BoxSurfaceIsExactlyTheOutermostLayerWithAxisNormals3D) {
  check_box_surface<3>({15, 14, 13});
}

// Lattice-filled ball: the surface includes every exposed particle and nothing deeper than
// `depth` spacings; normals within `max_angle` degrees of the radial direction.
template <int D>
double check_ball_surface(double radius, double spacing, double depth, double max_angle,
                          bool exactly_exposed) {
  Vec<D> center = Vec<D>::Constant(0.013 * radius);
  center[0] = -0.021 * radius;
  const Ellipsoid<D> ball(center, Vec<D>::Constant(radius));
  const auto cloud = lattice_fill<D>(ball, spacing);
  const auto surface = detect_surface<D>(cloud.positions, cloud.volumes, spacing);
  const auto exposed = exposed_sites<D>(cloud, ball, spacing);
  const std::set<Index> found(surface.particles.begin(), surface.particles.end());
  if (exactly_exposed) {
    EXPECT_EQ(found, exposed);
  } else {
    EXPECT_TRUE(std::includes(found.begin(), found.end(), exposed.begin(), exposed.end()));
  }
  double worst = 0.0;
  for (std::size_t k = 0; k < surface.particles.size(); ++k) {
    const Vec<D> r = cloud.positions[surface.particles[k]] - center;
    EXPECT_GT(r.norm(), radius - depth * spacing);
    worst = std::max(worst, angle_degrees(surface.normals[k], r));
  }
  EXPECT_LT(worst, max_angle);
  std::cout << D << "D ball R/s = " << radius / spacing << ": " << surface.particles.size()
            << " surface particles (" << exposed.size() << " exposed sites), max normal angle "
            << worst << " deg\n";
  return worst;
}

TEST(Surface, DiscSurfaceIsTheExposedLayerWithRadialNormals) {
  check_ball_surface<2>(1.0, 0.1, 1.0, 15.0, true);
  check_ball_surface<2>(1.0, 0.02, 1.0, 15.0, true);
}

TEST(Surface, SphereSurfaceHasRadialNormals) {
  check_ball_surface<3>(1.0, 0.1, 1.5, 12.0, false);
  check_ball_surface<3>(1.0, 0.05, 1.5, 12.0, false);
}

TEST(Surface, ConcaveCornerOfAnLShapeIsCoveredAndItsNeighboursAreExposed) {
  const Polygon l_shape({{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}});
  const double s = 0.04;
  const auto cloud = lattice_fill<2>(l_shape, s);
  const auto surface = detect_surface<2>(cloud.positions, cloud.volumes, s);
  EXPECT_EQ(std::set<Index>(surface.particles.begin(), surface.particles.end()),
            exposed_sites<2>(cloud, l_shape, s));
  // Particles of the notch's walls farther than the normal kernel's support (5.2 s) from the
  // corner and the arms' ends face exactly +x or +y.
  int checked = 0;
  for (std::size_t k = 0; k < surface.particles.size(); ++k) {
    const Vec<2>& x = cloud.positions[surface.particles[k]];
    if (std::abs(x[0] - 0.98) < 1e-9 && x[1] > 1.29 && x[1] < 1.71) {
      EXPECT_LT((surface.normals[k] - Vec<2>(1, 0)).norm(), 1e-12);
      ++checked;
    }
    if (std::abs(x[1] - 0.98) < 1e-9 && x[0] > 1.29 && x[0] < 1.71) {
      EXPECT_LT((surface.normals[k] - Vec<2>(0, 1)).norm(), 1e-12);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 22);
}

TEST(Surface, TruncatedShellNormalsFollowTheEllipsoids) {
  // 6 particles through the 3 mm wall. Each surface particle lies within 1.5 spacings of one of
  // the three surfaces and its normal is compared with that surface's normal: within 10 degrees
  // on the ellipsoids where the base is beyond the normal kernel's support (5.2 spacings), within
  // 20 degrees near the base rims (the wide kernel blends the normals of two faces there). The
  // rims themselves (within 2 spacings of two surfaces) have no single normal and are skipped.
  const double s = 0.5;
  const TruncatedEllipsoidalShell lv(7, 17, 10, 20, 5);
  const auto cloud = lattice_fill<3>(lv, s);
  const auto surface = detect_surface<3>(cloud.positions, cloud.volumes, s);
  double worst_clear = 0.0, worst_near_rim = 0.0;
  int clear = 0;
  for (std::size_t k = 0; k < surface.particles.size(); ++k) {
    const Vec<3>& x = cloud.positions[surface.particles[k]];
    // Distances to the endocardium, epicardium and base (the ellipsoid ones approximate, and
    // underestimates towards the apex, which only makes the skipping more conservative).
    const double rho2 = x[0] * x[0] + x[1] * x[1];
    const std::array<double, 3> d{(std::sqrt(rho2 / 49 + x[2] * x[2] / 289) - 1) * 7,
                                  (1 - std::sqrt(rho2 / 100 + x[2] * x[2] / 400)) * 10, 5 - x[2]};
    const std::array<Vec<3>, 3> normal{-Vec<3>(x[0] / 49, x[1] / 49, x[2] / 289),
                                       Vec<3>(x[0] / 100, x[1] / 100, x[2] / 400), Vec<3>(0, 0, 1)};
    const auto nearest = std::min_element(d.begin(), d.end()) - d.begin();
    EXPECT_LT(d[nearest], 1.5 * s) << x.transpose();
    double other = 1e9;
    for (int f = 0; f < 3; ++f)
      if (f != nearest) other = std::min(other, d[f]);
    if (other < 2 * s) continue;
    const double angle = angle_degrees(surface.normals[k], normal[nearest]);
    // Endocardium and epicardium are 6 spacings apart, out of each other's reach; only the base
    // plane can tilt their normals.
    if (nearest != 2 && d[2] > 5.2 * s) {
      worst_clear = std::max(worst_clear, angle);
      ++clear;
    } else {
      worst_near_rim = std::max(worst_near_rim, angle);
    }
  }
  std::cout << "LV shell: " << surface.particles.size() << " surface particles of "
            << cloud.positions.size() << ", max normal angle " << worst_clear << " deg on " << clear
            << " away from the base rims, " << worst_near_rim << " deg near them\n";
  EXPECT_GT(clear, 5000);
  EXPECT_LT(worst_clear, 10.0);
  EXPECT_LT(worst_near_rim, 20.0);
}

TEST(Surface, DegenerateCloudsAreAllSurface) {
  // A single particle and a line one particle thick: every particle is on the surface, with a
  // unit normal (across the line for the line).
  const auto single = detect_surface<2>({Vec<2>(1, 2)}, {1.0}, 1.0);
  ASSERT_EQ(single.particles, std::vector<Index>{0});
  EXPECT_NEAR(single.normals[0].norm(), 1.0, 1e-12);
  std::vector<Vec<3>> line;
  for (int i = 0; i < 20; ++i) line.emplace_back(0.1 * i, 0, 0);
  const auto surface = detect_surface<3>(line, std::vector<double>(20, 1e-3), 0.1);
  ASSERT_EQ(surface.particles.size(), 20u);
  for (std::size_t k = 2; k + 2 < surface.particles.size(); ++k)
    EXPECT_NEAR(surface.normals[k][0], 0.0, 1e-9);
  EXPECT_TRUE(detect_surface<2>({}, {}, 1.0).particles.empty());
}

TEST(Surface, PointCloudWithNonLatticeSpacingFindsItsRim) {
  // Hexagonal packing of a disc (not a cubic lattice): the rim particles are found with radial
  // normals, the interior is not.
  const double s = 0.05, radius = 1.0;
  std::vector<Vec<2>> positions;
  for (int j = -30; j <= 30; ++j)
    for (int i = -30; i <= 30; ++i) {
      const Vec<2> x((i + 0.5 * (j & 1)) * s, j * s * std::sqrt(3.0) / 2);
      if (x.norm() <= radius) positions.push_back(x);
    }
  const std::vector<double> volumes(positions.size(), s * s * std::sqrt(3.0) / 2);
  const auto surface = detect_surface<2>(positions, volumes, s);
  double worst = 0.0;
  for (std::size_t k = 0; k < surface.particles.size(); ++k) {
    const Vec<2>& x = positions[surface.particles[k]];
    EXPECT_GT(x.norm(), radius - s);
    worst = std::max(worst, angle_degrees(surface.normals[k], x));
  }
  // The rim circumference holds about 2 pi R / s = 126 particles.
  EXPECT_GT(surface.particles.size(), 110u);
  EXPECT_LT(surface.particles.size(), 150u);
  EXPECT_LT(worst, 12.0);
  std::cout << "hexagonal disc: " << surface.particles.size() << " surface particles, max normal "
            << "angle " << worst << " deg\n";
}

// Box lattice (spacing 1) with every coordinate jittered by up to +-0.2: interior supports are
// no longer symmetric, yet no particle below the outer layer may be reported (the free-site
// test removes them), and at least 99% of the outer layer must be found.
template <int D>
void check_jittered_box(int n) {
  const Box<D> box(Vec<D>::Zero(), Vec<D>::Constant(n));
  auto cloud = lattice_fill<D>(box, 1.0);
  const auto outer = exposed_sites<D>(cloud, box, 1.0);
  std::mt19937 random(12345);  // raw mt19937 output is the same on every platform
  for (auto& x : cloud.positions)
    for (int a = 0; a < D; ++a) x[a] += 0.4 * (static_cast<double>(random()) / 4294967296.0 - 0.5);
  const auto surface = detect_surface<D>(cloud.positions, cloud.volumes, 1.0);
  std::size_t found_outer = 0;
  for (const Index i : surface.particles) {
    EXPECT_TRUE(outer.count(i)) << "interior particle " << cloud.positions[i].transpose();
    found_outer += outer.count(i);
  }
  EXPECT_GE(static_cast<double>(found_outer), 0.99 * static_cast<double>(outer.size()));
  std::cout << D << "D jittered box: " << found_outer << " of " << outer.size()
            << " outer-layer particles found, " << surface.particles.size() - found_outer
            << " others\n";
}

TEST(Surface, JitteredBoxReportsNoInteriorParticle) {
  check_jittered_box<2>(12);
  check_jittered_box<3>(12);
}

TEST(Surface, ResultDoesNotDependOnTheThreadCount) {
  const auto cloud = lattice_fill<3>(Ellipsoid<3>(Vec<3>(0, 0, 0), Vec<3>(1, 0.7, 0.5)), 0.05);
  const auto many = detect_surface<3>(cloud.positions, cloud.volumes, 0.05);
  tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
  const auto one = detect_surface<3>(cloud.positions, cloud.volumes, 0.05);
  EXPECT_EQ(one.particles, many.particles);
  EXPECT_EQ(one.normals, many.normals);
}

TEST(Surface, RejectsMismatchedSizesAndBadSpacing) {
  const std::vector<Vec<2>> x{Vec<2>(0, 0), Vec<2>(1, 0)};
  EXPECT_THROW(detect_surface<2>(x, {1.0}, 1.0), std::invalid_argument);
  EXPECT_THROW(detect_surface<2>(x, {1.0, 1.0}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace cosph
