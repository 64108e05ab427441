// Point probes: field values interpolated at fixed points, e.g. a pressure sensor on a wall or
// the concentration at the centre of a domain, for time-series output.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "core/particles.hpp"
#include "core/types.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/domain.hpp"

namespace cosph {

// Samples named fields of one body at fixed points with the Shepard-normalised SPH interpolant
//   f(x) = sum_j V_j f_j W(|x - x_j|) / sum_j V_j W(|x - x_j|),
// over the particles j within the kernel support of x (minimum image on periodic axes). The
// normalisation makes constants exact even near free surfaces and walls, where the plain sum
// would be truncated; linear fields are exact where the neighbourhood is symmetric about x.
// A point with no particle within the support has no value: it yields NaN (CSV writes "nan"),
// so that a sensor that has run dry shows as a gap in a plot instead of a misleading 0.
// How a probe finds and weighs the particles around a point.
struct ProbeOptions {
  // The vector field holding the positions the points refer to: "position" (current
  // configuration) or, for material points of a moving body, "reference_position".
  std::string position_field = "position";
  // shepard: the normalised average. linear: moving least squares, f(x) = a of the weighted fit
  // f_j ~ a + b . (x_j - x), exact for linear fields also at corners and edges where the average
  // is biased by the one-sided neighbourhood. quadratic: the same fit with the second-order
  // terms, exact for quadratic fields: the average and the linear fit both smooth a curved field
  // by O(h^2) (a Gaussian of width 4 h reads 1.5% low at its peak), which can exceed the error of
  // the particle values themselves. Each falls back to the lower order where its fit is singular.
  enum class Interpolation { shepard, linear, quadratic };
  Interpolation interpolation = Interpolation::shepard;
};

template <int D>
class PointProbe {
 public:
  // `fields` name what is sampled at every point: "name" is the scalar field `name`, and
  // "name.x", "name.y", "name.z" a component of the vector field `name` (resolved when sampling,
  // where a scalar field literally called "name.x" takes precedence). `labels` name the points in
  // the column names, one per point; empty means "p0", "p1", ... Throws std::invalid_argument if
  // the number of labels does not match.
  PointProbe(std::vector<Vec<D>> points, std::vector<std::string> fields,
             std::vector<std::string> labels = {}, ProbeOptions options = {});

  const std::vector<Vec<D>>& points() const { return points_; }
  const std::vector<std::string>& fields() const { return fields_; }
  const std::vector<std::string>& labels() const { return labels_; }

  // Column names "<field>@<label>", field by field and point by point within a field (all points
  // of the first field, then all of the second...), in the order of sample()'s values.
  std::vector<std::string> columns() const;

  // Interpolated values in the order of columns(). Positions come from the options' position field,
  // volumes V_j from `volumes` (one per particle, e.g. m/rho computed by the caller) or from the
  // scalar field `volume_field`. Throws cosph::RuntimeError naming the body and field if a field
  // is missing, std::invalid_argument if the kernel's dimension is not D or `volumes` has the
  // wrong size. Deterministic: each point sums its neighbours in the search's fixed order.
  std::vector<double> sample(const ParticleSet<D>& particles, std::span<const double> volumes,
                             const Kernel& kernel, const Domain<D>& domain) const;
  std::vector<double> sample(const ParticleSet<D>& particles, const std::string& volume_field,
                             const Kernel& kernel, const Domain<D>& domain) const;

 private:
  std::vector<Vec<D>> points_;
  std::vector<std::string> fields_;
  std::vector<std::string> labels_;
  ProbeOptions options_;
  int order_;  // of the fit: 0 Shepard, 1 linear, 2 quadratic
};

extern template class PointProbe<2>;
extern template class PointProbe<3>;

}  // namespace cosph
