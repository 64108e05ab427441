// The fit-residual hourglass control (modules/solid_tlsph/fit_residual_control.hpp): zero energy
// for the fields the gradient fits reproduce, the force as the exact energy gradient, the
// constant stiffness as the force's exact derivative, and a wandering particle that the
// deformation gradients cannot see costs energy.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "../support/tlsph_body.hpp"
#include "solid_tlsph/fit_residual_control.hpp"

namespace cosph {
namespace {

using test::kTestSpacing;

template <int D>
test::TlsphBody<D> jittered_body(GradientCorrection correction) {
  std::array<int, D> n;
  if constexpr (D == 2)
    n = {9, 7};
  else
    n = {6, 5, 5};
  return test::make_tlsph_body<D>(test::lattice_box<D>(n, 0.15, 3), {}, correction, false);
}

template <int D>
double energy_of(FitResidualControl<D>& control, const std::vector<Vec<D>>& u) {
  control.update_residuals(u);
  return control.energy();
}

// Fields the fit reproduces: an affine map with a finite rotation everywhere; a quadratic one at
// the particles whose fit is quadratic (the others' residual is the quadratic's, small).
template <int D>
void check_reproduced_fields_cost_nothing() {
  auto body = jittered_body<D>(GradientCorrection::quadratic);
  FitResidualControl<D> control(body.X, body.V, body.pairs, body.kernel, 1.0);
  Mat<D> R = Mat<D>::Identity();
  if constexpr (D == 2)
    R = Eigen::Rotation2D<double>(1.1).toRotationMatrix();
  else
    R = Eigen::AngleAxisd(1.1, Vec<3>(1, 2, 3).normalized()).toRotationMatrix();
  Mat<D> G;
  G.setRandom();
  std::vector<Vec<D>> rotated(body.X.size()), random(body.X.size());
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 0.01 * kTestSpacing);
  for (std::size_t i = 0; i < body.X.size(); ++i) {
    rotated[i] = (R * (Mat<D>::Identity() + 0.1 * G) - Mat<D>::Identity()) * body.X[i];
    for (int a = 0; a < D; ++a) random[i][a] = normal(rng);
  }
  const double noise = energy_of(control, random);
  const double affine = energy_of(control, rotated);
  EXPECT_GT(noise, 0.0);
  // Round-off only: the rotated field moves particles by about the body's size, the noise by a
  // hundredth of a spacing.
  EXPECT_LT(affine, 1e-18 * noise) << D << "D: rotation and stretch cost " << affine;

