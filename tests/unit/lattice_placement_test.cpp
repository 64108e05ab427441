// Vertex placement of lattice particles (framework/geometry/lattice.cpp), the finite-element
// grid's nodes that seed 000 uses: the counts of its beam, the fractional volumes of face, edge
// and corner particles that sum to the shape's volume, robustness to a spacing that is not a
// binary fraction, the surface a vertex body presents, and the pressure load's face areas.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <numbers>
#include <string>

#include "../support/simulation_setup.hpp"
#include "geometry/lattice.hpp"
#include "geometry/shapes.hpp"
#include "geometry/surface.hpp"

namespace cosph {
namespace {

template <int D>
double total_volume(const ParticleCloud<D>& cloud) {
  double v = 0.0;
  for (double x : cloud.volumes) v += x;
  return v;
}

// Seed 000's beam, 10 x 1 x 1 mm at 0.25 mm: 41 x 5 x 5 = 1,025 particles (its table 1), with
// the faces, edges and corners carrying 1/2, 1/4 and 1/8 of a cell.
TEST(VertexLattice, LandBeamHasTheSeedsCountsAndTheBoxsVolume) {
  const double dp = 0.25;
  const Box<3> beam(Vec<3>(0, 0, 0), Vec<3>(10, 1, 1));
  const auto cloud = lattice_fill<3>(beam, dp, Vec<3>::Zero(), LatticePlacement::vertex);
  ASSERT_EQ(cloud.positions.size(), 1025u);
  EXPECT_NEAR(total_volume(cloud), 10.0, 1e-12);
  std::map<int, int> by_boundary_axes;  // how many axes a particle is on the boundary of
  for (std::size_t i = 0; i < cloud.positions.size(); ++i) {
    const Vec<3>& x = cloud.positions[i];
    int on = 0;
    for (int a = 0; a < 3; ++a) on += x[a] == 0.0 || x[a] == beam.upper()[a];
    ++by_boundary_axes[on];
    EXPECT_EQ(cloud.volumes[i], std::pow(dp, 3) / std::pow(2.0, on)) << x.transpose();
  }
  EXPECT_EQ(by_boundary_axes[0], 39 * 3 * 3);  // interior
  EXPECT_EQ(by_boundary_axes[3], 8);           // corners
  EXPECT_EQ(by_boundary_axes[2], 4 * 39 + 8 * 3);
  // The cell placement of the same box: 40 x 4 x 4, none on the faces.
  EXPECT_EQ(lattice_fill<3>(beam, dp).positions.size(), 640u);
}

// A spacing that binary floating point cannot hold (0.1): the nodes on the far faces round to
// either side of them and must all be kept, with exact halves and quarters.
TEST(VertexLattice, FacesAreKeptWhenTheSpacingIsNotABinaryFraction) {
  const Box<2> box(Vec<2>(0, 0), Vec<2>(0.7, 0.3));
  const auto cloud = lattice_fill<2>(box, 0.1, Vec<2>::Zero(), LatticePlacement::vertex);
  EXPECT_EQ(cloud.positions.size(), 8u * 4u);
  EXPECT_NEAR(total_volume(cloud), 0.21, 1e-15);
  // An anchor off the box's corner: the faces fall halfway between nodes, the outer nodes'
  // dual cells are cut in half the other way, and the volume is still exact.
  const auto shifted = lattice_fill<2>(box, 0.1, Vec<2>(0.05, 0.05), LatticePlacement::vertex);
  EXPECT_EQ(shifted.positions.size(), 7u * 3u);
  EXPECT_NEAR(total_volume(shifted), 0.21, 1e-15);
}

// A curved boundary: the nodes inside carry the parts of their dual cells inside the disc; the
// slivers of the dual cells of nodes just outside are lost, so the area converges at first order
// from below. Measured relative errors 0.0184 (spacing 0.1) and 0.00220 (0.01); bounds at 1.5x.
TEST(VertexLattice, DiscAreaFromDualCellFractions) {
  const Ellipsoid<2> disc(Vec<2>(0.0123, -0.0456), Vec<2>(1, 1));
  auto error = [&](double dp) {
    const auto cloud = lattice_fill<2>(disc, dp, Vec<2>::Zero(), LatticePlacement::vertex);
    return std::abs(total_volume(cloud) / std::numbers::pi - 1.0);
  };
  const double coarse = error(0.1), fine = error(0.01);
  std::cout << "vertex disc area relative error: " << coarse << " (0.1), " << fine << " (0.01)\n";
  EXPECT_LT(coarse, 1.5 * 0.0184);
  EXPECT_LT(fine, 1.5 * 0.00220);
  EXPECT_LT(fine, coarse);
}

// The surface a vertex body presents is its outermost layer of nodes, the half-volume ones
// included, with the faces' axis normals away from the edges.
TEST(VertexLattice, SurfaceIsTheOutermostLayerOfNodes) {
  const Box<2> box(Vec<2>(0, 0), Vec<2>(1.2, 1.2));
  const double dp = 0.1;
  const auto cloud = lattice_fill<2>(box, dp, Vec<2>::Zero(), LatticePlacement::vertex);
  ASSERT_EQ(cloud.positions.size(), 13u * 13u);
  const Surface<2> s = detect_surface<2>(cloud.positions, cloud.volumes, dp);
  EXPECT_EQ(s.particles.size(), 13u * 13u - 11u * 11u);
  for (std::size_t m = 0; m < s.particles.size(); ++m) {
    const Vec<2>& x = cloud.positions[s.particles[m]];
    const bool outer = std::abs(x[0]) < 1e-9 || std::abs(x[0] - 1.2) < 1e-9 ||
                       std::abs(x[1]) < 1e-9 || std::abs(x[1] - 1.2) < 1e-9;
    EXPECT_TRUE(outer) << x.transpose();
    if (std::abs(x[1]) < 1e-9 && x[0] > 0.55 && x[0] < 0.65) {  // mid-face, bottom
      EXPECT_LT((s.normals[m] - Vec<2>(0, -1)).norm(), 1e-3) << s.normals[m].transpose();
    }
  }
}

// The pressure load's areas on a vertex lattice: a free cube with a pressure on its bottom face
// only. Internal forces conserve momentum, so at the start (F = I) the total force is p A along
// +z with A the face's area: the face nodes' areas V / depth must sum to it. One step (end time
// below the stable step), so that F = I holds to round-off. Returns momentum / (p A t).
Vec<3> pressure_impulse_over_p_a_t(const std::string& anchor, double lattice_area) {
  const double rho = 1000.0;
  const std::string text = R"yaml(
dimension: 3
end_time: 2e-4
modules:
  - name: cube
    solid:
      body:
        spacing: 0.1
        placement: vertex
        lattice_anchor: )yaml" +
                           anchor + R"yaml(
        shape: {box: {lower: [0, 0, 0], upper: [1.2, 1.2, 1.2]}}
      material: {density: 1000, neo_hookean: {young: 1.0e5, poisson: 0.3}}
      pressures:
        - region: {name: bottom, shape: {box: {lower: [-1, -1, -1], upper: [2, 2, 0.04]}}}
          value: "1"
          normal: [0, 0, -1]
)yaml";
  auto s = test::make_simulation(text);
  const RunSummary summary = s->run();
  const auto& particles = test::particles_of<3>(*s);
  Vec<3> momentum = Vec<3>::Zero();
  for (std::size_t i = 0; i < particles.size(); ++i)
    momentum += rho * particles.scalar("volume")[i] * particles.vector("velocity")[i];
  const double impulse = lattice_area * summary.end_time;
  std::cout << "vertex cube, anchor " << anchor << ": momentum z " << momentum[2]
            << " against p A t = " << impulse << " (" << summary.steps << " steps)\n";
  return momentum / impulse;
}

