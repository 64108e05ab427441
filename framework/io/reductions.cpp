#include "io/reductions.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "core/parallel.hpp"
#include "io/required_field.hpp"

namespace cosph {

template <int D>
double total_kinetic_energy(const ParticleSet<D>& particles) {
  const auto& m = required_scalar(particles, "mass", "the kinetic energy");
  const auto& v = required_vector(particles, "velocity", "the kinetic energy");
  return deterministic_sum(particles.size(), 0.0,
                           [&](std::size_t i) { return 0.5 * m[i] * v[i].squaredNorm(); });
}

template <int D>
double surface_height(const ParticleSet<D>& particles, const Kernel& kernel, const Vec<D>& at,
                      int axis) {
  const auto& x = required_vector(particles, "position", "a surface height");
  const auto& V = required_scalar(particles, "volume", "a surface height");
  const double support = kernel.support_radius(), h = kernel.smoothing_length();
  // The particles that can contribute anywhere on the gauge line.
  std::vector<std::size_t> near;
  double top = -INFINITY;
  for (std::size_t i = 0; i < x.size(); ++i) {
    double lateral = 0.0;
    for (int a = 0; a < D; ++a)
      if (a != axis) lateral += (x[i][a] - at[a]) * (x[i][a] - at[a]);
    if (lateral < support * support && x[i][axis] > at[axis] - support) {
      near.push_back(i);
      top = std::max(top, x[i][axis]);
    }
  }
  if (near.empty()) return at[axis];
  auto fraction = [&](double level) {
    Vec<D> p = at;
    p[axis] = level;
    double sum = 0.0;
    for (std::size_t i : near) sum += V[i] * kernel.value((p - x[i]).norm());
    return sum;
  };
  const double step = h / 8.0;
  double level = at[axis] + h, below = fraction(level);
  if (below < 0.5) return at[axis];  // dry, or a film thinner than h
  while (level < top + support) {
    const double above = fraction(level + step);
    if (above < 0.5) return level + step * (below - 0.5) / (below - above);
    level += step;
    below = above;
  }
  return level;
}

template <int D>
double front(const ParticleSet<D>& particles, int axis) {
  if (axis < 0 || axis >= D)
    throw std::invalid_argument("front: axis " + std::to_string(axis) + " out of range");
  const auto& x = required_vector(particles, "position", "a front position");
  const auto& V = required_scalar(particles, "volume", "a front position");
  double far = -INFINITY;
  for (std::size_t i = 0; i < x.size(); ++i)
    far = std::max(far, x[i][axis] + 0.5 * std::pow(V[i], 1.0 / D));
  return std::isfinite(far) ? far : std::numeric_limits<double>::quiet_NaN();
}

template <int D>
double extent(const ParticleSet<D>& particles, int axis) {
  if (axis < 0 || axis >= D)
    throw std::invalid_argument("extent: axis " + std::to_string(axis) + " out of range");
  const auto& x = required_vector(particles, "position", "the extent");
  if (x.empty()) return 0.0;
  // min and max do not depend on the order of evaluation, so a plain loop is deterministic.
  double lo = x[0][axis], hi = x[0][axis];
  for (const auto& p : x) {
    lo = std::min(lo, p[axis]);
    hi = std::max(hi, p[axis]);
  }
  return hi - lo;
}

template <int D>
Vec<D> total_vector(const ParticleSet<D>& particles, const std::string& field) {
  const auto& f = required_vector(particles, field, "a total");
  return deterministic_sum(particles.size(), Vec<D>(Vec<D>::Zero()),
                           [&](std::size_t i) { return f[i]; });
}

template <int D>
double total_scalar(const ParticleSet<D>& particles, const std::string& field) {
  const auto& f = required_scalar(particles, field, "a total");
  return deterministic_sum(particles.size(), 0.0, [&](std::size_t i) { return f[i]; });
}

template <int D>
double integral(const ParticleSet<D>& particles, const std::string& scalar_field) {
  const std::string purpose = "the integral of '" + scalar_field + "'";
  const auto& volume = required_scalar(particles, "volume", purpose);
  const auto& f = required_scalar(particles, scalar_field, purpose);
  return deterministic_sum(particles.size(), 0.0, [&](std::size_t i) { return volume[i] * f[i]; });
}

#define COSPH_INSTANTIATE_REDUCTIONS(D)                                                        \
  template double total_kinetic_energy<D>(const ParticleSet<D>&);                              \
  template double extent<D>(const ParticleSet<D>&, int);                                       \
  template double front<D>(const ParticleSet<D>&, int);                                        \
  template double surface_height<D>(const ParticleSet<D>&, const Kernel&, const Vec<D>&, int); \
  template Vec<D> total_vector<D>(const ParticleSet<D>&, const std::string&);                  \
  template double total_scalar<D>(const ParticleSet<D>&, const std::string&);                  \
  template double integral<D>(const ParticleSet<D>&, const std::string&);
COSPH_INSTANTIATE_REDUCTIONS(2)
COSPH_INSTANTIATE_REDUCTIONS(3)

}  // namespace cosph
