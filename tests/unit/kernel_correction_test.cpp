// The corrected kernel gradient is exact for linear fields at every particle, boundaries included.
#include "kernels/kernel_correction.hpp"

#include <gtest/gtest.h>

#include <random>

#include "core/error.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {
namespace {

template <int D>
std::vector<Vec<D>> perturbed_lattice(int per_axis, double dp, double amplitude, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude * dp, amplitude * dp);
  std::vector<Vec<D>> x;
  const int total = D == 2 ? per_axis * per_axis : per_axis * per_axis * per_axis;
  for (int k = 0; k < total; ++k) {
    Vec<D> p;
    int r = k;
    for (int a = 0; a < D; ++a) {
      p[a] = (r % per_axis + 0.5) * dp + u(rng);
      r /= per_axis;
    }
    x.push_back(p);
  }
  return x;
}

template <int D>
void check_linear_exactness(KernelType type) {
  const double dp = 0.1;
  auto x = perturbed_lattice<D>(D == 2 ? 20 : 10, dp, 0.25, 42);
  std::vector<double> V(x.size(), std::pow(dp, D));
  Kernel w(type, D, 1.3 * dp);
  Domain<D> domain;
  auto nl = build_inner_list<D>(x, w.support_radius(), domain);
  std::vector<Mat<D>> B;
  compute_correction_matrices<D>(x, V, nl, w, domain, B);
  Vec<D> g;
  for (int a = 0; a < D; ++a) g[a] = 1.5 - 0.7 * a;
  std::vector<double> phi(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) phi[i] = 4.0 + g.dot(x[i]);
  std::vector<Vec<D>> grad;
  corrected_gradient<D>(x, V, nl, w, domain, B, phi, grad);
  double worst = 0.0;
  for (const auto& gi : grad) worst = std::max(worst, (gi - g).norm());
  EXPECT_LT(worst, 1e-10) << kernel_name(type) << " D=" << D;

  // Without the correction the boundary particles are badly wrong: the test has teeth.
  std::vector<Mat<D>> identity(x.size(), Mat<D>::Identity());
  corrected_gradient<D>(x, V, nl, w, domain, identity, phi, grad);
  double uncorrected = 0.0;
  for (const auto& gi : grad) uncorrected = std::max(uncorrected, (gi - g).norm());
  EXPECT_GT(uncorrected, 0.3);
}

TEST(KernelCorrection, CorrectedGradientIsExactForLinearField2D) {
  for (auto t : {KernelType::WendlandC2, KernelType::WendlandC4, KernelType::CubicSpline})
    check_linear_exactness<2>(t);
}
TEST(KernelCorrection, CorrectedGradientIsExactForLinearField3D) {
  check_linear_exactness<3>(KernelType::WendlandC2);
}

TEST(KernelCorrection, PeriodicLatticeNeedsNoCorrection) {
  // On a regular periodic lattice the moment matrix is the same diagonal matrix at every particle,
  // close to the identity (h = 1.3 dp: the lattice quadrature error is about 2% per entry).
  const double dp = 0.05;
  auto x = perturbed_lattice<2>(20, dp, 0.0, 1);
  std::vector<double> V(x.size(), dp * dp);
  Kernel w(KernelType::WendlandC2, 2, 1.3 * dp);
  Domain<2> domain;
  domain.upper = Vec<2>::Constant(1.0);
  domain.periodic = {true, true};
  auto nl = build_inner_list<2>(x, w.support_radius(), domain);
  std::vector<Mat<2>> B;
  compute_correction_matrices<2>(x, V, nl, w, domain, B);
  for (const auto& b : B) {
    EXPECT_LT((b - Mat<2>::Identity()).norm(), 0.05);
    EXPECT_LT(std::abs(b(0, 1)), 1e-12);
    EXPECT_LT((b - B[0]).norm(), 1e-12);
  }
}

TEST(KernelCorrection, SingularMatrixIsReportedWithIndexAndPosition) {
  // Particles on a line: their neighbourhoods span one direction only.
  std::vector<Vec<2>> x;
  for (int k = 0; k < 10; ++k) x.push_back(Vec<2>(0.1 * k, 0.5));
  std::vector<double> V(x.size(), 0.01);
  Kernel w(KernelType::WendlandC2, 2, 0.13);
  Domain<2> domain;
  auto nl = build_inner_list<2>(x, w.support_radius(), domain);
  std::vector<Mat<2>> B;
  try {
    compute_correction_matrices<2>(x, V, nl, w, domain, B);
    FAIL() << "expected a singular correction matrix";
  } catch (const RuntimeError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("particle 0"), std::string::npos) << msg;
    EXPECT_NE(msg.find("0.5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("singular"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace cosph
