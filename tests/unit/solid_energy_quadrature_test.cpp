// The dual-cell energy quadrature of the TL-SPH solid (energy_quadrature: dual_cell;
// modules/solid_tlsph/tlsph_operators.hpp): the quadratic fit's curvature coefficients give the
// exact second derivatives of quadratic displacements, the 2D points reproduce a cell's centroid
// and covariance, the stress divergence is the exact gradient of the integrated energy (finite
// differences), the lattice's cell moments are those of the (clipped) cells, and the pure-bending
// energy of a plate on a vertex lattice, 12.5% too large with nodal integration (the trapezoidal
// rule across 5 nodes), becomes exact.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "../support/tlsph_body.hpp"
#include "geometry/lattice.hpp"
#include "geometry/shapes.hpp"
#include "scene.pb.h"
#include "solid_tlsph/material_model.hpp"
#include "solid_tlsph/tlsph_operators.hpp"

namespace cosph {
namespace {

constexpr double kDp = test::kTestSpacing;

template <int D>
ReferencePairs<D> pairs_with_curvature(const test::TlsphBody<D>& b) {
  return build_reference_pairs<D>(b.X, b.V, b.kernel, GradientCorrection::quadratic, false, true);
}

// u_a = sum_b A_ab X_b + X^T H_a X: F = I + A + 2 H_a X per row, dF_ab / dX_c = 2 H_a(b, c).
template <int D>
void check_curvature_exact(double jitter) {
  std::array<int, D> n;
  n.fill(5);
  n[0] = 7;
  test::TlsphBody<D> b = test::make_tlsph_body<D>(test::lattice_box<D>(n, jitter, 3), {},
                                                  GradientCorrection::quadratic, false);
  b.pairs = pairs_with_curvature<D>(b);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> r(-0.1, 0.1);
  Mat<D> A;
  std::array<Mat<D>, D> H;
  for (int a = 0; a < D; ++a)
    for (int c = 0; c < D; ++c) A(a, c) = r(rng);
  for (auto& h : H) {
    Mat<D> M;
    for (int a = 0; a < D; ++a)
      for (int c = 0; c < D; ++c) M(a, c) = r(rng);
    h = M + M.transpose();
  }
  std::vector<Vec<D>> u(b.X.size());
  for (std::size_t i = 0; i < u.size(); ++i) {
    u[i] = A * b.X[i];
    for (int a = 0; a < D; ++a) u[i][a] += b.X[i].dot(H[a] * b.X[i]);
  }
  double worst = 0.0;
  std::size_t checked = 0, zero = 0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const GradientSlopes<D> S = deformation_gradient_slopes<D>(b.pairs, u, i);
    if (!b.pairs.quadratic[i]) {  // the linear correction: no curvature
      for (const auto& s : S) zero += s.norm() == 0.0;
      continue;
    }
    ++checked;
    for (int c = 0; c < D; ++c)
      for (int a = 0; a < D; ++a)
        for (int bb = 0; bb < D; ++bb)
          worst = std::max(worst, std::abs(S[c](a, bb) - 2.0 * H[a](bb, c)));
  }
  std::cout << D << "D jitter " << jitter << ": " << checked
            << " particles with the fit, max |S_c - d2u| = " << worst << "\n";
  EXPECT_GT(checked, u.size() / 3);
  EXPECT_EQ(zero, (u.size() - checked) * D);
  EXPECT_LT(worst, 1e-9);
}

TEST(EnergyQuadrature, CurvatureIsExactForQuadraticDisplacements) {
  for (double jitter : {0.0, 0.15}) {
    check_curvature_exact<2>(jitter);
    check_curvature_exact<3>(jitter);
  }
}

template <int D>
void check_points_reproduce_moments() {
  std::mt19937 rng(D);
  std::uniform_real_distribution<double> r(-1.0, 1.0);
  Vec<D> c;
  Mat<D> M;
  for (int a = 0; a < D; ++a) {
    c[a] = r(rng);
    for (int bb = 0; bb < D; ++bb) M(a, bb) = r(rng);
  }
  const Mat<D> covariance = M * M.transpose() + 0.1 * Mat<D>::Identity();
  const auto points = EnergyQuadrature<D>::points_of(c, covariance);
  Vec<D> mean = Vec<D>::Zero();
  for (const auto& p : points) mean += p / points.size();
  Mat<D> second = Mat<D>::Zero();
  for (const auto& p : points) second += (p - c) * (p - c).transpose() / points.size();
  EXPECT_LT((mean - c).norm(), 1e-14);
  EXPECT_LT((second - covariance).norm(), 1e-13 * covariance.norm());
}

TEST(EnergyQuadrature, PointsReproduceTheCellsCentroidAndCovariance) {
  check_points_reproduce_moments<2>();
  check_points_reproduce_moments<3>();
}

proto::MaterialSpec neo_hookean() {
  proto::MaterialSpec spec;
  spec.set_density(1000.0);
  spec.mutable_neo_hookean()->set_young(1.0);
  spec.mutable_neo_hookean()->set_poisson(0.3);
  return spec;
}

// A jittered body with unequal volumes and random cells (each particle's own centroid and
// covariance), under a large random deformation: V_i times the quadrature's stress divergence
// against central differences of sum_i V_i sum_q w_q Psi(F_iq).
template <int D>
void check_force_is_energy_gradient() {
  std::array<int, D> n;
  n.fill(4);
  n[0] = 6;
  std::mt19937 rng(D + 10);
  std::uniform_real_distribution<double> r(-1.0, 1.0);
  std::vector<double> V;
  const auto X = test::lattice_box<D>(n, 0.15, 9);
  for (std::size_t i = 0; i < X.size(); ++i) V.push_back(std::pow(kDp, D) * (1.0 + 0.2 * r(rng)));
  test::TlsphBody<D> b = test::make_tlsph_body<D>(X, V, GradientCorrection::quadratic, false);
  b.pairs = pairs_with_curvature<D>(b);
  const EnergyQuadrature<D> quadrature = test::random_cells<D>(X.size(), rng);
  const MaterialModel<D> material(neo_hookean(), "material");
  const Mat<D> frame = Mat<D>::Identity();
  std::vector<Vec<D>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    for (int a = 0; a < D; ++a) u[i][a] = 0.1 * X[i][a] * X[i][(a + 1) % D] + 0.02 * kDp * r(rng);

  auto energy = [&](const std::vector<Vec<D>>& w) {
    double sum = 0.0;
    for (std::size_t i = 0; i < X.size(); ++i) {
      const Mat<D> F = deformation_gradient<D>(b.pairs, w, i);
      const GradientSlopes<D> S = deformation_gradient_slopes<D>(b.pairs, w, i);
      for (const Vec<D>& d : quadrature.offset[i]) {
        Mat<D> F_q = F;
        for (int c = 0; c < D; ++c) F_q += d[c] * S[c];
        sum += b.V[i] * material.energy(F_q, frame) / EnergyQuadrature<D>::points;
      }
    }
    return sum;
  };
  std::vector<Mat<D>> P(X.size());
  std::vector<StressMoments<D>> T(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    P[i] = integrate_stress<D>(
        quadrature, i, deformation_gradient<D>(b.pairs, u, i),
        deformation_gradient_slopes<D>(b.pairs, u, i),
        [&](const Mat<D>& F_q) { return material.stress(F_q, frame); }, T[i]);
  double moment_share = 0.0;
  const auto [worst, scale] = test::energy_gradient_mismatch<D>(
      u, energy,
      [&](std::size_t i) {
        const Vec<D> force = b.V[i] * quadrature_stress_divergence<D>(b.pairs, P, T, i);
        moment_share = std::max(moment_share,
                                (force - b.V[i] * pair_stress_divergence<D>(b.pairs, P, i)).norm());
        return force;
      },
      1e-7 * kDp);
  std::cout << D << "D: max |V f + dE/dx| / max |dE/dx| = " << worst / scale
            << ", the moments' share " << moment_share / scale << "\n";
  EXPECT_GT(moment_share, 1e-2 * scale);  // a test the mean stress alone would fail
  EXPECT_LT(worst, 2e-7 * scale);
}

TEST(EnergyQuadrature, StressDivergenceIsTheGradientOfTheIntegratedEnergy) {
  check_force_is_energy_gradient<2>();
  check_force_is_energy_gradient<3>();
}

TEST(EnergyQuadrature, CellMomentsAreThoseOfTheClippedCells) {
  const Box<3> box(Vec<3>(0, 0, 0), Vec<3>(1, 1, 1));
  const double dp = 0.1, full = dp * dp / 12.0, half = 0.25 * full;
  const auto inside = cell_moments<3>(box, Vec<3>(0.5, 0.5, 0.5), dp, LatticePlacement::vertex);
  EXPECT_LT(inside.centroid.norm(), 1e-15);
  EXPECT_LT((inside.covariance - full * Mat<3>::Identity()).norm(), 1e-15);
  // A node on the edge x = 0, z = 0: a quarter cell reaching dp/2 in +x and +z.
  const auto edge = cell_moments<3>(box, Vec<3>(0.0, 0.5, 0.0), dp, LatticePlacement::vertex);
  EXPECT_LT((edge.centroid - Vec<3>(0.25 * dp, 0.0, 0.25 * dp)).norm(), 1e-15);
  EXPECT_LT((edge.covariance - Vec<3>(half, full, half).asDiagonal().toDenseMatrix()).norm(),
            1e-15);
  // Cell placement: the whole cell, wherever the shape's face is.
  const auto cell = cell_moments<3>(box, Vec<3>(0.05, 0.5, 0.5), dp, LatticePlacement::cell);
  EXPECT_EQ(cell.centroid.norm(), 0.0);
  EXPECT_LT((cell.covariance - full * Mat<3>::Identity()).norm(), 1e-15);
}

// Pure bending of a plate 5 nodes thick on a vertex lattice (nu = 0, small strain): u_x = -k x y,
// u_y = k x^2 / 2 about the mid-plane. The energy of the columns away from the ends, with the
// linear-elastic density W(F) = (eps_xx^2 + eps_yy^2) / 2 + eps_xy^2 (E = 1), against the exact
// integral over their dual cells, k^2 t^3 / 24 per unit length.
double vertex_bending_energy_ratio(bool dual_cell) {
  const int layers = 5, columns = 41;
  const double t = (layers - 1) * kDp;
  const Box<2> plate(Vec<2>(0, -0.5 * t), Vec<2>((columns - 1) * kDp, 0.5 * t));
  const ParticleCloud<2> cloud =
      lattice_fill<2>(plate, kDp, Vec<2>(0, -0.5 * t), LatticePlacement::vertex);
  test::TlsphBody<2> b = test::make_tlsph_body<2>(cloud.positions, cloud.volumes,
                                                  GradientCorrection::quadratic, false);
  b.pairs = pairs_with_curvature<2>(b);
  EnergyQuadrature<2> quadrature;
  for (const auto& x : b.X) {
    const auto cell = cell_moments<2>(plate, x, kDp, LatticePlacement::vertex);
    quadrature.offset.push_back(EnergyQuadrature<2>::points_of(cell.centroid, cell.covariance));
  }
  const double k = 1e-3;
  std::vector<Vec<2>> u(b.X.size());
  for (std::size_t i = 0; i < u.size(); ++i)
    u[i] = Vec<2>(-k * b.X[i][0] * b.X[i][1], 0.5 * k * b.X[i][0] * b.X[i][0]);
  auto W = [](const Mat<2>& F) {
    const Mat<2> e = 0.5 * (F + F.transpose()) - Mat<2>::Identity();
    return 0.5 * (e(0, 0) * e(0, 0) + e(1, 1) * e(1, 1)) + e(0, 1) * e(0, 1);
  };
  double discrete = 0.0;
  int interior_columns = 0;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const double x = b.X[i][0];
    if (x < 0.5 * columns * kDp - 10 * kDp || x > 0.5 * columns * kDp + 10 * kDp) continue;
    if (b.X[i][1] < -0.49 * t) ++interior_columns;
    const Mat<2> F = deformation_gradient<2>(b.pairs, u, i);
    if (!dual_cell) {
      discrete += b.V[i] * W(F);
      continue;
    }
    const GradientSlopes<2> S = deformation_gradient_slopes<2>(b.pairs, u, i);
    for (const Vec<2>& d : quadrature.offset[i])
      discrete += b.V[i] * W(F + d[0] * S[0] + d[1] * S[1]) / EnergyQuadrature<2>::points;
  }
  const double exact = interior_columns * kDp * k * k * t * t * t / 24.0;
  return discrete / exact;
}

TEST(EnergyQuadrature, BendingEnergyOnAVertexLatticeIsExactOverTheDualCells) {
  const double nodal = vertex_bending_energy_ratio(false);
  const double dual = vertex_bending_energy_ratio(true);
  std::cout << "plate 5 nodes thick, discrete / exact bending energy: nodal " << nodal
            << ", dual cells " << dual << "\n";
  // The trapezoidal rule across the thickness: 1 + 2 (dp / t)^2 = 1.125.
  EXPECT_NEAR(nodal, 1.125, 1e-6);
  EXPECT_NEAR(dual, 1.0, 1e-6);
}

}  // namespace
}  // namespace cosph
