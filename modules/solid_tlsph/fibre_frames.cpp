#include "solid_tlsph/fibre_frames.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "driver/scene_geometry.hpp"
#include "geometry/csv_table.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {

template <int D>
Mat<D> orthonormal_frame(const Vec<D>& f_in, const Vec<D>& s_in) {
  if (!(f_in.norm() > 0.0) || !f_in.allFinite())
    throw std::invalid_argument("fibre direction is zero or not finite");
  const Vec<D> f = f_in.normalized();
  Vec<D> s = s_in - s_in.dot(f) * f;
  if (!(s.norm() > 1e-6 * s_in.norm()) || !s.allFinite())
    throw std::invalid_argument("sheet direction is zero or parallel to the fibre");
  s.normalize();
  Mat<D> frame;
  frame.col(0) = f;
  frame.col(1) = s;
  if constexpr (D == 3) frame.col(2) = f.cross(s);
  return frame;
}

Mat<3> frame_turned_about_sheet(const Mat<3>& frame, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  Mat<3> turned;
  turned.col(0) = c * frame.col(0) + s * frame.col(2);
  turned.col(1) = frame.col(1);
  turned.col(2) = -s * frame.col(0) + c * frame.col(2);
  return turned;
}

Mat<3> land_ellipsoid_frame(const proto::EllipsoidFibreRule& rule, const Vec<3>& x) {
  const double rho = std::hypot(x[0], x[1]);
  auto short_radius = [&](double t) {
    return rule.inner_short_radius() + t * (rule.outer_short_radius() - rule.inner_short_radius());
  };
  auto long_radius = [&](double t) {
    return rule.inner_long_radius() + t * (rule.outer_long_radius() - rule.inner_long_radius());
  };
  // g(t) = (rho / r_s(t))^2 + (z / r_l(t))^2 - 1 decreases with t (the walls grow outwards).
  auto g = [&](double t) {
    const double a = rho / short_radius(t), b = x[2] / long_radius(t);
    return a * a + b * b - 1.0;
  };
  double lo = 0.0, hi = 1.0;
  double t = g(lo) <= 0.0 ? 0.0 : g(hi) >= 0.0 ? 1.0 : -1.0;
  if (t < 0.0) {
    for (int k = 0; k < 60; ++k) {
      const double mid = 0.5 * (lo + hi);
      (g(mid) > 0.0 ? lo : hi) = mid;
    }
    t = 0.5 * (lo + hi);
  }
  const double rs = short_radius(t), rl = long_radius(t);
  const double u = std::atan2(rho / rs, x[2] / rl);  // in [0, pi]: z = r_l cos u, rho = r_s sin u
  const double v = rho > 0.0 ? std::atan2(x[1], x[0]) : 0.0;
  // Tangents of x(u, v) = (r_s sin u cos v, r_s sin u sin v, r_l cos u). Land's u is the negative
  // of ours, so his d/du is minus ours; d/dv agrees.
  const Vec<3> along_u =
      -Vec<3>(rs * std::cos(u) * std::cos(v), rs * std::cos(u) * std::sin(v), -rl * std::sin(u))
           .normalized();
  const Vec<3> along_v(-std::sin(v), std::cos(v), 0.0);
  const double degrees =
      rule.endocardial_angle() + t * (rule.epicardial_angle() - rule.endocardial_angle());
  const double angle = degrees * std::numbers::pi / 180.0;
  const Vec<3> fibre = std::cos(angle) * along_v + std::sin(angle) * along_u;
  const Vec<3> normal = along_u.cross(along_v);
  return orthonormal_frame<3>(fibre, normal);
}

namespace {

template <int D>
std::string where(const Vec<D>& x) {
  std::ostringstream s;
  s << "(" << x.transpose() << ")";
  return s.str();
}

template <int D>
std::vector<Mat<D>> frames_from_csv(const std::string& file, const std::vector<Vec<D>>& X,
                                    double spacing, const std::string& key) {
  std::vector<std::string> required = {"x", "y"}, optional;
  if (D == 3) required.push_back("z");
  for (const char* c : {"fx", "fy", "fz"})
    if (required.size() < std::size_t(2 * D)) required.push_back(c);
  for (const char* c : {"sx", "sy", "sz"})
    if (optional.size() < std::size_t(D)) optional.push_back(c);
  CsvColumns table;
  try {
    table = read_csv_columns(file, required, optional, "fibre");
  } catch (const RuntimeError& e) {
    throw ConfigError(key, e.what());
  }
  int sheet_columns = 0;
  for (int a = 0; a < D; ++a) sheet_columns += !table.values[2 * D + a].empty();
  if (sheet_columns != 0 && sheet_columns != D)
    throw ConfigError(key, file + ": give all of the sheet columns (sx, sy" +
                               std::string(D == 3 ? ", sz" : "") + ") or none");
  const bool sheets = sheet_columns == D;
  std::vector<Vec<D>> points(table.rows()), fibres(table.rows()), sheet(table.rows());
  for (std::size_t r = 0; r < table.rows(); ++r)
    for (int a = 0; a < D; ++a) {
      points[r][a] = table.values[a][r];
      fibres[r][a] = table.values[D + a][r];
      sheet[r][a] = sheets ? table.values[2 * D + a][r] : (a == 1 ? 1.0 : 0.0);
    }
  const double radius = 2.0 * spacing;
  const CellLinkedList<D> cells(points, radius, Domain<D>{});
  std::vector<Mat<D>> frames(X.size());
  constexpr Index kNone = std::numeric_limits<Index>::max();
  for (std::size_t i = 0; i < X.size(); ++i) {
    Index nearest = kNone;
    double best = INFINITY;
    cells.for_each_neighbour(X[i], radius, kNone, [&](Index r) {
      const double d = (points[r] - X[i]).squaredNorm();
      if (d < best || (d == best && r < nearest)) {
        best = d;
        nearest = r;
      }
    });
    if (nearest == kNone)
      throw ConfigError(key, file + ": no row within 2 spacings of the particle at " + where(X[i]));
    Vec<D> s = sheet[nearest];
    if (!sheets && std::abs(fibres[nearest].normalized().dot(s)) > 0.9) s = Vec<D>::Unit(0);
    try {
      frames[i] = orthonormal_frame<D>(fibres[nearest], s);
    } catch (const std::invalid_argument& e) {
      throw ConfigError(key, file + ":" + std::to_string(table.lines[nearest]) + ": " + e.what());
    }
  }
  return frames;
}

}  // namespace

