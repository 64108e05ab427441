#include "geometry/shell_nodes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace cosph {

namespace {

// A point of the meridian half-plane (rho, z) and its derivatives in the grid coordinates.
struct MeridianPoint {
  double rho, z;
  double rho_t, z_t, rho_s, z_s;
};

class ShellMap {
 public:
  explicit ShellMap(const TruncatedEllipsoidalShell& shell)
      : rs0_(shell.inner_short()),
        rl0_(shell.inner_long()),
        drs_(shell.outer_short() - shell.inner_short()),
        drl_(shell.outer_long() - shell.inner_long()),
        zb_(shell.z_truncation()) {}

  MeridianPoint at(double t, double s) const {
    const double rs = rs0_ + t * drs_, rl = rl0_ + t * drl_;
    const double q = zb_ / rl;
    const double ub = std::acos(q);
    const double ub_t = zb_ * drl_ / (rl * rl * std::sqrt(1.0 - q * q));
    const double u = ub + s * (std::numbers::pi - ub);
    const double u_t = (1.0 - s) * ub_t, u_s = std::numbers::pi - ub;
    const double su = std::sin(u), cu = std::cos(u);
    return {rs * su,       rl * cu,       drs_ * su + rs * cu * u_t, drl_ * cu - rl * su * u_t,
            rs * cu * u_s, -rl * su * u_s};
  }

 private:
  double rs0_, rl0_, drs_, drl_, zb_;
};

// Integrates f over [a, b] with 4-point Gauss-Legendre on each of `pieces` equal parts (the
// integrands are smooth: polynomial-trigonometric in t and s).
template <typename F>
double gauss(double a, double b, const F& f, int pieces = 2) {
  static constexpr std::array<double, 4> x{-0.8611363115940526, -0.3399810435848563,
                                           0.3399810435848563, 0.8611363115940526};
  static constexpr std::array<double, 4> w{0.3478548451374538, 0.6521451548625461,
                                           0.6521451548625461, 0.3478548451374538};
  double sum = 0.0;
  const double h = (b - a) / pieces;
  for (int p = 0; p < pieces; ++p) {
    const double mid = a + (p + 0.5) * h;
    for (int k = 0; k < 4; ++k) sum += w[k] * f(mid + 0.5 * h * x[k]);
  }
  return 0.5 * h * sum;
}

// The dual interval of node k of n uniform intervals on [0, 1], clipped to [0, 1].
std::pair<double, double> dual_interval(int k, int n) {
  const double d = 1.0 / n;
  return {std::max(0.0, (k - 0.5) * d), std::min(1.0, (k + 0.5) * d)};
}

// The dual interval of node k of the nodes s[0] = 0 < ... < s[n] = 1: halfway to each neighbour.
std::pair<double, double> dual_interval(const std::vector<double>& s, std::size_t k) {
  return {k == 0 ? 0.0 : 0.5 * (s[k - 1] + s[k]),
          k + 1 == s.size() ? 1.0 : 0.5 * (s[k] + s[k + 1])};
}

// The latitudes s_j of the rings, j = 0..n, at equal arc lengths along the mid-wall meridian:
// u uniform in s would crowd the rings near the apex, where the meridian runs along the short
// radius (1 mm spacing on Land's ventricle: rings 0.65 mm apart at the apex, 1.4 mm at the
// equator), and the crowded nodes near the axis are weakly coupled.
template <typename Length>
std::vector<double> equal_arc_latitudes(int n, const Length& arc_density) {
  std::vector<double> edge(1025, 0.0);  // arc length from the base at s = i / 1024
  for (std::size_t i = 1; i < edge.size(); ++i)
    edge[i] = edge[i - 1] + gauss((i - 1) / 1024.0, i / 1024.0, arc_density, 1);
  std::vector<double> s(static_cast<std::size_t>(n) + 1, 0.0);
  s.back() = 1.0;
  for (int j = 1; j < n; ++j) {
    const double target = edge.back() * j / n;
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      const std::size_t i = std::min<std::size_t>(1023, static_cast<std::size_t>(mid * 1024.0));
      const double length = edge[i] + gauss(i / 1024.0, mid, arc_density, 1);
      (length < target ? lo : hi) = mid;
    }
    s[static_cast<std::size_t>(j)] = 0.5 * (lo + hi);
  }
  return s;
}

