#include "io/probes.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "core/parallel.hpp"
#include "io/required_field.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {

namespace {

// One sampled quantity as a strided view of a field's raw doubles: value of particle j is
// data[j * stride + component].
struct FieldView {
  const double* data;
  std::size_t stride;
  std::size_t component;
};

template <int D>
FieldView resolve(const ParticleSet<D>& particles, const std::string& spec) {
  const std::string purpose = "point probe '" + spec + "'";
  if (particles.has(spec) && particles.info(spec).kind == FieldKind::Scalar)
    return {particles.scalar(spec).data(), 1, 0};
  const std::size_t dot = spec.rfind('.');
  if (dot != std::string::npos && dot + 2 == spec.size()) {
    const char axis = spec.back();
    const int component = axis == 'x' ? 0 : axis == 'y' ? 1 : axis == 'z' ? 2 : -1;
    if (component >= D)
      throw RuntimeError("point probe '" + spec + "': body '" + particles.name() + "' is " +
                         std::to_string(D) + "D, it has no z component");
    if (component >= 0) {
      const std::string base = spec.substr(0, dot);
      require_field(particles, base, FieldKind::Vector, purpose);
      return {particles.raw(base).data(), D, static_cast<std::size_t>(component)};
    }
  }
  require_field(particles, spec, FieldKind::Scalar, purpose);
  return {};  // not reached: require_field throws
}

// The fit's basis: 1, then the D components of d, then the D (D + 1) / 2 products d_a d_b
// (a <= b). basis_size(order) says how many of them a fit of that order uses.
template <int D>
constexpr int kBasisMax = (D + 1) * (D + 2) / 2;

template <int D>
int basis_size(int order) {
  return order == 0 ? 1 : order == 1 ? D + 1 : kBasisMax<D>;
}

template <int D>
Eigen::Matrix<double, kBasisMax<D>, 1> basis(const Vec<D>& d) {
  Eigen::Matrix<double, kBasisMax<D>, 1> b;
  b[0] = 1.0;
  int k = 1;
  for (int a = 0; a < D; ++a) b[k++] = d[a];
  for (int a = 0; a < D; ++a)
    for (int c = a; c < D; ++c) b[k++] = d[a] * d[c];
  return b;
}

template <int D>
Eigen::Matrix<double, kBasisMax<D>, 1> basis_scale(double h) {
  Eigen::Matrix<double, kBasisMax<D>, 1> s;
  s.setConstant(1.0 / (h * h));
  s[0] = 1.0;
  s.template segment<D>(1).setConstant(1.0 / h);
  return s;
}

}  // namespace

template <int D>
PointProbe<D>::PointProbe(std::vector<Vec<D>> points, std::vector<std::string> fields,
                          std::vector<std::string> labels, ProbeOptions options)
    : points_(std::move(points)),
      fields_(std::move(fields)),
      labels_(std::move(labels)),
      options_(std::move(options)),
      order_(static_cast<int>(options_.interpolation)) {
  if (labels_.empty())
    for (std::size_t p = 0; p < points_.size(); ++p) {
      // Appended rather than "p" + to_string(p), which trips GCC 12's false -Wrestrict
      // (GCC bug 105329) at -O3.
      std::string label = "p";
      labels_.push_back(label.append(std::to_string(p)));
    }
  if (labels_.size() != points_.size())
    throw std::invalid_argument("point probe: " + std::to_string(labels_.size()) + " labels for " +
                                std::to_string(points_.size()) + " points");
}

template <int D>
std::vector<std::string> PointProbe<D>::columns() const {
  std::vector<std::string> names;
  for (const auto& f : fields_)
    for (const auto& l : labels_) names.push_back(f + "@" + l);
  return names;
}

template <int D>
std::vector<double> PointProbe<D>::sample(const ParticleSet<D>& particles,
                                          const std::string& volume_field, const Kernel& kernel,
                                          const Domain<D>& domain) const {
  const auto& volumes = required_scalar(particles, volume_field, "point probes");
  return sample(particles, std::span<const double>(volumes), kernel, domain);
}

