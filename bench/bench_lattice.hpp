// Test clouds for the benchmarks: about `target` particles on a cubic lattice of spacing dp,
// each displaced uniformly by up to `jitter` * dp per axis (fixed seed: repeatable numbers).
#pragma once

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "core/types.hpp"

namespace cosph::bench {

template <int D>
std::vector<Vec<D>> jittered_lattice(std::size_t target, double dp, double jitter) {
  const int n = static_cast<int>(std::round(std::pow(double(target), 1.0 / D)));
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-jitter * dp, jitter * dp);
  std::vector<Vec<D>> x;
  std::array<int, D> k{};
  while (true) {
    Vec<D> p;
    for (int a = 0; a < D; ++a) p[a] = (k[a] + 0.5) * dp + (jitter > 0.0 ? u(rng) : 0.0);
    x.push_back(p);
    int a = 0;
    for (; a < D; ++a) {
      if (++k[a] < n) break;
      k[a] = 0;
    }
    if (a == D) break;
  }
  return x;
}

}  // namespace cosph::bench