int ring_count(double rho, double spacing) {
  return std::max(3, static_cast<int>(std::lround(2.0 * std::numbers::pi * rho / spacing)));
}

// The integrals over a node's meridian dual region (per unit v) of J, J rho, J z, J rho^2,
// J rho z and J z^2, with J the volume per dt ds dv.
struct MeridianMoments {
  double m0, rho, z, rho2, rhoz, z2;
};

// The centroid (relative to the node x) and covariance of the dual cell that spans
// v in [v - a, v + a], a = pi / count, over a meridian region of moments m.
CellMoments<3> ring_cell(const MeridianMoments& m, const Vec<3>& x, double v, int count) {
  const double a = std::numbers::pi / count;
  const double c = std::cos(v), s = std::sin(v), s1 = 2.0 * std::sin(a);
  const double half_sin2 = 0.5 * std::sin(2.0 * a);
  const double volume = 2.0 * a * m.m0;
  const Vec<3> first(m.rho * s1 * c, m.rho * s1 * s, 2.0 * a * m.z);
  Mat<3> second;
  second(0, 0) = m.rho2 * (a + half_sin2 * std::cos(2.0 * v));
  second(1, 1) = m.rho2 * (a - half_sin2 * std::cos(2.0 * v));
  second(0, 1) = second(1, 0) = m.rho2 * half_sin2 * std::sin(2.0 * v);
  second(0, 2) = second(2, 0) = m.rhoz * s1 * c;
  second(1, 2) = second(2, 1) = m.rhoz * s1 * s;
  second(2, 2) = 2.0 * a * m.z2;
  const Vec<3> mean = first / volume;
  return {mean - x, second / volume - mean * mean.transpose()};
}

// The outward area vector of a ring node's share of a face whose meridian profile has in-plane
// area density (n_rho, n_z) per unit of v (already integrated over the node's dual interval):
// integrating the rotated normal over v in [v - a, v + a], a = pi / count.
Vec<3> ring_area(double n_rho, double n_z, double v, int count) {
  const double a = std::numbers::pi / count;
  return Vec<3>(n_rho * 2.0 * std::sin(a) * std::cos(v), n_rho * 2.0 * std::sin(a) * std::sin(v),
                n_z * 2.0 * a);
}

}  // namespace