// Anchor on the cube's corner: 13 x 13 face nodes carry dp^2 inside the face, dp^2 / 2 on its
// edges, dp^2 / 4 at its corners (V / (dp / 2)), summing to A = 1.2^2 = 1.44. With V / dp, the
// cell placement's rule, they would sum to 0.72.
TEST(VertexLattice, PressureOnAFaceOfVertexParticlesPushesWithPTimesTheFaceArea) {
  const Vec<3> ratio = pressure_impulse_over_p_a_t("[0, 0, 0]", 1.44);
  EXPECT_NEAR(ratio[2], 1.0, 1e-6);
  EXPECT_NEAR(ratio[0], 0.0, 1e-9);
  EXPECT_NEAR(ratio[1], 0.0, 1e-9);
}

// Anchor a quarter spacing off the corner: the nodes sit at 0.025 + 0.1 k, so the bottom face
// lies a quarter spacing below the first layer, whose dual cells reach 3/4 of a spacing into the
// body. Their areas are V / (3 dp / 4); the rule V / (dp / 2) would give 1.5 times the face. The
// lattice's dual cells cover 0.075 + 11 x 0.1 = 1.175 of each side (the far 0.025, beyond the
// last node's cell, belongs to no node, the vertex placement's first-order loss on a face off the
// lattice), so the face carries A = 1.175^2.
TEST(VertexLattice, PressureAreasFollowTheDualCellsDepthWhenTheFaceIsBetweenNodes) {
  const Vec<3> ratio = pressure_impulse_over_p_a_t("[0.025, 0.025, 0.025]", 1.175 * 1.175);
  EXPECT_NEAR(ratio[2], 1.0, 1e-6);
  EXPECT_NEAR(ratio[0], 0.0, 1e-9);
  EXPECT_NEAR(ratio[1], 0.0, 1e-9);
}

// The depth of a dual cell along a direction, for the face areas: a node on a face has half its
// dual cell inside along the face's normal, a node a quarter spacing inside has three quarters,
// an interior node all of it; along an axis parallel to the face the node's whole segment is in.
TEST(VertexLattice, DualCellDepthAlongTheNormal) {
  const Box<3> box(Vec<3>(0, 0, 0), Vec<3>(1, 1, 1));
  const Vec<3> down(0, 0, -1), along(1, 0, 0);
  EXPECT_DOUBLE_EQ(dual_cell_depth<3>(box, Vec<3>(0.5, 0.5, 0.0), down, 0.1), 0.05);
  EXPECT_DOUBLE_EQ(dual_cell_depth<3>(box, Vec<3>(0.5, 0.5, 0.025), down, 0.1), 0.075);
  EXPECT_DOUBLE_EQ(dual_cell_depth<3>(box, Vec<3>(0.5, 0.5, 0.5), down, 0.1), 0.1);
  EXPECT_DOUBLE_EQ(dual_cell_depth<3>(box, Vec<3>(0.5, 0.5, 0.0), along, 0.1), 0.1);
  EXPECT_DOUBLE_EQ(dual_cell_depth<3>(box, Vec<3>(0.5, 0.5, 1.2), down, 0.1), 0.0);
}

}  // namespace
}  // namespace cosph