template <int D>
std::vector<double> PointProbe<D>::sample(const ParticleSet<D>& particles,
                                          std::span<const double> volumes, const Kernel& kernel,
                                          const Domain<D>& domain) const {
  if (kernel.dimension() != D)
    throw std::invalid_argument("point probe: " + std::to_string(kernel.dimension()) +
                                "D kernel for a " + std::to_string(D) + "D body");
  if (volumes.size() != particles.size())
    throw std::invalid_argument("point probe: " + std::to_string(volumes.size()) + " volumes for " +
                                std::to_string(particles.size()) + " particles of body '" +
                                particles.name() + "'");
  const auto& x = required_vector(particles, options_.position_field, "point probes");
  std::vector<FieldView> views;
  for (const auto& f : fields_) views.push_back(resolve(particles, f));

  const std::size_t np = points_.size(), nf = fields_.size();
  std::vector<double> values(nf * np, std::numeric_limits<double>::quiet_NaN());
  if (particles.size() == 0 || np == 0) return values;

  const double support = kernel.support_radius();
  // Points beyond the particles' bounding box (plus the support) on a non-periodic axis have no
  // neighbours; they are answered here, which also keeps far-away points out of the cell
  // search (its cell index of such a point could overflow an int).
  Vec<D> lo = x[0], hi = x[0];
  for (const auto& p : x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const CellLinkedList<D> cells(x, support, domain);
  constexpr Index kNone = std::numeric_limits<Index>::max();

  using Moment = Eigen::Matrix<double, kBasisMax<D>, kBasisMax<D>>;
  using Basis = Eigen::Matrix<double, kBasisMax<D>, 1>;
  parallel_for_each_index(np, [&](std::size_t p) {
    const Vec<D> point = domain.wrap(points_[p]);
    if (!point.allFinite()) return;
    for (int a = 0; a < D; ++a)
      if (!domain.periodic[a] && (point[a] < lo[a] - support || point[a] > hi[a] + support)) return;
    // Moments of the weighted fit: M = sum w b b^T, r_f = sum w f b, with the basis
    // b = [1, d, (d d^T)'s upper triangle] truncated to the order asked, d = x_j - x.
    Moment M = Moment::Zero();
    std::vector<Basis> rhs(nf, Basis::Zero());
    const int size = basis_size<D>(order_);
    cells.for_each_neighbour(point, support, kNone, [&](Index j) {
      const Vec<D> d = domain.displacement(x[j], point);
      const double w = volumes[j] * kernel.value(d.norm());
      const Basis b = basis<D>(d);
      M.topLeftCorner(size, size).noalias() += w * b.head(size) * b.head(size).transpose();
      for (std::size_t f = 0; f < nf; ++f)
        rhs[f] += (w * views[f].data[j * views[f].stride + views[f].component]) * b;
    });
    if (M(0, 0) == 0.0) return;  // NaN stays: nothing (of non-zero volume) within the support
    // Scaled by h per power of d so that the condition number reflects geometry, not units.
    const Basis scale = basis_scale<D>(kernel.smoothing_length());
    for (int order = order_; order > 0; --order) {
      const int n = basis_size<D>(order);
      const auto s = scale.head(n).asDiagonal();
      const Eigen::MatrixXd S = s * M.topLeftCorner(n, n) * s;
      const Eigen::FullPivLU<Eigen::MatrixXd> lu(S);
      if (lu.rank() == n && lu.rcond() > 1e-6) {
        for (std::size_t f = 0; f < nf; ++f) {
          const Eigen::VectorXd c = lu.solve(s * rhs[f].head(n));
          values[f * np + p] = c[0];  // a = f at the point (scale[0] = 1)
        }
        return;
      }
    }
    for (std::size_t f = 0; f < nf; ++f) values[f * np + p] = rhs[f][0] / M(0, 0);
  });
  return values;
}

template class PointProbe<2>;
template class PointProbe<3>;

}  // namespace cosph
