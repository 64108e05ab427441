#include "io/wall_sensor.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>

#include "core/parallel.hpp"

namespace cosph {

namespace {

// The tangents of a plane with unit normal n: in 3D the coordinate axis least aligned with n,
// made orthogonal to it, and n x that, so that an axis-aligned wall's squares line up with them.
template <int D>
std::vector<Vec<D>> plane_tangents(const Vec<D>& n) {
  if constexpr (D == 2) {
    return {Vec<D>(-n[1], n[0])};
  } else {
    int k = 0;
    for (int a = 1; a < D; ++a)
      if (std::abs(n[a]) < std::abs(n[k])) k = a;
    Vec<D> t = Vec<D>::Unit(k) - n[k] * n;
    t.normalize();
    return {t, n.cross(t)};
  }
}

// The face's quadrature points in 3D: the midpoints of a 32 x 32 grid over the disc's bounding
// square that lie in the disc, as (u, v) in the face's plane.
std::vector<std::pair<double, double>> disc_points(double radius) {
  constexpr int m = 32;
  const double cell = 2.0 * radius / m;
  std::vector<std::pair<double, double>> points;
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < m; ++j) {
      const double u = -radius + (i + 0.5) * cell, v = -radius + (j + 0.5) * cell;
      if (u * u + v * v <= radius * radius) points.emplace_back(u, v);
    }
  return points;
}

}  // namespace

template <int D>
WallSensor<D>::WallSensor(std::vector<Vec<D>> centres, const Vec<D>& normal, double diameter)
    : centres_(std::move(centres)), radius_(0.5 * diameter) {
  if (!(normal.norm() > 0.0)) throw std::invalid_argument("wall sensor: the normal is zero");
  if (!(diameter > 0.0 && std::isfinite(diameter)))
    throw std::invalid_argument("wall sensor: the diameter must be positive and finite");
  normal_ = normal.normalized();
  tangents_ = plane_tangents<D>(normal_);
  if constexpr (D == 3) face_points_ = disc_points(radius_);
}

template <int D>
double WallSensor<D>::face_area() const {
  return D == 2 ? 2.0 * radius_ : std::acos(-1.0) * radius_ * radius_;
}

template <int D>
double WallSensor<D>::covered(const Vec<D>& offset, double a) const {
  const double half = 0.5 * a;
  if constexpr (D == 2) {
    const double s = offset.dot(tangents_[0]);
    return std::max(0.0, std::min(s + half, radius_) - std::max(s - half, -radius_));
  } else {
    const double u = offset.dot(tangents_[0]), v = offset.dot(tangents_[1]);
    if (std::abs(u) > radius_ + half || std::abs(v) > radius_ + half) return 0.0;
    // The face's share of quadrature points in the square [u - a/2, u + a/2) x [v - a/2, v + a/2):
    // half-open, so that a lattice of squares partitions the points exactly.
    std::size_t inside = 0;
    for (const auto& [x, y] : face_points_)
      if (x >= u - half && x < u + half && y >= v - half && y < v + half) ++inside;
    return face_area() * double(inside) / double(face_points_.size());
  }
}

template <int D>
void WallSensor<D>::near_face(const ParticleSet<D>& wall, double depth, const Domain<D>& domain,
                              std::size_t s, std::vector<Near>& behind,
                              std::vector<Near>& front) const {
  const auto& x = wall.vector("position");
  const auto& volume = wall.scalar("volume");
  behind.clear();
  front.clear();
  for (std::size_t w = 0; w < x.size(); ++w) {
    const Vec<D> r = domain.displacement(x[w], centres_[s]);
    const double a = std::pow(volume[w], 1.0 / D);
    const double along = -r.dot(normal_);  // > 0: behind the plane
    // Farther along the plane a particle can neither be covered nor pass its force to one that is.
    if ((r + along * normal_).norm() > radius_ + depth + a) continue;
    if (along > 0.0 && along <= depth) behind.push_back({w, r, a});
    if (along <= 0.0 && along > -a) front.push_back({w, r, a});
  }
}

