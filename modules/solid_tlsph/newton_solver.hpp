// Newton's method for a static equilibrium R(x) = 0 on the free unknowns x, with a sparse tangent
// K = -dR/dx factorised by a sparse Cholesky solver (CHOLMOD's supernodal LL^T; a simplicial
// LDL^T where K is not positive definite) and a line search along each step. The tangent's
// pattern is the same at every call (it comes from the reference pairs), so the fill-reducing
// ordering and the symbolic factorisation are computed once per solver.
//
// The residual is a force: converged when |R| <= tolerance * scale, where the residual callback
// returns the scale (the size of the forces in balance), so that the tolerance is relative.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>

namespace cosph {

struct NewtonSettings {
  double tolerance = 1e-8;
  int max_iterations = 25;
};

struct NewtonOutcome {
  bool converged = false;
  int iterations = 0;              // tangent solves
  int residual_evaluations = 0;    // line-search trials included
  double relative_residual = 0.0;  // |R| / scale at the returned x
};

class NewtonSolver {
 public:
  // Fills r = R(x) and returns the force scale; a non-finite r marks x as inadmissible (an
  // inverted particle), and the line search steps back from it.
  using Residual = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd& r)>;
  // K = -dR/dx at x (symmetric: its lower triangle is used), called right after Residual(x).
  using Tangent = std::function<Eigen::SparseMatrix<double>(const Eigen::VectorXd& x)>;

  // Iterates from x; leaves the last accepted iterate in x (the last residual call may have been
  // a rejected trial: a caller that keeps state from the callbacks evaluates x again).
  NewtonOutcome solve(Eigen::VectorXd& x, const Residual& residual, const Tangent& tangent,
                      const NewtonSettings& settings);

  NewtonSolver();
  ~NewtonSolver();
  NewtonSolver(NewtonSolver&&) noexcept;
  NewtonSolver& operator=(NewtonSolver&&) noexcept;

  double factorisation_seconds() const { return factorisation_seconds_; }

 private:
  struct Factorisation;  // the sparse solvers (newton_solver.cpp), kept out of this header
  std::unique_ptr<Factorisation> factorisation_;
  double factorisation_seconds_ = 0.0;
};

}  // namespace cosph
