// Wall pressure sensors: the mean pressure over a sensor's face from the force on the wall
// particles behind it.
#include "io/wall_sensor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "neighbour/domain.hpp"

namespace cosph {
namespace {

constexpr double kA = 0.1;  // wall particle spacing
constexpr int kLayers = 3;

// A wall below the plane y = 0 (2D) or z = 0 (3D), kLayers particles thick, over [-1, 1] along the
// face, plus a far wall above y (z) = 2 facing it. The force on each particle of a column is the
// column's pressure p(face coordinates) times the particle's share a^(D-1), split unequally over
// the layers (60/30/10%): the sensor must add the layers, whatever the split.
template <int D>
struct Wall {
  ParticleSet<D> particles{"wall"};
  std::vector<Vec<D>> force;
  explicit Wall(const std::function<double(const Vec<D>&)>& pressure) {
    std::vector<Vec<D>> x;
    const double split[kLayers] = {0.6, 0.3, 0.1};
    const int n = static_cast<int>(std::lround(2.0 / kA));
    const int columns = D == 2 ? n : n * n;
    for (int c = 0; c < columns; ++c)
      for (int l = 0; l < kLayers; ++l) {
        Vec<D> p = Vec<D>::Zero();
        p[0] = -1.0 + (c % n + 0.5) * kA;
        if constexpr (D == 3) p[1] = -1.0 + (c / n + 0.5) * kA;
        p[D - 1] = -(l + 0.5) * kA;
        const double share = D == 2 ? kA : kA * kA;
        x.push_back(p);
        force.push_back(-split[l] * pressure(p) * share * Vec<D>::Unit(D - 1));
        // The far wall: pushed the other way, and hard; it must not count.
        Vec<D> q = p;
        q[D - 1] = 2.0 + (l + 0.5) * kA;
        x.push_back(q);
        force.push_back(1e6 * Vec<D>::Unit(D - 1));
      }
    particles.resize(x.size());
    particles.add_vector("position") = x;
    particles.add_scalar("volume") = std::vector<double>(x.size(), std::pow(kA, D));
  }
};

template <int D>
Vec<D> on_face(double u, double v = 0.0) {
  Vec<D> c = Vec<D>::Zero();
  c[0] = u;
  if constexpr (D == 3) c[1] = v;
  return c;
}

template <int D>
void check_uniform() {
  const Wall<D> wall([](const Vec<D>&) { return 2.5; });
  // Faces narrower than a particle, a few particles wide, off the lattice.
  for (double diameter : {0.03, 0.17, 0.45})
    for (double u : {0.0, 0.013, 0.35}) {
      const WallSensor<D> sensor({on_face<D>(u, -0.21)}, Vec<D>::Unit(D - 1), diameter);
      EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35)[0], 2.5, 1e-12)
          << "diameter " << diameter << " at " << u;
    }
}

TEST(WallSensor, ReadsAUniformPressureWhateverItsSize2D) { check_uniform<2>(); }
TEST(WallSensor, ReadsAUniformPressureWhateverItsSize3D) { check_uniform<3>(); }

// A pressure varying along the wall: a face narrower than a particle reads the column in front of
// it, a wider one the area-weighted mean of the columns it covers.
TEST(WallSensor, AveragesTheColumnsItsFaceCovers2D) {
  const Wall<2> wall([](const Vec<2>& x) { return 1.0 + 10.0 * x[0]; });
  const Vec<2> up = Vec<2>::Unit(1);
  // Column [0.1, 0.2] carries 1 + 10 * 0.15 = 2.5.
  EXPECT_NEAR(
      WallSensor<2>({Vec<2>(0.13, 0.0)}, up, 0.02).sample(wall.particles, wall.force, 0.35)[0], 2.5,
      1e-12);
  // Face [0.15, 0.35]: half of column 0.15 (2.5), all of 0.25 (3.5), half of 0.35 (4.5).
  EXPECT_NEAR(
      WallSensor<2>({Vec<2>(0.25, 0.0)}, up, 0.2).sample(wall.particles, wall.force, 0.35)[0],
      (0.05 * 2.5 + 0.1 * 3.5 + 0.05 * 4.5) / 0.2, 1e-12);
}