// A particle behind the plane whose share of the plane lies under a particle in front of it is
// not behind the face: it is behind another wall's first layer, in the concave corner where the
// two walls meet. The water pushes the corner along the pairs' diagonals; the component along
// this face's normal acts on the face's end, so each such particle passes its force to the nearest
// particle behind the face (ties: the first in the wall's order; none beyond the depth, the
// kernel's support). Without this, a sensor at the foot of a wall of water at rest read 23% low.
//
// Two particles near the face may be neighbours across a periodic seam, their offsets from the
// face's centre on either side of it: their separation is the minimum image of the offsets'
// difference.
template <int D>
std::vector<std::size_t> WallSensor<D>::receivers(const std::vector<Near>& behind,
                                                  const std::vector<Near>& front, double depth,
                                                  const Domain<D>& domain) const {
  const auto overlaps = [&](const Near& p, const Near& q) {
    const Vec<D> d = domain.displacement(p.r, q.r);
    const double reach = 0.5 * (p.a + q.a) * (1.0 - 1e-9);
    for (const Vec<D>& t : tangents_)
      if (std::abs(d.dot(t)) >= reach) return false;
    return true;
  };
  std::vector<char> corner(behind.size(), 0);
  for (std::size_t k = 0; k < behind.size(); ++k)
    corner[k] = std::any_of(front.begin(), front.end(),
                            [&](const Near& q) { return overlaps(behind[k], q); });
  std::vector<std::size_t> receiver(behind.size(), behind.size());
  for (std::size_t k = 0; k < behind.size(); ++k) {
    if (!corner[k]) {
      receiver[k] = k;
      continue;
    }
    double best = depth;
    for (std::size_t q = 0; q < behind.size(); ++q) {
      const double d = domain.displacement(behind[q].r, behind[k].r).norm();
      if (!corner[q] && d < best * (1.0 - 1e-12)) best = d, receiver[k] = q;
    }
  }
  return receiver;
}

template <int D>
template <typename F>
void WallSensor<D>::for_each_covered(const ParticleSet<D>& wall, double depth,
                                     const Domain<D>& domain, std::size_t s, const F& f) const {
  std::vector<Near> behind, front;
  near_face(wall, depth, domain, s, behind, front);
  const std::vector<std::size_t> receiver = receivers(behind, front, depth, domain);
  // Each face particle's corner particles, listed once (not a search per face particle).
  std::vector<std::vector<std::size_t>> corners(behind.size());
  for (std::size_t c = 0; c < behind.size(); ++c)
    if (receiver[c] < behind.size() && receiver[c] != c) corners[receiver[c]].push_back(c);
  for (std::size_t k = 0; k < behind.size(); ++k) {
    if (receiver[k] != k) continue;  // a corner's particle, or none
    const Near& p = behind[k];
    const double area = covered(p.r + (-p.r.dot(normal_)) * normal_, p.a);
    if (!(area > 0.0)) continue;
    const double share = D == 2 ? p.a : p.a * p.a;
    f(p.w, area, share);
    for (std::size_t c : corners[k]) f(behind[c].w, area, share);
  }
}

// A column counts at the minimum image of its offset from the face's centre (near_face). On a
// periodic axis along which the face plus one particle's share is longer than the period, two
// images of one column could both lie under the face, and one of them would not count. Along
// axis a the face and a share span sqrt(1 - n_a^2) (2 radius + sqrt(D - 1) side): nothing along
// the normal, and in 3D the diagonal of a square share, which is more than an axis-aligned wall's
// squares need.
template <int D>
void WallSensor<D>::require_period(const ParticleSet<D>& wall, const Domain<D>& domain) const {
  if (!domain.any_periodic()) return;
  double side = 0.0;
  for (double v : wall.scalar("volume")) side = std::max(side, std::pow(v, 1.0 / D));
  for (int a = 0; a < D; ++a) {
    const double along_plane = std::sqrt(std::max(0.0, 1.0 - normal_[a] * normal_[a]));
    const double span = along_plane * (2.0 * radius_ + std::sqrt(double(D - 1)) * side);
    if (domain.periodic[a] && domain.length(a) < span * (1.0 - 1e-12))
      throw std::invalid_argument("wall sensor: the periodic axis " + std::to_string(a) + " is " +
                                  std::to_string(domain.length(a)) +
                                  " long, shorter than the face with one wall particle's share (" +
                                  std::to_string(span) +
                                  "): two periodic images of a column would both lie under the "
                                  "face; narrow the face or lengthen the period");
  }
}

template <int D>
typename WallSensor<D>::Coverage WallSensor<D>::coverage(const ParticleSet<D>& wall, double depth,
                                                         const Domain<D>& domain) const {
  require_period(wall, domain);
  Coverage c;
  c.weights.resize(centres_.size());
  parallel_for_each_index(centres_.size(), [&](std::size_t s) {
    for_each_covered(wall, depth, domain, s, [&](std::size_t w, double area, double share) {
      c.weights[s].emplace_back(w, area / share);
    });
  });
  return c;
}

template <int D>
std::vector<double> WallSensor<D>::sample(const Coverage& coverage,
                                          const std::vector<Vec<D>>& force) const {
  std::vector<double> values(centres_.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t s = 0; s < centres_.size(); ++s) {
    if (coverage.weights[s].empty()) continue;
    double weighted = 0.0;
    for (const auto& [w, weight] : coverage.weights[s]) weighted += weight * -force[w].dot(normal_);
    values[s] = weighted / face_area();
  }
  return values;
}

template <int D>
std::vector<double> WallSensor<D>::sample(const ParticleSet<D>& wall,
                                          const std::vector<Vec<D>>& force, double depth,
                                          const Domain<D>& domain) const {
  return sample(coverage(wall, depth, domain), force);
}

template class WallSensor<2>;
template class WallSensor<3>;

}  // namespace cosph
