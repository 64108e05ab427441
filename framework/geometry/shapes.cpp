#include "geometry/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace cosph {

namespace {

template <int D>
std::string format_vec(const Vec<D>& v) {
  std::ostringstream s;
  s << '(';
  for (int a = 0; a < D; ++a) s << (a ? ", " : "") << v[a];
  s << ')';
  return s.str();
}

template <int D>
bool all_finite(const Vec<D>& v) {
  for (int a = 0; a < D; ++a)
    if (!std::isfinite(v[a])) return false;
  return true;
}

double cross(const Vec<2>& a, const Vec<2>& b) { return a[0] * b[1] - a[1] * b[0]; }

// Sign of the turn p -> q -> r, with a tolerance so that nearly collinear triples count as
// collinear (the crossing test below must then also catch touching and overlapping edges).
int orientation(const Vec<2>& p, const Vec<2>& q, const Vec<2>& r, double tol) {
  const double c = cross(q - p, r - p);
  return c > tol ? 1 : c < -tol ? -1 : 0;
}

bool on_segment_box(const Vec<2>& p, const Vec<2>& q, const Vec<2>& r) {
  return r[0] >= std::min(p[0], q[0]) && r[0] <= std::max(p[0], q[0]) &&
         r[1] >= std::min(p[1], q[1]) && r[1] <= std::max(p[1], q[1]);
}

// Closed segments p1-p2 and q1-q2 share at least one point.
bool segments_meet(const Vec<2>& p1, const Vec<2>& p2, const Vec<2>& q1, const Vec<2>& q2,
                   double tol) {
  const int o1 = orientation(p1, p2, q1, tol), o2 = orientation(p1, p2, q2, tol);
  const int o3 = orientation(q1, q2, p1, tol), o4 = orientation(q1, q2, p2, tol);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && on_segment_box(p1, p2, q1)) || (o2 == 0 && on_segment_box(p1, p2, q2)) ||
         (o3 == 0 && on_segment_box(q1, q2, p1)) || (o4 == 0 && on_segment_box(q1, q2, p2));
}

}  // namespace

// ---- Box ----------------------------------------------------------------------------------

template <int D>
Box<D>::Box(const Vec<D>& lower, const Vec<D>& upper) : lower_(lower), upper_(upper) {
  if (!all_finite<D>(lower) || !all_finite<D>(upper))
    throw std::invalid_argument("box: corners must be finite, got lower " + format_vec<D>(lower) +
                                " and upper " + format_vec<D>(upper));
  for (int a = 0; a < D; ++a)
    if (!(upper[a] > lower[a]))
      throw std::invalid_argument("box: upper corner " + format_vec<D>(upper) +
                                  " must exceed lower corner " + format_vec<D>(lower) +
                                  " on every axis (axis " + std::to_string(a) + " does not)");
}

template <int D>
bool Box<D>::contains(const Vec<D>& x) const {
  for (int a = 0; a < D; ++a)
    if (x[a] < lower_[a] || x[a] > upper_[a]) return false;
  return true;
}

// ---- Ellipsoid ----------------------------------------------------------------------------

template <int D>
Ellipsoid<D>::Ellipsoid(const Vec<D>& center, const Vec<D>& radii)
    : center_(center), radii_(radii) {
  if (!all_finite<D>(center))
    throw std::invalid_argument("ellipsoid: centre must be finite, got " + format_vec<D>(center));
  for (int a = 0; a < D; ++a)
    if (!(radii[a] > 0.0) || !std::isfinite(radii[a]))
      throw std::invalid_argument("ellipsoid: radii must be positive and finite, got " +
                                  format_vec<D>(radii));
}

template <int D>
bool Ellipsoid<D>::contains(const Vec<D>& x) const {
  return (x - center_).cwiseQuotient(radii_).squaredNorm() <= 1.0;
}

template <int D>
std::pair<Vec<D>, Vec<D>> Ellipsoid<D>::bounds() const {
  return {center_ - radii_, center_ + radii_};
}