// Particles deeper than the depth do not count (nor does the far wall, beyond any depth); with a
// depth of one layer only the first layer's 60% is read.
TEST(WallSensor, CountsOnlyTheParticlesBehindTheFaceWithinTheDepth) {
  const Wall<2> wall([](const Vec<2>&) { return 1.0; });
  const WallSensor<2> sensor({Vec<2>(0.0, 0.0)}, Vec<2>::Unit(1), 0.3);
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.1)[0], 0.6, 1e-12);
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35)[0], 1.0, 1e-12);
}

// The same wall seen from the far side: its normal points the other way, and the near wall's
// particles lie in front of that face.
TEST(WallSensor, FacingTheOtherWayReadsTheOtherWall) {
  const Wall<2> wall([](const Vec<2>&) { return 1.0; });
  const WallSensor<2> sensor({Vec<2>(0.0, 2.0)}, -Vec<2>::Unit(1), 0.3);
  // The far wall's force, 1e6 along +y on three layers of share 0.1: 3e7 along the normal's
  // opposite, i.e. a pressure of 3e7 on the far wall.
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35)[0], 3e7, 1.0);
}

TEST(WallSensor, SensorOffTheWallReadsNaNAndBadInputThrows) {
  const Wall<2> wall([](const Vec<2>&) { return 1.0; });
  EXPECT_TRUE(std::isnan(WallSensor<2>({Vec<2>(5.0, 0.0)}, Vec<2>::Unit(1), 0.1)
                             .sample(wall.particles, wall.force, 0.35)[0]));
  EXPECT_THROW(WallSensor<2>({Vec<2>(0.0, 0.0)}, Vec<2>::Zero(), 0.1), std::invalid_argument);
  EXPECT_THROW(WallSensor<2>({Vec<2>(0.0, 0.0)}, Vec<2>::Unit(1), 0.0), std::invalid_argument);
}

// The wall periodic along x (period 2, its columns continuing across the seam at x = +-1), with
// the pressure 1 + x of each column: a face of 0.3 centred at x = 0.97 covers 0.08 of the column
// at 0.85 (pressure 1.85), the column at 0.95 (1.95) and, across the seam, the column at -0.95
// (0.05) and 0.02 of the one at -0.85 (0.15): (0.148 + 0.195 + 0.005 + 0.003) / 0.3 = 1.17.
// Without the period the face's part past the seam reads nothing: 0.343 / 0.3 = 1.143.
Domain<2> periodic_along_x() {
  Domain<2> domain;
  domain.lower = Vec<2>(-1.0, -3.0);
  domain.upper = Vec<2>(1.0, 3.0);
  domain.periodic = {true, false};
  return domain;
}

TEST(WallSensor, AFaceAcrossAPeriodicSeamReadsTheColumnsOnBothSides) {
  const Wall<2> wall([](const Vec<2>& x) { return 1.0 + x[0]; });
  const WallSensor<2> sensor({Vec<2>(0.97, 0.0)}, Vec<2>::Unit(1), 0.3);
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35, periodic_along_x())[0], 1.17, 1e-12);
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35)[0], 0.343 / 0.3, 1e-12);
}

// A face with one particle's share fits in the period 2 up to a diameter of 1.9; past it two
// images of a column could both lie under the face, and the sensor is refused, not read short.
TEST(WallSensor, APeriodShorterThanTheFaceAndOneShareIsRefused) {
  const Wall<2> wall([](const Vec<2>&) { return 1.0; });
  const Domain<2> domain = periodic_along_x();
  const auto read = [&](double diameter) {
    return WallSensor<2>({Vec<2>(0.0, 0.0)}, Vec<2>::Unit(1), diameter)
        .sample(wall.particles, wall.force, 0.35, domain)[0];
  };
  EXPECT_NEAR(read(1.9), 1.0, 1e-12);
  EXPECT_THROW(read(1.95), std::invalid_argument);
  try {
    read(1.95);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("periodic axis 0"), std::string::npos) << e.what();
  }
}

