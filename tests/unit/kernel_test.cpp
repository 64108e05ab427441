// Kernels: normalisation, derivative, compact support and convergence of SPH interpolation.
#include "kernels/kernel.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace cosph {
namespace {

const KernelType kAllTypes[] = {KernelType::WendlandC2, KernelType::WendlandC4,
                                KernelType::CubicSpline};

// Integral of W over the plane (2 pi r dr) or space (4 pi r^2 dr) by composite Simpson.
double radial_integral(const Kernel& w) {
  const int n = 20000;
  const double R = w.support_radius(), dr = R / n;
  double sum = 0.0;
  for (int k = 0; k <= n; ++k) {
    const double r = k * dr;
    const double shell =
        w.dimension() == 2 ? 2.0 * std::numbers::pi * r : 4.0 * std::numbers::pi * r * r;
    const double weight = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
    sum += weight * w.value(r) * shell;
  }
  return sum * dr / 3.0;
}

TEST(Kernel, IntegratesToOneIn2DAnd3D) {
  for (KernelType t : kAllTypes)
    for (int d : {2, 3})
      for (double h : {0.013, 1.0, 2.7}) {
        Kernel w(t, d, h);
        EXPECT_NEAR(radial_integral(w), 1.0, 1e-6) << kernel_name(t) << " D=" << d << " h=" << h;
      }
}

TEST(Kernel, DerivativeMatchesCentralDifferenceOfValue) {
  for (KernelType t : kAllTypes)
    for (int d : {2, 3}) {
      Kernel w(t, d, 0.7);
      for (double r = 0.01; r < w.support_radius(); r += 0.0371) {
        const double eps = 1e-6;
        const double fd = (w.value(r + eps) - w.value(r - eps)) / (2 * eps);
        EXPECT_NEAR(w.derivative(r), fd, 1e-6 * (1.0 + std::abs(fd)))
            << kernel_name(t) << " r=" << r;
      }
    }
}

TEST(Kernel, VanishesOutsideSupportAndIsPositiveInside) {
  for (KernelType t : kAllTypes) {
    Kernel w(t, 3, 0.5);
    EXPECT_EQ(w.value(w.support_radius()), 0.0);
    EXPECT_EQ(w.value(1.5 * w.support_radius()), 0.0);
    EXPECT_EQ(w.derivative(w.support_radius() + 1e-12), 0.0);
    EXPECT_GT(w.value(0.999 * w.support_radius()), 0.0);
    EXPECT_LE(w.derivative(0.5), 0.0);
    // Continuity at the support edge: the value just inside tends to zero.
    EXPECT_LT(w.value(w.support_radius() * (1 - 1e-6)), 1e-12);
  }
}

TEST(Kernel, GradientIsAntisymmetricInThePair) {
  // grad_i W_ij = W'(r) (r_i - r_j)/r and grad_j W_ji = W'(r) (r_j - r_i)/r.
  Kernel w(KernelType::WendlandC2, 2, 0.3);
  const double xi[2] = {0.1, 0.2}, xj[2] = {0.25, 0.05};
  const double dx = xi[0] - xj[0], dy = xi[1] - xj[1], r = std::hypot(dx, dy);
  const double gi[2] = {w.derivative(r) * dx / r, w.derivative(r) * dy / r};
  const double gj[2] = {w.derivative(r) * -dx / r, w.derivative(r) * -dy / r};
  EXPECT_DOUBLE_EQ(gi[0], -gj[0]);
  EXPECT_DOUBLE_EQ(gi[1], -gj[1]);
  EXPECT_LT(gi[0] * dx + gi[1] * dy, 0.0);  // points from i towards j
}

// SPH interpolation sum_j V_j f(x_j) W(x - x_j) of a smooth field converges to f with second
// order in h (the kernels are symmetric with unit zeroth moment). The particles are fine enough
// (dp = h/6) that the smoothing error, not the lattice quadrature error, is measured.
double interpolation_error(KernelType t, double h) {
  const double dp = h / 6.0;
  Kernel w(t, 2, h);
  auto f = [](double x, double y) { return std::sin(2 * x) * std::cos(3 * y) + x * y; };
  const double px = 0.3, py = 0.4;  // off-lattice point
  double sum = 0.0;
  const int n = static_cast<int>(std::ceil(3 * w.support_radius() / dp));
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j) {
      const double x = px + (i + 0.37) * dp, y = py + (j + 0.61) * dp;
      sum += dp * dp * f(x, y) * w.value(std::hypot(x - px, y - py));
    }
  return std::abs(sum - f(px, py));
}

TEST(Kernel, InterpolationOfSmoothFieldConvergesWithResolution) {
  for (KernelType t : kAllTypes) {
    const double e1 = interpolation_error(t, 0.04), e2 = interpolation_error(t, 0.02);
    EXPECT_GT(e1 / e2, 3.5) << kernel_name(t) << " e(h=0.04)=" << e1 << " e(h=0.02)=" << e2;
    EXPECT_LT(e2, 2e-3) << kernel_name(t);
  }
}

TEST(Kernel, NamesRoundTripAndUnknownNameIsRejected) {
  for (KernelType t : kAllTypes) EXPECT_EQ(kernel_type_from_name(kernel_name(t)), t);
  EXPECT_EQ(kernel_type_from_name("quintic_wendland"), KernelType::WendlandC2);
  EXPECT_THROW(kernel_type_from_name("gaussian"), std::invalid_argument);
}

}  // namespace
}  // namespace cosph
