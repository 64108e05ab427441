// Static equilibrium of a total-Lagrangian SPH body at one load: Newton on the free
// displacement components (newton_solver.hpp) with the tangent of static_tangent.hpp. The body
// supplies its forces and the derivatives of its stresses through callbacks, so that this class
// knows the unknowns and the linear algebra and nothing of the material or the loads.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <vector>

#include "solid_tlsph/block_jacobi_smoother.hpp"
#include "solid_tlsph/newton_solver.hpp"
#include "solid_tlsph/static_tangent.hpp"

namespace cosph {

// d/dF of a function of F, by central differences of step eps in each entry (the laws' stresses
// are smooth in F; eps = 1e-6 leaves a relative error near 1e-10, below the solver's tolerance).
template <int D, int Rows>
Eigen::Matrix<double, Rows, D * D> derivative_in_F(
    const std::function<Eigen::Matrix<double, Rows, 1>(const Mat<D>&)>& f, const Mat<D>& F,
    double eps = 1e-6) {
  Eigen::Matrix<double, Rows, D * D> d;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) {
      Mat<D> plus = F, minus = F;
      plus(a, b) += eps;
      minus(a, b) -= eps;
      d.col(a * D + b) = (f(plus) - f(minus)) / (2.0 * eps);
    }
  return d;
}

// P flattened with entry (a, b) at a * D + b, the layout of MaterialTangent.
template <int D>
Eigen::Matrix<double, D * D, 1> flatten(const Mat<D>& P) {
  Eigen::Matrix<double, D * D, 1> p;
  for (int a = 0; a < D; ++a)
    for (int b = 0; b < D; ++b) p[a * D + b] = P(a, b);
  return p;
}

template <int D>
class StaticEquilibrium {
 public:
  struct Body {
    // Sets the prescribed components of u at load time t (clamps, fixed components, prescribed
    // displacements).
    std::function<void(double t, std::vector<Vec<D>>& u)> prescribe;
    // The net force on every particle at displacements u (zero on prescribed components) and
    // the scale of the forces in balance (|f_internal| and |f_external| over the free
    // components); keeps F_i of u for the tangent callback.
    std::function<double(double t, const std::vector<Vec<D>>& u, std::vector<Vec<D>>& force)> force;
    // C_i = dP/dF for every particle and L_i = df_i/dF_i for the particles with a force of their
    // own (the follower pressure), at the F of the last force call.
    std::function<void(double t, std::vector<MaterialTangent<D>>& C, std::vector<Index>& loaded,
                       std::vector<ForceTangent<D>>& L)>
        tangents;
    // A zero-energy control whose force is part of `force`: its constant stiffness joins the
    // tangent (null: none).
    const FitResidualControl<D>* control = nullptr;
    // Where the energy is integrated over each particle's dual cell: C then holds C at every
    // quadrature point, point q of particle i at i * points + q (null: C_i at the particles).
    const EnergyQuadrature<D>* quadrature = nullptr;
  };

  // prescribed[i * D + a]: component a of particle i is prescribed at every load.
  StaticEquilibrium(const ReferencePairs<D>& pairs, const std::vector<double>& volume,
                    const std::vector<char>& prescribed);

  // Solves for u at load time t, starting from the u given (prescribed components are set
  // first), the equilibrium at load time t_start (t_start = t: no earlier equilibrium). The first
  // tangent is that equilibrium's own, at the load of t_start: a stable equilibrium's tangent is
  // positive definite, where the tangent of the start under the new load need not be (a follower
  // pressure's load stiffness at full load on an unstressed body: Land's ventricle at u = 0 and
  // 10 kPa). Later tangents take the load of t. A solve that follows a converged one starts on
  // the factorisation that solve left (newton_solver.hpp), a tangent of the last equilibrium's
  // neighbourhood, instead of assembling the first one. On failure u holds the last accepted
  // iterate.
  NewtonOutcome solve(double t_start, double t, std::vector<Vec<D>>& u, const Body& body,
                      const NewtonSettings& settings);

  // Where the factorisation that the next solve starts on was taken: the displacements of the
  // body, the load time of its force call and the load time of its tangent. A checkpoint keeps it
  // so that a restart starts on the same factorisation, bit for bit, as the run it continues.
  struct TangentPoint {
    std::vector<Vec<D>> u;
    double force_time = 0.0, tangent_time = 0.0;
  };
  const TangentPoint* kept_tangent() const {
    return solver_.has_factorisation() ? &tangent_point_ : nullptr;
  }
  // Assembles and factorises the tangent at a point that kept_tangent() gave. Throws
  // RuntimeError where it does not factorise.
  void restore_tangent(const TangentPoint& point, const Body& body);

  // Damped block-Jacobi sweeps on u at the loads of t (block_jacobi_smoother.hpp; a block is a
  // particle's free components) on the tangent at u: a guess interpolated from a coarser solution
  // loses its particle-scale error. Drops the kept factorisation, so that the solve that follows
  // (with t_start = t) starts on a fresh tangent at the smoothed u.
  SmoothingOutcome smooth(double t, std::vector<Vec<D>>& u, const Body& body, int sweeps);

  long long unknowns() const { return unknowns_; }
  std::size_t tangent_blocks() const { return pattern_.column.size(); }
  const NewtonSolver& solver() const { return solver_; }
  // The tangents' evaluation and assembly, a restart's included.
  double assembly_seconds() const { return assembly_seconds_; }
  // The smoothing sweeps' time (their tangent's assembly included).
  double smoothing_seconds() const { return smoothing_seconds_; }

 private:
  void scatter(const Eigen::VectorXd& x, std::vector<Vec<D>>& u) const;
  Eigen::VectorXd gather(const std::vector<Vec<D>>& u) const;
  double residual(double t, const Eigen::VectorXd& x, Eigen::VectorXd& r,
                  std::vector<Vec<D>>& trial, const Body& body);
  Eigen::SparseMatrix<double> assemble(const Body& body, double tangent_time);

  const ReferencePairs<D>& pairs_;
  std::vector<double> volume_;
  std::vector<long long> dof_;
  long long unknowns_ = 0;
  std::vector<Eigen::Index> block_start_;  // the first unknown of each particle's, and the end
  TangentPattern pattern_;
  NewtonSolver solver_;
  std::vector<MaterialTangent<D>> C_;
  std::vector<Index> loaded_;
  std::vector<ForceTangent<D>> L_;
  std::vector<Vec<D>> force_;
  TangentPoint tangent_point_;
  double assembly_seconds_ = 0.0, smoothing_seconds_ = 0.0;
};

}  // namespace cosph