// A period along the face's normal does not bound the face: the face has no extent there. A face
// of 1.9 (2.0 with one particle's share) facing along y, in a domain periodic along y with a period
// of 1.5, reads its uniform pressure; the far wall (y = 2.05-2.25) lies 0.55-0.75 above the face
// or 0.75-0.95 below it through the period, both beyond the wall's depth of 0.35.
TEST(WallSensor, APeriodAlongTheNormalDoesNotLimitTheFace) {
  const Wall<2> wall([](const Vec<2>&) { return 1.0; });
  Domain<2> domain;
  domain.lower = Vec<2>(-3.0, -1.0);
  domain.upper = Vec<2>(3.0, 0.5);
  domain.periodic = {false, true};
  const WallSensor<2> sensor({Vec<2>(0.0, 0.0)}, Vec<2>::Unit(1), 1.9);
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35, domain)[0], 1.0, 1e-12);
}

// The corner's particles find their receivers across a periodic seam. A wall two columns wide
// (x in [0.8, 1]) stands on the periodic floor; the face (x in [-0.95, 0.95], over part of that
// wall only to put the corner on the far side of the centre from the face's other end) takes the
// floor's uniform pressure 1. The corner column at 0.95 is 0.1 from the face's end column at
// -0.95 across the seam and 0.2 from the column at 0.75: it passes its force to the end column,
// whose half is covered, and the face reads 1.9 / 1.9 = 1. Measured by the offsets' plain
// difference it would pass it to 0.75, covered whole: 1.95 / 1.9 = 1.026.
TEST(WallSensor, ACornersParticlesFindTheirReceiverAcrossAPeriodicSeam) {
  Wall<2> wall([](const Vec<2>&) { return 1.0; });
  auto& x = wall.particles.vector("position");
  auto& volume = wall.particles.scalar("volume");
  for (double column : {0.85, 0.95})
    for (int layer = 0; layer < kLayers; ++layer) {
      x.emplace_back(column, (layer + 0.5) * kA);
      volume.push_back(kA * kA);
      wall.force.push_back(Vec<2>::Zero());
    }
  wall.particles.resize(x.size());
  const WallSensor<2> sensor({Vec<2>(0.0, 0.0)}, Vec<2>::Unit(1), 1.9);
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35, periodic_along_x())[0], 1.0, 1e-12);
}

// A moving wall: the cached coverage follows it. The wall with a linear pressure 1 + x slides by
// 0.5 along the face: the sensor at x = 0.2 then reads the columns that arrived behind it (a
// pressure of 0.7 where they started at -0.3), and NaN once the wall has left its face.
TEST(WallSensor, CoverageCacheFollowsAMovingWall) {
  Wall<2> wall([](const Vec<2>& x) { return 1.0 + x[0]; });
  const WallSensor<2> sensor({Vec<2>(0.2, 0.0)}, Vec<2>::Unit(1), 0.1);
  CoverageCache<2> cache;
  EXPECT_NEAR(sensor.sample(cache.of(sensor, wall.particles, 0.35, {}), wall.force)[0], 1.2, 1e-12);
  for (auto& x : wall.particles.vector("position")) x[0] += 0.5;
  EXPECT_NEAR(sensor.sample(cache.of(sensor, wall.particles, 0.35, {}), wall.force)[0], 0.7, 1e-12);
  for (auto& x : wall.particles.vector("position")) x[0] += 2.0;
  EXPECT_TRUE(std::isnan(sensor.sample(cache.of(sensor, wall.particles, 0.35, {}), wall.force)[0]));
}

// A disc against the squares of a 3D wall: a small disc inside one square is covered whole, a
// square far away not at all, and the squares of a lattice share a large disc between them
// exactly. The squares' edges (side 1/8, centres k/8 + 5/64) fall on the face's quadrature points
// ((2 i + 1) / 64 - 1/2 for a unit disc), so a point on an edge must count once, not twice.
TEST(WallSensor, CoveredAreaOfADiscAndASquare3D) {
  const double pi = std::acos(-1.0);
  const WallSensor<3> small({Vec<3>::Zero()}, Vec<3>::Unit(2), 0.02);
  EXPECT_NEAR(small.covered(Vec<3>(0.01, 0.02, 0.0), kA), pi * 0.01 * 0.01, 1e-15);
  EXPECT_EQ(small.covered(Vec<3>(0.2, 0.0, 0.0), kA), 0.0);
  const WallSensor<3> large({Vec<3>::Zero()}, Vec<3>::Unit(2), 1.0);
  const double side = 0.125, shift = 5.0 / 64.0;
  double total = 0.0;
  for (int i = -6; i <= 6; ++i)
    for (int j = -6; j <= 6; ++j)
      total += large.covered(Vec<3>(shift + i * side, shift + j * side, 0.0), side);
  EXPECT_NEAR(total, pi * 0.25, 1e-12);
}