  // A quadratic field: zero residual at every particle with the quadratic fit.
  std::vector<Vec<D>> quadratic(body.X.size());
  for (std::size_t i = 0; i < body.X.size(); ++i) {
    quadratic[i] = Vec<D>::Zero();
    quadratic[i][0] = body.X[i][1] * body.X[i][1] + 0.5 * body.X[i][0] * body.X[i][D - 1];
    quadratic[i][1] = -body.X[i][0] * body.X[i][0];
  }
  auto linear_only = body;  // the same particles with the linear fit everywhere
  linear_only.pairs =
      build_reference_pairs<D>(body.X, body.V, body.kernel, GradientCorrection::linear, false);
  FitResidualControl<D> linear_control(linear_only.X, linear_only.V, linear_only.pairs,
                                       linear_only.kernel, 1.0);
  const double with_quadratic_fits = energy_of(control, quadratic);
  const double with_linear_fits = energy_of(linear_control, quadratic);
  // Only the particles that kept the linear fit (edges, corners) pay with the quadratic
  // correction: measured 0.043 (2D) and 0.211 (3D) of what the linear fits pay everywhere.
  EXPECT_GT(with_linear_fits, 0.0);
  EXPECT_LT(with_quadratic_fits, (D == 2 ? 0.065 : 0.32) * with_linear_fits)
      << D << "D: " << with_quadratic_fits << " against " << with_linear_fits;
  EXPECT_GT(with_quadratic_fits, (D == 2 ? 0.029 : 0.14) * with_linear_fits);
}

TEST(FitResidualControl, FieldsTheFitsReproduceCostNothing) {
  check_reproduced_fields_cost_nothing<2>();
  check_reproduced_fields_cost_nothing<3>();
}

// The force on every particle against central differences of the energy, and K u = -f for the
// stiffness the steady solver assembles (E is quadratic: f = -K u exactly).
template <int D>
void check_force_and_stiffness(GradientCorrection correction) {
  auto body = jittered_body<D>(correction);
  FitResidualControl<D> control(body.X, body.V, body.pairs, body.kernel, 3.0);
  const std::size_t n = body.X.size();
  std::vector<Vec<D>> u(n);
  std::mt19937 rng(11);
  std::normal_distribution<double> normal(0.0, 0.05 * kTestSpacing);
  for (auto& ui : u)
    for (int a = 0; a < D; ++a) ui[a] = normal(rng);
  control.update_residuals(u);
  std::vector<Vec<D>> force(n);
  for (std::size_t k = 0; k < n; ++k) force[k] = control.force(k);

  double worst_fd = 0.0, scale = 0.0;
  const double eps = 1e-6 * kTestSpacing;
  for (std::size_t k = 0; k < n; k += 3) {
    for (int a = 0; a < D; ++a) {
      auto plus = u, minus = u;
      plus[k][a] += eps;
      minus[k][a] -= eps;
      const double fd = -(energy_of(control, plus) - energy_of(control, minus)) / (2.0 * eps);
      worst_fd = std::max(worst_fd, std::abs(force[k][a] - fd));
      scale = std::max(scale, std::abs(fd));
    }
  }
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(worst_fd, 1e-6 * scale) << D << "D force against the energy's differences";

  // K u gathered as the tangent assembly does: particle i's slots (0: i, s: its neighbours).
  const auto& nl = body.pairs.neighbours;
  std::vector<Vec<D>> Ku(n, Vec<D>::Zero());
  auto node = [&](std::size_t i, std::size_t s) {
    return s == 0 ? i : static_cast<std::size_t>(nl.index[nl.offset[i] + s - 1]);
  };
  double symmetry = 0.0, largest = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t slots = nl.offset[i + 1] - nl.offset[i] + 1;
    for (std::size_t a = 0; a < slots; ++a)
      for (std::size_t b = 0; b < slots; ++b) {
        Ku[node(i, a)] += control.stiffness(i, a, b) * u[node(i, b)];
        symmetry =
            std::max(symmetry, std::abs(control.stiffness(i, a, b) - control.stiffness(i, b, a)));
        largest = std::max(largest, std::abs(control.stiffness(i, a, b)));
      }
  }
  double worst = 0.0, size = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    worst = std::max(worst, (Ku[k] + force[k]).norm());
    size = std::max(size, force[k].norm());
  }
  EXPECT_LT(worst, 1e-10 * size) << D << "D: K u against -f";
  EXPECT_LT(symmetry, 1e-12 * largest);  // round-off: p_a . y_b against p_b . y_a
}

TEST(FitResidualControl, ForceIsTheEnergyGradientAndStiffnessItsDerivative) {
  for (auto c : {GradientCorrection::linear, GradientCorrection::quadratic}) {
    check_force_and_stiffness<2>(c);
    check_force_and_stiffness<3>(c);
  }
}

// One interior particle displaced: its neighbours' deformation gradients barely see it where the
// fits give it little weight, but the residual of every neighbourhood it belongs to does.
TEST(FitResidualControl, AWanderingParticleCostsEnergy) {
  auto body = jittered_body<3>(GradientCorrection::quadratic);
  FitResidualControl<3> control(body.X, body.V, body.pairs, body.kernel, 1.0);
  std::size_t centre = 0;
  const Vec<3> middle(0.3, 0.25, 0.25);
  for (std::size_t i = 0; i < body.X.size(); ++i)
    if ((body.X[i] - middle).norm() < (body.X[centre] - middle).norm()) centre = i;
  std::vector<Vec<3>> u(body.X.size(), Vec<3>::Zero());
  u[centre] = Vec<3>(0.01 * kTestSpacing, 0.0, 0.0);
  const double one = energy_of(control, u);
  u[centre] *= 2.0;
  const double two = energy_of(control, u);
  EXPECT_GT(one, 0.0);
  EXPECT_NEAR(two / one, 4.0, 1e-9);  // quadratic in the displacement
}

}  // namespace
}  // namespace cosph
