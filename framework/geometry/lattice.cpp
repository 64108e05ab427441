#include "geometry/lattice.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/parallel.hpp"

namespace cosph {

template <int D>
ParticleCloud<D> lattice_fill(const Shape<D>& shape, double spacing, const Vec<D>& anchor) {
  if (!(spacing > 0.0) || !std::isfinite(spacing)) {
    std::ostringstream s;
    s << "lattice fill: spacing must be positive and finite, got " << spacing;
    throw std::invalid_argument(s.str());
  }
  const auto [lower, upper] = shape.bounds();
  // Integer lattice range covering the bounding box, one site wider on each side so that
  // rounding in the site coordinates can never drop a site the shape contains.
  std::array<std::int64_t, D> k_lo{}, count{};
  double total = 1.0;
  for (int a = 0; a < D; ++a) {
    const double lo = std::ceil((lower[a] - anchor[a]) / spacing - 0.5) - 1.0;
    const double hi = std::floor((upper[a] - anchor[a]) / spacing - 0.5) + 1.0;
    const double n = hi - lo + 1.0;
    if (!std::isfinite(lo) || !std::isfinite(hi)) total = std::numeric_limits<double>::infinity();
    total *= std::max(n, 0.0);
    if (!(total <= kMaxLatticeSites)) {
      std::ostringstream s;
      s << "lattice fill: the shape's bounding box spans more than " << kMaxLatticeSites
        << " lattice sites at spacing " << spacing
        << " (is the spacing in the same unit as the geometry?)";
      throw std::invalid_argument(s.str());
    }
    k_lo[a] = static_cast<std::int64_t>(lo);
    count[a] = static_cast<std::int64_t>(n);
  }

  if (total == 0.0) count.fill(0);  // an empty bounding box: nothing to scan

  // Slices along the slowest axis are filled in parallel, each into its own buffer, and joined in
  // slice order: the result is the same for any number of threads.
  const auto slices = static_cast<std::size_t>(count[D - 1]);  // 0 if any axis is empty
  std::vector<std::vector<Vec<D>>> found(slices);
  parallel_for_each_index(slices, [&](std::size_t slice) {
    std::array<std::int64_t, D> k{};
    k[D - 1] = static_cast<std::int64_t>(slice);
    while (true) {
      Vec<D> x;
      for (int a = 0; a < D; ++a)
        x[a] = anchor[a] + (static_cast<double>(k_lo[a] + k[a]) + 0.5) * spacing;
      if (shape.contains(x)) found[slice].push_back(x);
      int a = 0;
      for (; a < D - 1; ++a) {
        if (++k[a] < count[a]) break;
        k[a] = 0;
      }
      if (a == D - 1) break;
    }
  });

  ParticleCloud<D> cloud;
  std::size_t n = 0;
  for (const auto& f : found) n += f.size();
  if (n == 0) {
    std::ostringstream s;
    s << "lattice fill: no lattice site at spacing " << spacing
      << " lies inside the shape (spacing too coarse for the shape, or the shape is empty)";
    throw std::invalid_argument(s.str());
  }
  cloud.positions.reserve(n);
  for (const auto& f : found) cloud.positions.insert(cloud.positions.end(), f.begin(), f.end());
  cloud.volumes.assign(n, std::pow(spacing, D));
  return cloud;
}

template ParticleCloud<2> lattice_fill<2>(const Shape<2>&, double, const Vec<2>&);
template ParticleCloud<3> lattice_fill<3>(const Shape<3>&, double, const Vec<3>&);

}  // namespace cosph