// ---- TruncatedEllipsoidalShell ------------------------------------------------------------

TruncatedEllipsoidalShell::TruncatedEllipsoidalShell(double inner_short, double inner_long,
                                                     double outer_short, double outer_long,
                                                     double z_truncation)
    : inner_short_(inner_short),
      inner_long_(inner_long),
      outer_short_(outer_short),
      outer_long_(outer_long),
      z_truncation_(z_truncation) {
  for (double r : {inner_short, inner_long, outer_short, outer_long})
    if (!(r > 0.0) || !std::isfinite(r))
      throw std::invalid_argument(
          "truncated ellipsoidal shell: radii must be positive and finite (inner short " +
          std::to_string(inner_short) + ", inner long " + std::to_string(inner_long) +
          ", outer short " + std::to_string(outer_short) + ", outer long " +
          std::to_string(outer_long) + ")");
  // Both semi-axes smaller is necessary and sufficient for the inner (axis-aligned, co-centred)
  // ellipsoid to lie strictly inside the outer one; otherwise the wall would be cut through.
  if (!(inner_short < outer_short) || !(inner_long < outer_long))
    throw std::invalid_argument(
        "truncated ellipsoidal shell: the inner ellipsoid must lie inside the outer one (inner "
        "radii short " +
        std::to_string(inner_short) + ", long " + std::to_string(inner_long) +
        " must be smaller than outer short " + std::to_string(outer_short) + ", long " +
        std::to_string(outer_long) + ")");
  if (!std::isfinite(z_truncation) || !(z_truncation > -outer_long))
    throw std::invalid_argument(
        "truncated ellipsoidal shell: truncation z = " + std::to_string(z_truncation) +
        " leaves nothing (must be above the apex z = " + std::to_string(-outer_long) + ")");
}

bool TruncatedEllipsoidalShell::contains(const Vec<3>& x) const {
  if (x[2] > z_truncation_) return false;
  const double rho2 = x[0] * x[0] + x[1] * x[1];
  const double z2 = x[2] * x[2];
  const double outer = rho2 / (outer_short_ * outer_short_) + z2 / (outer_long_ * outer_long_);
  const double inner = rho2 / (inner_short_ * inner_short_) + z2 / (inner_long_ * inner_long_);
  return outer <= 1.0 && inner >= 1.0;
}

std::pair<Vec<3>, Vec<3>> TruncatedEllipsoidalShell::bounds() const {
  // Below the equator the widest cross-section is at the truncation plane.
  double rho = outer_short_;
  if (z_truncation_ < 0.0) {
    const double t = z_truncation_ / outer_long_;
    rho = outer_short_ * std::sqrt(std::max(0.0, 1.0 - t * t));
  }
  const double ztop = std::min(z_truncation_, outer_long_);
  return {Vec<3>(-rho, -rho, -outer_long_), Vec<3>(rho, rho, ztop)};
}

// ---- Polygon ------------------------------------------------------------------------------

