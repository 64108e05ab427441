#include "solid_tlsph/static_equilibrium.hpp"

namespace cosph {

template <int D>
StaticEquilibrium<D>::StaticEquilibrium(const ReferencePairs<D>& pairs,
                                        const std::vector<double>& volume,
                                        const std::vector<char>& prescribed)
    : pairs_(pairs), volume_(volume), dof_(prescribed.size(), -1) {
  for (std::size_t k = 0; k < prescribed.size(); ++k)
    if (!prescribed[k]) dof_[k] = unknowns_++;
  pattern_ = build_tangent_pattern<D>(pairs);
}

template <int D>
void StaticEquilibrium<D>::scatter(const Eigen::VectorXd& x, std::vector<Vec<D>>& u) const {
  for (std::size_t k = 0; k < dof_.size(); ++k)
    if (dof_[k] >= 0) u[k / D][static_cast<int>(k % D)] = x[dof_[k]];
}

template <int D>
NewtonOutcome StaticEquilibrium<D>::solve(double t_start, double t, std::vector<Vec<D>>& u,
                                          const Body& body, const NewtonSettings& settings) {
  body.prescribe(t, u);
  Eigen::VectorXd x(unknowns_);
  for (std::size_t k = 0; k < dof_.size(); ++k)
    if (dof_[k] >= 0) x[dof_[k]] = u[k / D][static_cast<int>(k % D)];
  std::vector<Vec<D>> trial = u;
  force_.resize(u.size());
  const auto residual = [&](const Eigen::VectorXd& y, Eigen::VectorXd& r) {
    scatter(y, trial);
    const double scale = body.force(t, trial, force_);
    for (std::size_t k = 0; k < dof_.size(); ++k)
      if (dof_[k] >= 0) r[dof_[k]] = force_[k / D][static_cast<int>(k % D)];
    return scale;
  };
  bool first = true;
  const auto tangent = [&](const Eigen::VectorXd&) {
    body.tangents(first ? t_start : t, C_, loaded_, L_);
    first = false;
    return assemble_tangent<D>(pairs_, pattern_, volume_, C_, loaded_, L_, dof_, unknowns_,
                               body.control);
  };
  const NewtonOutcome outcome = solver_.solve(x, residual, tangent, settings);
  scatter(x, u);
  return outcome;
}

template class StaticEquilibrium<2>;
template class StaticEquilibrium<3>;

}  // namespace cosph
