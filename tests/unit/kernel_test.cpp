// Kernels: normalisation, derivative, compact support and convergence of SPH interpolation.
#include "kernels/kernel.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
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

// The gradient's first moment: sum_j V_j (x_j - x_i) (x) grad_i W_ij = I, i.e. the integral of
// -W'(r) r_hat (x) r over the support is the identity. This is what makes an uncorrected SPH
// gradient of a linear field exact in the bulk, and it fixes derivative()'s normalisation
// together with value()'s (a kernel whose derivative is off by a factor 1.0001 fails it). On a
// lattice centred on x_i with h / dp = 8 the sum is the integral to 1.5e-6 at worst (measured:
// 3.9e-7 / 4.3e-7 Wendland C2 2D / 3D, 9.2e-8 / 8.1e-9 C4, 2.5e-7 / 1.5e-6 cubic spline); the
// zeroth moment sum_j V_j grad_i W_ij vanishes by the lattice's symmetry about x_i.
template <int D>
void check_gradient_moments(KernelType t) {
  const double h = 0.4, dp = h / 8.0;
  Kernel w(t, D, h);
  const int n = static_cast<int>(std::ceil(w.support_radius() / dp)) + 1;
  double moment[3][3] = {}, zeroth[3] = {};
  const int nz = D == 3 ? n : 0;
  for (int i = -n; i <= n; ++i)
    for (int j = -n; j <= n; ++j)
      for (int k = -nz; k <= nz; ++k) {
        const double r_vec[3] = {i * dp, j * dp, k * dp};
        const double r = std::sqrt(r_vec[0] * r_vec[0] + r_vec[1] * r_vec[1] + r_vec[2] * r_vec[2]);
        if (r == 0.0 || r >= w.support_radius()) continue;
        const double volume = std::pow(dp, D);
        for (int a = 0; a < D; ++a) {
          // grad_i W_ij with x_i - x_j = -r_vec (x_j = x_i + r_vec).
          const double grad_a = w.derivative(r) * -r_vec[a] / r;
          zeroth[a] += volume * grad_a;
          for (int b = 0; b < D; ++b) moment[a][b] += volume * r_vec[b] * grad_a;
        }
      }
  double worst = 0.0;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) worst = std::max(worst, std::abs(moment[a][b] - (a == b)));
  std::cout << kernel_name(t) << " D=" << D << ": first moment off the identity by " << worst
            << "\n";
  for (int a = 0; a < D; ++a) {
    EXPECT_NEAR(zeroth[a], 0.0, 1e-12) << kernel_name(t) << " D=" << D;
    for (int b = 0; b < D; ++b)
      EXPECT_NEAR(moment[a][b], a == b ? 1.0 : 0.0, 2.3e-6) << kernel_name(t) << " D=" << D;
  }
}

TEST(Kernel, GradientFirstMomentIsTheIdentity) {
  for (KernelType t : kAllTypes) {
    check_gradient_moments<2>(t);
    check_gradient_moments<3>(t);
  }
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