template <int D>
std::vector<Mat<D>> build_fibre_frames(const proto::FibreSpec& spec, const std::vector<Vec<D>>& X,
                                       double spacing, const std::string& key,
                                       const std::string& scene_directory) {
  const int sources = (spec.fibre_size() > 0) + spec.has_csv() + spec.has_ellipsoid_rule();
  if (sources > 1) throw ConfigError(key, "give one of: fibre (and sheet), csv, ellipsoid_rule");
  if (spec.has_csv()) {
    std::filesystem::path file(spec.csv());
    if (file.is_relative()) file = std::filesystem::path(scene_directory) / file;
    return frames_from_csv<D>(file.string(), X, spacing, key + ".csv");
  }
  if (spec.has_ellipsoid_rule()) {
    if constexpr (D == 3) {
      std::vector<Mat<3>> frames(X.size());
      parallel_for_each_index(X.size(), [&](std::size_t i) {
        frames[i] = land_ellipsoid_frame(spec.ellipsoid_rule(), X[i]);
      });
      return frames;
    }
    throw ConfigError(key + ".ellipsoid_rule", "the ellipsoid rule is 3D");
  }
  const Vec<D> f = spec.fibre_size() > 0 ? to_vec<D>(spec.fibre()) : Vec<D>(Vec<D>::Unit(0));
  Vec<D> s = spec.sheet_size() > 0 ? to_vec<D>(spec.sheet()) : Vec<D>(Vec<D>::Unit(1));
  if (spec.sheet_size() == 0 && std::abs(f.normalized().dot(s)) > 0.9) s = Vec<D>::Unit(0);
  try {
    return std::vector<Mat<D>>(X.size(), orthonormal_frame<D>(f, s));
  } catch (const std::invalid_argument& e) {
    throw ConfigError(key + (spec.fibre_size() > 0 ? ".fibre" : ".sheet"), e.what());
  }
}

template <int D>
std::vector<char> fibre_undefined_in_wall(const proto::FibreSpec& spec,
                                          const std::vector<Vec<D>>& X) {
  if constexpr (D == 3) {
    if (!spec.has_ellipsoid_rule()) return {};
    // On the axis up to the round-off of a placement's trigonometry; the nearest off-axis
    // particles lie about a spacing away.
    const double tolerance = 1e-9 * spec.ellipsoid_rule().outer_short_radius();
    std::vector<char> undefined(X.size(), 0);
    bool any = false;
    for (std::size_t i = 0; i < X.size(); ++i)
      if (std::hypot(X[i][0], X[i][1]) <= tolerance) undefined[i] = any = true;
    return any ? undefined : std::vector<char>{};
  } else {
    (void)spec;
    (void)X;
    return {};
  }
}

template Mat<2> orthonormal_frame<2>(const Vec<2>&, const Vec<2>&);
template Mat<3> orthonormal_frame<3>(const Vec<3>&, const Vec<3>&);
template std::vector<char> fibre_undefined_in_wall<2>(const proto::FibreSpec&,
                                                      const std::vector<Vec<2>>&);
template std::vector<char> fibre_undefined_in_wall<3>(const proto::FibreSpec&,
                                                      const std::vector<Vec<3>>&);
template std::vector<Mat<2>> build_fibre_frames<2>(const proto::FibreSpec&,
                                                   const std::vector<Vec<2>>&, double,
                                                   const std::string&, const std::string&);
template std::vector<Mat<3>> build_fibre_frames<3>(const proto::FibreSpec&,
                                                   const std::vector<Vec<3>>&, double,
                                                   const std::string&, const std::string&);

}  // namespace cosph
