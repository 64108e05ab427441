// A TL-SPH test body: particles on a jittered cell-centred lattice of spacing kTestSpacing, their
// volumes, the Wendland C2 kernel with h = 1.3 dp and the reference pairs of the solid's operators
// (shared by tests/unit/solid_tlsph_test.cpp and solid_gradient_correction_test.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "kernels/kernel.hpp"
#include "solid_tlsph/tlsph_operators.hpp"

namespace cosph::test {

constexpr double kTestSpacing = 0.1;

// Particles at the cell centres (k + 1/2) dp of an n[0] x n[1] (x n[2]) lattice, each moved by up
// to jitter * dp per axis.
template <int D>
std::vector<Vec<D>> lattice_box(const std::array<int, D>& n, double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter * kTestSpacing, jitter * kTestSpacing);
  int total = 1;
  for (int a = 0; a < D; ++a) total *= n[a];
  std::vector<Vec<D>> X(total);
  for (int k = 0; k < total; ++k) {
    int r = k;
    for (int a = 0; a < D; ++a) {
      X[k][a] = (r % n[a] + 0.5) * kTestSpacing + u(rng);
      r /= n[a];
    }
  }
  return X;
}

template <int D>
struct TlsphBody {
  std::vector<Vec<D>> X;
  std::vector<double> V;
  Kernel kernel{KernelType::WendlandC2, D, 1.3 * kTestSpacing};
  ReferencePairs<D> pairs;
};

// A body of the given particles and volumes (dp^D when none are given).
template <int D>
TlsphBody<D> make_tlsph_body(std::vector<Vec<D>> X, std::vector<double> V,
                             GradientCorrection correction, bool hourglass) {
  TlsphBody<D> b;
  b.X = std::move(X);
  b.V = V.empty() ? std::vector<double>(b.X.size(), std::pow(kTestSpacing, D)) : std::move(V);
  b.pairs = build_reference_pairs<D>(b.X, b.V, b.kernel, correction, hourglass);
  return b;
}

// An energy quadrature on cells of random centroids (up to 0.2 dp from the particle per axis) and
// random covariances (M M^T, M's entries up to 0.3 dp): no lattice symmetry hides an index error.
template <int D>
EnergyQuadrature<D> random_cells(std::size_t count, std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  EnergyQuadrature<D> quadrature;
  for (std::size_t i = 0; i < count; ++i) {
    Vec<D> c;
    Mat<D> M;
    for (int a = 0; a < D; ++a) {
      c[a] = 0.2 * kTestSpacing * unit(rng);
      for (int b = 0; b < D; ++b) M(a, b) = 0.3 * kTestSpacing * unit(rng);
    }
    quadrature.offset.push_back(EnergyQuadrature<D>::points_of(c, M * M.transpose()));
  }
  return quadrature;
}

// How far the forces are from the energy's gradient: the largest |force_i - (-dE/du_i)| over the
// particles and components, by central differences of step eps, and the largest |dE/du|.
struct GradientMismatch {
  double worst = 0.0, scale = 0.0;
};
template <int D, typename Energy, typename Force>
GradientMismatch energy_gradient_mismatch(const std::vector<Vec<D>>& u, const Energy& energy,
                                          const Force& force, double eps) {
  GradientMismatch m;
  for (std::size_t i = 0; i < u.size(); ++i) {
    const Vec<D> f = force(i);
    for (int a = 0; a < D; ++a) {
      auto plus = u, minus = u;
      plus[i][a] += eps;
      minus[i][a] -= eps;
      const double fd = -(energy(plus) - energy(minus)) / (2.0 * eps);
      m.worst = std::max(m.worst, std::abs(f[a] - fd));
      m.scale = std::max(m.scale, std::abs(fd));
    }
  }
  return m;
}

}  // namespace cosph::test