Polygon::Polygon(std::vector<Vec<2>> vertices) : vertices_(std::move(vertices)) {
  const std::size_t n = vertices_.size();
  if (n < 3)
    throw std::invalid_argument("polygon: needs at least 3 vertices, got " + std::to_string(n));
  lower_ = upper_ = vertices_[0];
  for (std::size_t i = 0; i < n; ++i) {
    if (!all_finite<2>(vertices_[i]))
      throw std::invalid_argument("polygon: vertex " + std::to_string(i) + " is not finite");
    lower_ = lower_.cwiseMin(vertices_[i]);
    upper_ = upper_.cwiseMax(vertices_[i]);
  }
  const double size = (upper_ - lower_).norm();
  double twice_area = 0.0;
  for (std::size_t i = 0; i < n; ++i) twice_area += cross(vertices_[i], vertices_[(i + 1) % n]);
  if (!(std::abs(twice_area) > 1e-12 * size * size))
    throw std::invalid_argument("polygon: vertices enclose no area (all collinear?)");

  // Tolerance on cross products of edge vectors, relative to the polygon size squared, so that
  // the checks do not depend on the unit of length.
  const double tol = 1e-12 * size * size;
  for (std::size_t i = 0; i < n; ++i)
    if ((vertices_[(i + 1) % n] - vertices_[i]).norm() <= 1e-12 * size)
      throw std::invalid_argument("polygon: vertices " + std::to_string(i) + " and " +
                                  std::to_string((i + 1) % n) + " coincide");
  for (std::size_t i = 0; i < n; ++i) {
    const Vec<2>& a = vertices_[i];
    const Vec<2>& b = vertices_[(i + 1) % n];
    // Adjacent edges meet at their shared vertex only; a fold back along the previous edge is an
    // overlap. Non-adjacent edges must not meet at all.
    const Vec<2>& next = vertices_[(i + 2) % n];
    if (orientation(a, b, next, tol) == 0 && (next - b).dot(a - b) > 0.0)
      throw std::invalid_argument("polygon: edge " + std::to_string((i + 1) % n) +
                                  " folds back onto edge " + std::to_string(i));
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segments_meet(a, b, vertices_[j], vertices_[(j + 1) % n], tol))
        throw std::invalid_argument("polygon: edges " + std::to_string(i) + " and " +
                                    std::to_string(j) + " cross or touch (not a simple polygon)");
    }
  }
}

bool Polygon::contains(const Vec<2>& x) const {
  if (x[0] < lower_[0] || x[0] > upper_[0] || x[1] < lower_[1] || x[1] > upper_[1]) return false;
  // Crossing number (even-odd rule) of a ray towards +x; for a simple polygon it equals the
  // winding-number test and does not depend on the orientation. The half-open rule on the edge's
  // y range counts a ray through a vertex exactly once.
  const std::size_t n = vertices_.size();
  const double size = (upper_ - lower_).norm();
  bool inside = false;
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec<2>& a = vertices_[j];
    const Vec<2>& b = vertices_[i];
    // Points on an edge belong to the polygon, as boundary points of every primitive do.
    const Vec<2> e = b - a;
    if (std::abs(cross(e, x - a)) <= 1e-12 * size * e.norm() && on_segment_box(a, b, x))
      return true;
    if ((a[1] > x[1]) != (b[1] > x[1])) {
      const double x_cross = a[0] + (x[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
      if (x[0] < x_cross) inside = !inside;
    }
  }
  return inside;
}

// ---- Union --------------------------------------------------------------------------------

template <int D>
Union<D>::Union(std::vector<ShapePtr<D>> parts) : parts_(std::move(parts)) {
  if (parts_.empty()) throw std::invalid_argument("union: needs at least one shape");
  for (std::size_t k = 0; k < parts_.size(); ++k)
    if (!parts_[k]) throw std::invalid_argument("union: shape " + std::to_string(k) + " is null");
  std::tie(lower_, upper_) = parts_[0]->bounds();
  for (const auto& p : parts_) {
    const auto [lo, hi] = p->bounds();
    lower_ = lower_.cwiseMin(lo);
    upper_ = upper_.cwiseMax(hi);
  }
}

template <int D>
bool Union<D>::contains(const Vec<D>& x) const {
  for (const auto& p : parts_)
    if (p->contains(x)) return true;
  return false;
}

// ---- Difference ---------------------------------------------------------------------------

template <int D>
Difference<D>::Difference(ShapePtr<D> a, ShapePtr<D> b) : a_(std::move(a)), b_(std::move(b)) {
  if (!a_ || !b_) throw std::invalid_argument("difference: both shapes must be given (null)");
}

template <int D>
bool Difference<D>::contains(const Vec<D>& x) const {
  return a_->contains(x) && !b_->contains(x);
}

template class Box<2>;
template class Box<3>;
template class Ellipsoid<2>;
template class Ellipsoid<3>;
template class Union<2>;
template class Union<3>;
template class Difference<2>;
template class Difference<3>;

}  // namespace cosph
