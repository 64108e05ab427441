#include "solid_tlsph/static_equilibrium.hpp"

#include "core/error.hpp"
#include "core/scoped_seconds.hpp"

namespace cosph {

template <int D>
StaticEquilibrium<D>::StaticEquilibrium(const ReferencePairs<D>& pairs,
                                        const std::vector<double>& volume,
                                        const std::vector<char>& prescribed)
    : pairs_(pairs), volume_(volume), dof_(prescribed.size(), -1) {
  for (std::size_t k = 0; k < prescribed.size(); ++k)
    if (!prescribed[k]) dof_[k] = unknowns_++;
  // A particle's free components are consecutive unknowns: one block each.
  for (std::size_t k = 0; k < dof_.size(); k += D)
    for (int a = 0; a < D; ++a)
      if (dof_[k + a] >= 0) {
        block_start_.push_back(dof_[k + a]);
        break;
      }
  block_start_.push_back(unknowns_);
  pattern_ = build_tangent_pattern<D>(pairs);
}

template <int D>
void StaticEquilibrium<D>::scatter(const Eigen::VectorXd& x, std::vector<Vec<D>>& u) const {
  for (std::size_t k = 0; k < dof_.size(); ++k)
    if (dof_[k] >= 0) u[k / D][static_cast<int>(k % D)] = x[dof_[k]];
}

// The tangent at the F of the body's last force call, with the loads of tangent_time.
template <int D>
Eigen::SparseMatrix<double> StaticEquilibrium<D>::assemble(const Body& body, double tangent_time) {
  const ScopedSeconds timer(assembly_seconds_);
  body.tangents(tangent_time, C_, loaded_, L_);
  return assemble_tangent<D>(pairs_, pattern_, volume_, C_, loaded_, L_, dof_, unknowns_,
                             body.control, body.quadrature);
}

template <int D>
Eigen::VectorXd StaticEquilibrium<D>::gather(const std::vector<Vec<D>>& u) const {
  Eigen::VectorXd x(unknowns_);
  for (std::size_t k = 0; k < dof_.size(); ++k)
    if (dof_[k] >= 0) x[dof_[k]] = u[k / D][static_cast<int>(k % D)];
  return x;
}

// R(x) on the free components into r, through `trial` (u with x scattered into it); returns the
// force scale.
template <int D>
double StaticEquilibrium<D>::residual(double t, const Eigen::VectorXd& x, Eigen::VectorXd& r,
                                      std::vector<Vec<D>>& trial, const Body& body) {
  scatter(x, trial);
  force_.resize(trial.size());
  const double scale = body.force(t, trial, force_);
  for (std::size_t k = 0; k < dof_.size(); ++k)
    if (dof_[k] >= 0) r[dof_[k]] = force_[k / D][static_cast<int>(k % D)];
  return scale;
}

template <int D>
NewtonOutcome StaticEquilibrium<D>::solve(double t_start, double t, std::vector<Vec<D>>& u,
                                          const Body& body, const NewtonSettings& settings) {
  body.prescribe(t, u);
  Eigen::VectorXd x = gather(u);
  std::vector<Vec<D>> trial = u;
  const auto R = [&](const Eigen::VectorXd& y, Eigen::VectorXd& r) {
    return residual(t, y, r, trial, body);
  };
  // The first tangent a solve assembles itself is at the start (the callback follows the residual
  // of x); on a kept factorisation the first one it assembles is a refresh, at the load of t.
  bool first = !solver_.has_factorisation();
  const auto tangent = [&](const Eigen::VectorXd& y) {
    tangent_point_.u = trial;
    scatter(y, tangent_point_.u);
    tangent_point_.force_time = t;
    tangent_point_.tangent_time = first ? t_start : t;
    first = false;
    return assemble(body, tangent_point_.tangent_time);
  };
  const NewtonOutcome outcome = solver_.solve(x, R, tangent, settings);
  scatter(x, u);
  return outcome;
}

template <int D>
SmoothingOutcome StaticEquilibrium<D>::smooth(double t, std::vector<Vec<D>>& u, const Body& body,
                                              int sweeps) {
  const ScopedSeconds timer(smoothing_seconds_);
  solver_.drop_factorisation();
  if (sweeps <= 0) return {};  // no tangent to assemble
  body.prescribe(t, u);
  Eigen::VectorXd x = gather(u), r(unknowns_);
  std::vector<Vec<D>> trial = u;
  const auto R = [&](const Eigen::VectorXd& y, Eigen::VectorXd& out) {
    return residual(t, y, out, trial, body);
  };
  const double scale = R(x, r);
  const SmoothingOutcome outcome =
      smooth_block_jacobi(x, r, scale, R, assemble(body, t), block_start_, sweeps);
  scatter(x, u);
  return outcome;
}

template <int D>
void StaticEquilibrium<D>::restore_tangent(const TangentPoint& point, const Body& body) {
  force_.resize(point.u.size());
  body.force(point.force_time, point.u, force_);  // F at the point, for the tangent call
  if (!solver_.adopt_tangent(assemble(body, point.tangent_time)))
    throw RuntimeError("the checkpoint's steady-state tangent does not factorise");
  tangent_point_ = point;
}

template class StaticEquilibrium<2>;
template class StaticEquilibrium<3>;

}  // namespace cosph
