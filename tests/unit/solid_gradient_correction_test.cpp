// The quadratic gradient correction of the TL-SPH solid (modules/solid_tlsph/tlsph_operators):
// F is exact for quadratic displacements wherever it applies (and the linear correction is not,
// next to surfaces); inside a regular lattice it is the linear one; a body two particles thick
// keeps the linear one; the stress divergence is the exact gradient of the discrete strain
// energy (finite differences); and the pure-bending energy of a plate five particles thick, 79%
// of the true one with the linear correction, becomes exact.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <random>
#include <vector>

#include "../support/tlsph_body.hpp"
#include "kernels/kernel.hpp"
#include "scene.pb.h"
#include "solid_tlsph/material_model.hpp"
#include "solid_tlsph/tlsph_operators.hpp"

namespace cosph {
namespace {

constexpr double kDp = test::kTestSpacing;

// A lattice size: n2 in 2D, n3 in 3D.
template <int D>
std::array<int, D> size_of(std::array<int, 2> n2, std::array<int, 3> n3) {
  std::array<int, D> n;
  for (int a = 0; a < D; ++a) n[a] = D == 2 ? n2[a] : n3[a];
  return n;
}

template <int D>
std::vector<Vec<D>> box(const std::array<int, D>& n, double jitter, unsigned seed) {
  return test::lattice_box<D>(n, jitter, seed);
}

// A body of dp^D volumes with the given correction.
template <int D>
struct Body : test::TlsphBody<D> {
  Body(std::vector<Vec<D>> positions, GradientCorrection correction)
      : test::TlsphBody<D>(test::make_tlsph_body<D>(std::move(positions), {}, correction, false)) {}
};

// A quadratic displacement u_a = sum_b A_ab X_b + sum_bc H_abc X_b X_c and its gradient.
template <int D>
struct Quadratic {
  Mat<D> A;
  std::array<Mat<D>, D> H;  // H[a] symmetric
  Vec<D> at(const Vec<D>& X) const {
    Vec<D> u = A * X;
    for (int a = 0; a < D; ++a) u[a] += X.dot(H[a] * X);
    return u;
  }
  Mat<D> gradient(const Vec<D>& X) const {
    Mat<D> G = A;
    for (int a = 0; a < D; ++a) G.row(a) += 2.0 * (H[a] * X).transpose();
    return G;
  }
};

template <int D>
Quadratic<D> random_quadratic(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.1, 0.1);
  Quadratic<D> q;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) q.A(a, b) = u(rng);
  for (int a = 0; a < D; ++a) {
    Mat<D> M;
    for (int b = 0; b < D; ++b)
      for (int c = 0; c < D; ++c) M(b, c) = u(rng);
    q.H[a] = 0.5 * (M + M.transpose());
  }
  return q;
}

// Largest |F_i - (I + grad u)| over the particles with the quadratic correction (all of them
// for the linear correction's body).
template <int D>
double worst_gradient_error(const Body<D>& b, const Quadratic<D>& q) {
  const bool only_quadratic = b.pairs.quadratic_particles() > 0;
  std::vector<Vec<D>> u(b.X.size());
  for (std::size_t i = 0; i < u.size(); ++i) u[i] = q.at(b.X[i]);
  std::vector<Mat<D>> F(u.size());
  deformation_gradients<D>(b.pairs, u, F);
  double worst = 0.0;
  for (std::size_t i = 0; i < u.size(); ++i)
    if (!only_quadratic || b.pairs.quadratic[i])
      worst = std::max(worst, (F[i] - Mat<D>::Identity() - q.gradient(b.X[i])).norm());
  return worst;
}

// How many lattice faces particle k of an n[0] x n[1] (x n[2]) box lies on.
template <int D>
int faces_of(const std::array<int, D>& n, int k) {
  int faces = 0;
  for (int a = 0; a < D; ++a) {
    const int index = k % n[a];
    faces += index == 0 || index == n[a] - 1;
    k /= n[a];
  }
  return faces;
}

