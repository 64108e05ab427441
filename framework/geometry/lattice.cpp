#include "geometry/lattice.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/parallel.hpp"

namespace cosph {

namespace {

// Calls f(offset) for the 2^D corners of the cube [-r, r]^D.
template <int D, typename F>
bool any_corner(double r, const F& f) {
  for (int c = 0; c < (1 << D); ++c) {
    Vec<D> offset;
    for (int a = 0; a < D; ++a) offset[a] = (c >> a) & 1 ? r : -r;
    if (f(offset)) return true;
  }
  return false;
}

// A vertex site is in the shape if it or a point within 1e-9 spacings of it is: a site on a face
// at 10 = 40 * 0.25 may round to 10 + 2e-15, and losing it would drop the face's whole layer.
template <int D>
bool contains_vertex(const Shape<D>& shape, const Vec<D>& x, double spacing) {
  if (shape.contains(x)) return true;
  return any_corner<D>(1e-9 * spacing, [&](const Vec<D>& o) { return shape.contains(x + o); });
}

// The sub-point offsets of a dual cell along one axis, in spacings: (-3/8, -1/8, 1/8, 3/8).
constexpr int kSubPoints = 4;
constexpr double sub_point_offset(int s) { return (s + 0.5 - 0.5 * kSubPoints) / kSubPoints; }

// The fraction of the dual cell [x - spacing/2, x + spacing/2]^D inside the shape, on 4^D
// sub-points. No sub-point lies on a plane through the vertex or halfway to the next one, so such
// faces cut off exact halves.
template <int D>
double dual_cell_fraction(const Shape<D>& shape, const Vec<D>& x, double spacing) {
  int total = 1;
  for (int a = 0; a < D; ++a) total *= kSubPoints;
  int inside = 0;
  for (int s = 0; s < total; ++s) {
    Vec<D> y = x;
    int rest = s;
    for (int a = 0; a < D; ++a, rest /= kSubPoints)
      y[a] += sub_point_offset(rest % kSubPoints) * spacing;
    if (shape.contains(y)) ++inside;
  }
  return static_cast<double>(inside) / total;
}

}  // namespace

template <int D>
double dual_cell_depth(const Shape<D>& shape, const Vec<D>& x, const Vec<D>& direction,
                       double spacing) {
  int inside = 0;
  for (int s = 0; s < kSubPoints; ++s)
    if (contains_vertex<D>(shape, x + (sub_point_offset(s) * spacing) * direction, spacing))
      ++inside;
  return static_cast<double>(inside) / kSubPoints * spacing;
}

template <int D>
CellMoments<D> cell_moments(const Shape<D>& shape, const Vec<D>& x, double spacing,
                            LatticePlacement placement) {
  const double sub_cell = spacing / kSubPoints;
  const Mat<D> sub_cell_covariance = (sub_cell * sub_cell / 12.0) * Mat<D>::Identity();
  if (placement != LatticePlacement::vertex)
    return {Vec<D>::Zero(), (spacing * spacing / 12.0) * Mat<D>::Identity()};
  int total = 1;
  for (int a = 0; a < D; ++a) total *= kSubPoints;
  std::vector<Vec<D>> inside;
  for (int s = 0; s < total; ++s) {
    Vec<D> offset;
    int rest = s;
    for (int a = 0; a < D; ++a, rest /= kSubPoints)
      offset[a] = sub_point_offset(rest % kSubPoints) * spacing;
    if (shape.contains(x + offset)) inside.push_back(offset);
  }
  if (inside.empty())
    throw std::invalid_argument("cell moments: the dual cell of a site lies outside the shape");
  Vec<D> centroid = Vec<D>::Zero();
  for (const Vec<D>& o : inside) centroid += o;
  centroid /= static_cast<double>(inside.size());
  Mat<D> covariance = sub_cell_covariance;
  for (const Vec<D>& o : inside)
    covariance += (o - centroid) * (o - centroid).transpose() / static_cast<double>(inside.size());
  return {centroid, covariance};
}

template <int D>
ParticleCloud<D> lattice_fill(const Shape<D>& shape, double spacing, const Vec<D>& anchor,
                              LatticePlacement placement) {
  if (!(spacing > 0.0) || !std::isfinite(spacing)) {
    std::ostringstream s;
    s << "lattice fill: spacing must be positive and finite, got " << spacing;
    throw std::invalid_argument(s.str());
  }
  const auto [lower, upper] = shape.bounds();
  // Sites sit at anchor + (k + shift) * spacing.
  const bool vertex = placement == LatticePlacement::vertex;
  const double shift = vertex ? 0.0 : 0.5;
  // Integer lattice range covering the bounding box, one site wider on each side so that
  // rounding in the site coordinates can never drop a site the shape contains.
  std::array<std::int64_t, D> k_lo{}, count{};
  double total = 1.0;
  for (int a = 0; a < D; ++a) {
    const double lo = std::ceil((lower[a] - anchor[a]) / spacing - shift) - 1.0;
    const double hi = std::floor((upper[a] - anchor[a]) / spacing - shift) + 1.0;
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
  std::vector<std::vector<double>> volumes(slices);
  const double cell_volume = std::pow(spacing, D);
  parallel_for_each_index(slices, [&](std::size_t slice) {
    std::array<std::int64_t, D> k{};
    k[D - 1] = static_cast<std::int64_t>(slice);
    while (true) {
      Vec<D> x;
      for (int a = 0; a < D; ++a)
        x[a] = anchor[a] + (static_cast<double>(k_lo[a] + k[a]) + shift) * spacing;
      if (!vertex && shape.contains(x)) {
        found[slice].push_back(x);
        volumes[slice].push_back(cell_volume);
      } else if (vertex && contains_vertex(shape, x, spacing)) {
        // A site on the shape whose dual cell is all outside (a vertex touching a corner
        // from outside, a sliver) carries no volume: left out, a particle needs one.
        const double fraction = dual_cell_fraction(shape, x, spacing);
        if (fraction > 0.0) {
          found[slice].push_back(x);
          volumes[slice].push_back(fraction * cell_volume);
        }
      }
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
  cloud.volumes.reserve(n);
  for (std::size_t s = 0; s < slices; ++s) {
    cloud.positions.insert(cloud.positions.end(), found[s].begin(), found[s].end());
    cloud.volumes.insert(cloud.volumes.end(), volumes[s].begin(), volumes[s].end());
  }
  return cloud;
}

template double dual_cell_depth<2>(const Shape<2>&, const Vec<2>&, const Vec<2>&, double);
template double dual_cell_depth<3>(const Shape<3>&, const Vec<3>&, const Vec<3>&, double);
template CellMoments<2> cell_moments<2>(const Shape<2>&, const Vec<2>&, double, LatticePlacement);
template CellMoments<3> cell_moments<3>(const Shape<3>&, const Vec<3>&, double, LatticePlacement);
template ParticleCloud<2> lattice_fill<2>(const Shape<2>&, double, const Vec<2>&, LatticePlacement);
template ParticleCloud<3> lattice_fill<3>(const Shape<3>&, double, const Vec<3>&, LatticePlacement);

}  // namespace cosph
