// The box particles live in and which of its axes are periodic. Pair displacements go through
// displacement(), which applies the minimum-image convention on periodic axes.
#pragma once

#include <array>
#include <cmath>

#include "core/types.hpp"

namespace cosph {

template <int D>
struct Domain {
  Vec<D> lower = Vec<D>::Zero();
  Vec<D> upper = Vec<D>::Zero();
  std::array<bool, D> periodic{};

  bool any_periodic() const {
    for (bool p : periodic)
      if (p) return true;
    return false;
  }
  double length(int axis) const { return upper[axis] - lower[axis]; }

  // r_i - r_j, shortest over periodic images.
  Vec<D> displacement(const Vec<D>& xi, const Vec<D>& xj) const {
    Vec<D> d = xi - xj;
    for (int a = 0; a < D; ++a)
      if (periodic[a]) {
        const double L = length(a);
        d[a] -= L * std::round(d[a] / L);
      }
    return d;
  }

  // Maps a position back into [lower, upper) along periodic axes.
  Vec<D> wrap(Vec<D> x) const {
    for (int a = 0; a < D; ++a)
      if (periodic[a]) {
        const double L = length(a);
        x[a] -= L * std::floor((x[a] - lower[a]) / L);
        if (x[a] >= upper[a]) x[a] -= L;  // guards the round-off case x == upper
      }
    return x;
  }
};

}  // namespace cosph