template <int D>
void check_quadratic_exact() {
  const std::array<int, D> n = size_of<D>({10, 6}, {6, 5, 4});
  for (double jitter : {0.0, 0.15}) {
    const Body<D> quadratic(box<D>(n, jitter, 7), GradientCorrection::quadratic);
    const Body<D> linear(box<D>(n, jitter, 7), GradientCorrection::linear);
    // Inside and on faces the quadratic correction holds; on edges and corners (two or more
    // faces) the fit would stiffen the operator more than it gains, and the linear one stays.
    // Jittered, the stiffening of a face particle's fit overlaps an edge's or a corner's: there
    // only the inside is certain.
    const bool classified = jitter == 0.0;
    for (std::size_t k = 0; k < quadratic.X.size(); ++k) {
      const int faces = faces_of<D>(n, int(k));
      if (faces == 0 || (classified && faces == 1)) {
        EXPECT_TRUE(quadratic.pairs.quadratic[k]) << "particle " << k << " on " << faces;
      } else if (classified) {
        EXPECT_FALSE(quadratic.pairs.quadratic[k]) << "particle " << k << " on " << faces;
      }
    }
    const Quadratic<D> q = random_quadratic<D>(11);
    const double e_quadratic = worst_gradient_error(quadratic, q);
    const double e_linear = worst_gradient_error(linear, q);
    std::cout << D << "D jitter " << jitter << ": max |F - (I + grad u)| quadratic " << e_quadratic
              << ", linear " << e_linear << "\n";
    EXPECT_LT(e_quadratic, 1e-10);
    EXPECT_GT(e_linear, 1e-3) << "the linear correction is not exact for quadratic fields";
  }
}

TEST(QuadraticCorrection, DeformationGradientExactForQuadraticDisplacements2D) {
  check_quadratic_exact<2>();
}
TEST(QuadraticCorrection, DeformationGradientExactForQuadraticDisplacements3D) {
  check_quadratic_exact<3>();
}

TEST(QuadraticCorrection, InsideARegularLatticeItIsTheLinearCorrection) {
  const Body<2> quadratic(box<2>({12, 12}, 0.0, 1), GradientCorrection::quadratic);
  const Body<2> linear(box<2>({12, 12}, 0.0, 1), GradientCorrection::linear);
  // Particle (6, 6) is more than a support (2.6 dp) from every surface.
  const std::size_t i = 6 + 12 * 6;
  double worst = 0.0, scale = 0.0;
  for (std::size_t k = linear.pairs.neighbours.offset[i]; k < linear.pairs.neighbours.offset[i + 1];
       ++k) {
    worst = std::max(worst, (quadratic.pairs.gradient[k] - linear.pairs.gradient[k]).norm());
    scale = std::max(scale, linear.pairs.gradient[k].norm());
  }
  EXPECT_LT(worst, 1e-12 * scale);
  // Next to a surface the two differ: particle (6, 0).
  const std::size_t s = 6;
  double differ = 0.0;
  for (std::size_t k = linear.pairs.neighbours.offset[s]; k < linear.pairs.neighbours.offset[s + 1];
       ++k)
    differ = std::max(differ, (quadratic.pairs.gradient[k] - linear.pairs.gradient[k]).norm());
  EXPECT_GT(differ, 1e-2 * scale);
}

TEST(QuadraticCorrection, ABodyTwoParticlesThickKeepsTheLinearCorrection) {
  const Body<2> thin(box<2>({12, 2}, 0.0, 1), GradientCorrection::quadratic);
  const Body<2> linear(box<2>({12, 2}, 0.0, 1), GradientCorrection::linear);
  EXPECT_EQ(thin.pairs.quadratic_particles(), 0u);
  for (std::size_t k = 0; k < thin.pairs.gradient.size(); ++k)
    ASSERT_EQ(thin.pairs.gradient[k], linear.pairs.gradient[k]);
}