// A 3D pressure varying over the wall, p = 1 + 10 x + 3 y: a face narrower than a particle reads
// the column in front of it (x in [0.1, 0.2], y in [-0.3, -0.2]: 1.75).
TEST(WallSensor, ReadsTheColumnInFrontOfASmallFace3D) {
  const Wall<3> wall([](const Vec<3>& x) { return 1.0 + 10.0 * x[0] + 3.0 * x[1]; });
  const WallSensor<3> sensor({Vec<3>(0.13, -0.21, 0.0)}, Vec<3>::Unit(2), 0.02);
  EXPECT_NEAR(sensor.sample(wall.particles, wall.force, 0.35)[0], 1.75, 1e-12);
}

// A concave corner: a side wall behind the plane x = 0 (normal -x, the water at x < 0) meets a
// floor below y = 0 (2D) or z = 0 (3D) that runs under the water (x < 0) and on under the side
// wall (x > 0). The particles under the side wall below the floor's top are behind the side
// wall's plane but not behind its face: the floor's first layer lies in front of them. Whatever
// force along x the water puts on them acts on the face's end, so the face's lowest column takes
// it; columns farther up do not. In 3D the wall extends along y over [-0.5, 0.5].
template <int D>
void check_corner() {
  std::vector<Vec<D>> x, force;
  const double share = D == 2 ? kA : kA * kA;
  const int rows = D == 2 ? 1 : 10;
  for (int k = 0; k < rows; ++k)
    for (int i = -10; i < 3; ++i)      // x = (i + 0.5) a: the floor (i < 0) and the corner (i >= 0)
      for (int j = -3; j < 10; ++j) {  // height (j + 0.5) a
        if (i < 0 && j >= 0) continue;  // the water
        Vec<D> p = Vec<D>::Zero();
        p[0] = (i + 0.5) * kA;
        p[D - 1] = (j + 0.5) * kA;
        if constexpr (D == 3) p[1] = -0.5 + (k + 0.5) * kA;
        x.push_back(p);
        // 1 on each face column's particle, 0.25 along x on each corner particle (and a push
        // down on everything, which a sensor facing -x must not read).
        Vec<D> f = -3.0 * Vec<D>::Unit(D - 1);
        f[0] = i >= 0 && j >= 0 ? 1.0 : i >= 0 ? 0.25 : 0.0;
        force.push_back(share * f);
      }
  ParticleSet<D> wall("wall");
  wall.resize(x.size());
  wall.add_vector("position") = x;
  wall.add_scalar("volume") = std::vector<double>(x.size(), std::pow(kA, D));
  const Vec<D> normal = -Vec<D>::Unit(0);
  const double depth = 0.35;
  auto at = [](double height) {  // a point of the plane x = 0, centred on a column in 3D
    Vec<D> c = Vec<D>::Zero();
    c[D - 1] = height;
    if constexpr (D == 3) c[1] = 0.05;
    return c;
  };
  // The lowest column (height in [0, a]): its three layers (3) and the corner's nine particles
  // within the depth of 0.35 of it (the 3 x 3 block under it: 9 x 0.25).
  EXPECT_NEAR(WallSensor<D>({at(0.5 * kA)}, normal, 0.5 * kA).sample(wall, force, depth)[0],
              3.0 + 9 * 0.25, 1e-12);
  // A column two spacings up reads its own layers only.
  EXPECT_NEAR(WallSensor<D>({at(2.5 * kA)}, normal, 0.5 * kA).sample(wall, force, depth)[0], 3.0,
              1e-12);
  if constexpr (D == 2) {
    // A face over the two lowest columns shares the corner's push between them by area.
    EXPECT_NEAR(WallSensor<2>({at(kA)}, normal, 2 * kA).sample(wall, force, depth)[0],
                (6.0 + 9 * 0.25) / 2.0, 1e-12);
  }
}

TEST(WallSensor, ACornersParticlesPassTheirPushToTheFacesEnd2D) { check_corner<2>(); }
TEST(WallSensor, ACornersParticlesPassTheirPushToTheFacesEnd3D) { check_corner<3>(); }

}  // namespace
}  // namespace cosph