ParticleCloud<3> conforming_shell_nodes(const TruncatedEllipsoidalShell& shell, double spacing) {
  if (!(spacing > 0.0) || !std::isfinite(spacing)) {
    std::ostringstream s;
    s << "conforming placement: spacing must be positive and finite, got " << spacing;
    throw std::invalid_argument(s.str());
  }
  if (!(std::abs(shell.z_truncation()) < shell.inner_long())) {
    std::ostringstream s;
    s << "conforming placement: the base plane z = " << shell.z_truncation()
      << " must cut the cavity open (lie strictly between the inner apex -" << shell.inner_long()
      << " and top " << shell.inner_long() << ")";
    throw std::invalid_argument(s.str());
  }
  const ShellMap map(shell);
  const double thickness =
      std::max(shell.outer_short() - shell.inner_short(), shell.outer_long() - shell.inner_long());
  const auto arc_density = [&](double s) {
    const MeridianPoint p = map.at(0.5, s);
    return std::hypot(p.rho_s, p.z_s);
  };
  const double meridian = gauss(0.0, 1.0, arc_density, 16);
  const int nt = std::max(1, static_cast<int>(std::lround(thickness / spacing)));
  const int ns = std::max(2, static_cast<int>(std::lround(meridian / spacing)));
  if (static_cast<double>(nt) * ns * meridian / spacing > 2e8)
    throw std::invalid_argument(
        "conforming placement: more than 2e8 nodes (is the spacing in the "
        "geometry's unit?)");
  const std::vector<double> latitude = equal_arc_latitudes(ns, arc_density);

  ParticleCloud<3> cloud;
  BoundaryFace<3> inner{"inner", {}, {}}, outer{"outer", {}, {}}, base{"base", {}, {}};
  const auto jacobian = [&](double t, double s) {  // volume per dt ds dv
    const MeridianPoint p = map.at(t, s);
    return p.rho * std::abs(p.rho_t * p.z_s - p.rho_s * p.z_t);
  };
  for (int k = 0; k <= nt; ++k) {
    const double t = static_cast<double>(k) / nt;
    const auto [t0, t1] = dual_interval(k, nt);
    for (int j = 0; j <= ns; ++j) {
      const double s = latitude[static_cast<std::size_t>(j)];
      const auto [s0, s1] = dual_interval(latitude, static_cast<std::size_t>(j));
      const MeridianPoint p = map.at(t, s);
      const bool apex = j == ns;
      const int count = apex ? 1 : ring_count(p.rho, spacing);
      const auto integral = [&](auto&& weight) {
        return gauss(t0, t1, [&](double tt) {
          return gauss(s0, s1, [&](double ss) {
            const MeridianPoint q = map.at(tt, ss);
            return jacobian(tt, ss) * weight(q);
          });
        });
      };
      const double band = integral([](const MeridianPoint&) { return 1.0; });
      const MeridianMoments moments{band,
                                    integral([](const MeridianPoint& q) { return q.rho; }),
                                    integral([](const MeridianPoint& q) { return q.z; }),
                                    integral([](const MeridianPoint& q) { return q.rho * q.rho; }),
                                    integral([](const MeridianPoint& q) { return q.rho * q.z; }),
                                    integral([](const MeridianPoint& q) { return q.z * q.z; })};
      // Face densities per unit v over the node's dual interval: rho times the meridian
      // tangent turned outwards (away from the body's interior, i.e. against x_t on t = 0, along
      // it on t = 1, against x_s on s = 0).
      const auto wall = [&](double tt, double sign) {
        std::array<double, 2> n{0.0, 0.0};
        for (int c = 0; c < 2; ++c)
          n[c] = gauss(s0, s1, [&](double ss) {
            const MeridianPoint q = map.at(tt, ss);
            double nr = q.z_s, nz = -q.rho_s;  // tangent (rho_s, z_s) turned by -90 degrees
            if ((nr * q.rho_t + nz * q.z_t) * sign < 0.0) nr = -nr, nz = -nz;
            return q.rho * (c == 0 ? nr : nz);
          });
        return n;
      };
      std::array<double, 2> base_density{0.0, 0.0};
      if (j == 0)
        for (int c = 0; c < 2; ++c)
          base_density[c] = gauss(t0, t1, [&](double tt) {
            const MeridianPoint q = map.at(tt, 0.0);
            double nr = q.z_t, nz = -q.rho_t;
            if (nr * q.rho_s + nz * q.z_s > 0.0) nr = -nr, nz = -nz;
            return q.rho * (c == 0 ? nr : nz);
          });
      const std::array<double, 2> inner_density = k == 0 ? wall(0.0, -1.0) : std::array{0.0, 0.0};
      const std::array<double, 2> outer_density = k == nt ? wall(1.0, 1.0) : std::array{0.0, 0.0};
      for (int m = 0; m < count; ++m) {
        const double v = 2.0 * std::numbers::pi * m / count;
        const std::size_t index = cloud.positions.size();
        const double rho = apex ? 0.0 : p.rho;
        cloud.positions.emplace_back(rho * std::cos(v), rho * std::sin(v), p.z);
        cloud.volumes.push_back(band * 2.0 * std::numbers::pi / count);
        cloud.cells.push_back(ring_cell(moments, cloud.positions.back(), v, count));
        const auto add = [&](BoundaryFace<3>& face, const std::array<double, 2>& n) {
          face.particles.push_back(index);
          face.areas.push_back(ring_area(n[0], n[1], v, count));
        };
        if (k == 0) add(inner, inner_density);
        if (k == nt) add(outer, outer_density);
        if (j == 0) add(base, base_density);
      }
    }
  }
  cloud.faces = {std::move(inner), std::move(outer), std::move(base)};
  return cloud;
}

}  // namespace cosph