// The discrete strain energy sum_i V_i W(F_i) and the stress divergence: V_i rho0 a_i must be
// -dE/dx_i (central differences), for both corrections.
template <int D>
void check_force_is_energy_gradient(GradientCorrection correction) {
  const std::array<int, D> n = size_of<D>({7, 5}, {5, 4, 4});
  const Body<D> b(box<D>(n, 0.1, 3), correction);
  proto::MaterialSpec spec;
  spec.set_density(1000.0);
  spec.mutable_neo_hookean()->set_young(1e6);
  spec.mutable_neo_hookean()->set_poisson(0.3);
  const MaterialModel<D> m(spec, "material");
  const std::size_t count = b.X.size();
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> jitter(-0.05 * kDp, 0.05 * kDp);
  std::vector<Vec<D>> u(count);
  for (auto& ui : u)
    for (int a = 0; a < D; ++a) ui[a] = jitter(rng);
  auto energy = [&](const std::vector<Vec<D>>& displacement) {
    std::vector<Mat<D>> F(count);
    deformation_gradients<D>(b.pairs, displacement, F);
    double E = 0.0;
    for (std::size_t i = 0; i < count; ++i) E += b.V[i] * m.energy(F[i], Mat<D>::Identity());
    return E;
  };
  std::vector<Mat<D>> F(count), P(count);
  deformation_gradients<D>(b.pairs, u, F);
  for (std::size_t i = 0; i < count; ++i) P[i] = m.stress(F[i], Mat<D>::Identity());
  const auto [worst, scale] = test::energy_gradient_mismatch<D>(
      u, energy,
      [&](std::size_t i) { return Vec<D>(b.V[i] * pair_stress_divergence<D>(b.pairs, P, i)); },
      1e-7 * kDp);
  std::cout << D << "D " << (correction == GradientCorrection::quadratic ? "quadratic" : "linear")
            << ": max |V f + dE/dx| / max |dE/dx| " << worst / scale << "\n";
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(
      worst,
      2e-7 * scale);  // measured 5e-8 (linear) and 6e-9 (quadratic) in 2D, 8e-8 and 2e-8 in 3D
}

TEST(QuadraticCorrection, StressDivergenceIsTheEnergyGradient) {
  for (auto c : {GradientCorrection::linear, GradientCorrection::quadratic}) {
    check_force_is_energy_gradient<2>(c);
    check_force_is_energy_gradient<3>(c);
  }
}

// Pure bending of a plate 5 particles thick (nu = 0, small strain): u_x = -k x y, u_y = k x^2 / 2
// about the mid-plane. The discrete energy of the columns away from the ends, against the exact
// energy density E k^2 y^2 / 2 summed over the same particles.
double bending_energy_ratio(GradientCorrection correction) {
  const int layers = 5, columns = 40;
  std::vector<Vec<2>> X = box<2>({columns, layers}, 0.0, 1);
  for (auto& x : X) x[1] -= 0.5 * layers * kDp;  // mid-plane at y = 0
  const Body<2> b(X, correction);
  const double k = 1e-3;
  std::vector<Vec<2>> u(X.size());
  for (std::size_t i = 0; i < X.size(); ++i)
    u[i] = Vec<2>(-k * X[i][0] * X[i][1], 0.5 * k * X[i][0] * X[i][0]);
  std::vector<Mat<2>> F(X.size());
  deformation_gradients<2>(b.pairs, u, F);
  double discrete = 0.0, exact = 0.0;
  for (std::size_t i = 0; i < X.size(); ++i) {
    if (X[i][0] < 1.5 || X[i][0] > columns * kDp - 1.5) continue;  // away from the ends
    const Mat<2> eps = 0.5 * (F[i] + F[i].transpose()) - Mat<2>::Identity();
    // nu = 0: W = E/2 (eps_xx^2 + eps_yy^2) + E eps_xy^2 (G = E/2); E = 1.
    discrete += 0.5 * (eps(0, 0) * eps(0, 0) + eps(1, 1) * eps(1, 1)) + eps(0, 1) * eps(0, 1);
    exact += 0.5 * (k * X[i][1]) * (k * X[i][1]);
  }
  return discrete / exact;
}

TEST(QuadraticCorrection, BendingEnergyOfAThinPlateIsExact) {
  const double linear = bending_energy_ratio(GradientCorrection::linear);
  const double quadratic = bending_energy_ratio(GradientCorrection::quadratic);
  std::cout << "plate 5 particles thick, discrete / exact bending energy: linear " << linear
            << ", quadratic " << quadratic << "\n";
  // Measured 0.794 (linear): the plate is a fifth too soft in bending.
  EXPECT_GT(linear, 0.78);
  EXPECT_LT(linear, 0.81);
  EXPECT_NEAR(quadratic, 1.0, 1e-6);
}

}  // namespace
}  // namespace cosph
