// Hyperelastic laws: every stress is the derivative of its strain energy (central finite
// differences at random deformation gradients), objective (frame invariant), and zero at F = I.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <functional>
#include <random>

#include "solid_tlsph/materials.hpp"

namespace cosph {
namespace {

template <int D>
Mat<D> random_deformation(std::mt19937& rng, double amplitude) {
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Mat<D> F = Mat<D>::Identity();
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) F(i, j) += u(rng);
  return F;
}

template <int D>
Mat<D> random_rotation(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  if constexpr (D == 2) {
    const double a = u(rng);
    Mat<2> R;
    R << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    return R;
  } else {
    return Eigen::AngleAxisd(u(rng), Vec<3>(u(rng), u(rng), u(rng)).normalized())
        .toRotationMatrix();
  }
}

// Central difference of W with respect to each entry of F, compared with P.
template <int D>
void expect_stress_is_energy_derivative(const std::function<double(const Mat<D>&)>& W,
                                        const std::function<Mat<D>(const Mat<D>&)>& P,
                                        const Mat<D>& F, double tolerance) {
  const double h = 1e-6;
  const Mat<D> stress = P(F);
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) {
      Mat<D> plus = F, minus = F;
      plus(i, j) += h;
      minus(i, j) -= h;
      const double fd = (W(plus) - W(minus)) / (2.0 * h);
      EXPECT_NEAR(stress(i, j), fd, tolerance * (1.0 + std::abs(fd)))
          << "entry " << i << j << "\nF =\n"
          << F;
    }
}

template <int D>
void check_law(const std::function<double(const Mat<D>&)>& W,
               const std::function<Mat<D>(const Mat<D>&)>& P, double tolerance) {
  std::mt19937 rng(11 + D);
  EXPECT_LT(P(Mat<D>::Identity()).norm(), 1e-10) << "reference state must be stress-free";
  EXPECT_NEAR(W(Mat<D>::Identity()), 0.0, 1e-12);
  for (int k = 0; k < 20; ++k) {
    const Mat<D> F = random_deformation<D>(rng, 0.25);
    ASSERT_GT(F.determinant(), 0.0);
    expect_stress_is_energy_derivative<D>(W, P, F, tolerance);
    // Objectivity: W(QF) = W(F), P(QF) = Q P(F).
    const Mat<D> Q = random_rotation<D>(rng);
    EXPECT_NEAR(W(Q * F), W(F), 1e-9 * (1.0 + std::abs(W(F))));
    EXPECT_LT((P(Q * F) - Q * P(F)).norm(), 1e-9 * (1.0 + P(F).norm()));
  }
}

TEST(SolidMaterials, LameParametersFollowTheCorrectedRelations) {
  const LameParameters p = lame_from_young_poisson(2e6, 0.3975);
  EXPECT_NEAR(2.0 * p.mu * (1.0 + 0.3975), 2e6, 1e-6);
  EXPECT_NEAR(3.0 * p.bulk * (1.0 - 2.0 * 0.3975), 2e6, 1e-6);  // E = 3K(1 - 2 nu), not (1 + 2 nu)
  EXPECT_NEAR(p.lambda, p.bulk - 2.0 * p.mu / 3.0, 1e-6);
  EXPECT_THROW(lame_from_young_poisson(1.0, 0.5), std::invalid_argument);
  EXPECT_THROW(lame_from_young_poisson(1.0, -1.0), std::invalid_argument);
  EXPECT_THROW(lame_from_young_poisson(-1.0, 0.3), std::invalid_argument);
  EXPECT_NO_THROW(lame_from_young_poisson(1.0, 0.495));
}

TEST(SolidMaterials, StVenantKirchhoffStressIsEnergyDerivative) {
  const LameParameters p = lame_from_young_poisson(1.7e7, 0.45);
  check_law<2>([&](const Mat<2>& F) { return svk_energy<2>(p, F); },
               [&](const Mat<2>& F) { return svk_stress<2>(p, F); }, 1e-6);
  check_law<3>([&](const Mat<3>& F) { return svk_energy<3>(p, F); },
               [&](const Mat<3>& F) { return svk_stress<3>(p, F); }, 1e-6);
}

TEST(SolidMaterials, NeoHookeanStressIsEnergyDerivative) {
  const LameParameters p = lame_from_young_poisson(2e6, 0.495);  // near-incompressible
  check_law<2>([&](const Mat<2>& F) { return neo_hookean_energy<2>(p, F); },
               [&](const Mat<2>& F) { return neo_hookean_stress<2>(p, F); }, 1e-6);
  check_law<3>([&](const Mat<3>& F) { return neo_hookean_energy<3>(p, F); },
               [&](const Mat<3>& F) { return neo_hookean_stress<3>(p, F); }, 1e-6);
}

TEST(SolidMaterials, HolzapfelOgdenStressIsEnergyDerivative) {
  // Garcia-Blanco et al. parameters (kPa), seed 001 table 4, and a bulk modulus for the penalty.
  const HolzapfelOgdenParameters p{0.059, 8.023, 18.472, 16.026, 2.841,
                                   11.12, 0.216, 11.436, 100.0};
  const Vec<3> f0 = Vec<3>(1.0, 0.2, 0.1).normalized();
  const Vec<3> s0 = (Vec<3>(0.0, 1.0, 0.0) - f0.dot(Vec<3>(0.0, 1.0, 0.0)) * f0).normalized();
  std::mt19937 rng(5);
  for (int k = 0; k < 20; ++k) {
    const Mat<3> F = random_deformation<3>(rng, 0.15);
    expect_stress_is_energy_derivative<3>(
        [&](const Mat<3>& G) { return holzapfel_ogden_energy<3>(p, G, f0, s0); },
        [&](const Mat<3>& G) { return holzapfel_ogden_stress<3>(p, G, f0, s0); }, F, 1e-5);
    // Objectivity with the fibres attached to the material (reference frame): W(QF) = W(F).
    const Mat<3> Q = random_rotation<3>(rng);
    EXPECT_NEAR(holzapfel_ogden_energy<3>(p, Q * F, f0, s0),
                holzapfel_ogden_energy<3>(p, F, f0, s0), 1e-9);
  }
  EXPECT_LT(holzapfel_ogden_stress<3>(p, Mat<3>::Identity(), f0, s0).norm(), 1e-12);
  // 2D (plane strain) too.
  const Vec<2> f2(1.0, 0.0), s2(0.0, 1.0);
  for (int k = 0; k < 10; ++k) {
    const Mat<2> F = random_deformation<2>(rng, 0.15);
    expect_stress_is_energy_derivative<2>(
        [&](const Mat<2>& G) { return holzapfel_ogden_energy<2>(p, G, f2, s2); },
        [&](const Mat<2>& G) { return holzapfel_ogden_stress<2>(p, G, f2, s2); }, F, 1e-5);
  }
}

TEST(SolidMaterials, GuccioneStressIsEnergyDerivativeInARotatedFibreFrame) {
  // Land et al. (2015) problem 1: C = 2 kPa, bf = 8, bt = 2, bfs = 4, and a penalty bulk modulus.
  const GuccioneParameters p{2.0, 8.0, 2.0, 4.0, 50.0};
  std::mt19937 rng(9);
  const Mat<3> frame = random_rotation<3>(rng);  // columns: fibre, sheet, normal
  check_law<3>([&](const Mat<3>& F) { return guccione_energy(p, F, frame); },
               [&](const Mat<3>& F) { return guccione_stress(p, F, frame); }, 1e-5);
  // Fibre stretch costs more than the same cross-fibre stretch (bf > bt).
  Mat<3> along = Mat<3>::Identity() + 0.1 * frame.col(0) * frame.col(0).transpose();
  Mat<3> across = Mat<3>::Identity() + 0.1 * frame.col(1) * frame.col(1).transpose();
  EXPECT_GT(guccione_energy(p, along, frame), guccione_energy(p, across, frame));
}

}  // namespace
}  // namespace cosph
