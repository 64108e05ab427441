// A quasi-Newton method for a static equilibrium R(x) = 0 on the free unknowns x: L-BFGS whose
// initial inverse is a lagged sparse tangent K = -dR/dx, factorised by CHOLMOD's supernodal
// Cholesky (shifted where K is not positive definite) and refreshed only when it stops paying,
// with a line search along each step. The tangent's pattern is the same at every call (it comes
// from the reference pairs), so the fill-reducing ordering and the symbolic factorisation are
// computed once per solver.
//
// The residual is a force: converged when |R| <= tolerance * scale, where the residual callback
// returns the scale (the size of the forces in balance), so that the tolerance is relative.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <functional>
#include <memory>
#include <vector>

namespace cosph {

struct NewtonSettings {
  double tolerance = 1e-8;
  int max_iterations = 200;
  // A new tangent is assembled and factorised when an iteration multiplies |R| by more than this
  // ratio (the lagged one has stopped describing the body), or after `history` quasi-Newton
  // iterations on one factorisation. Measured on Land's beam (2 load steps, 2 threads, before
  // BLAS was held to one thread): a factorisation costs 1.1-1.6 s at 4,544 particles against
  // 0.02-0.03 s per iteration, and refreshing only on a full history of 60 took 151 iterations, 4
  // factorisations, 12.6-14.4 s (1,025 particles: 153, 4, 1.5-1.8 s); a ratio of 10 or 100
  // refreshed 6 times (14.7-16.2 s), a history of 100 took 226 iterations (14.4 s), exact Newton 38
  // iterations and 77.6 s.
  double refresh_ratio = 1000.0;
  int history = 60;
};

struct NewtonOutcome {
  bool converged = false;
  int iterations = 0;              // quasi-Newton steps taken (each a line search)
  int factorisations = 0;          // tangents assembled and factorised
  int shifted_factorisations = 0;  // of which not positive definite (factorised as K + mu I)
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
  //
  // The factorisation of a converged solve is kept as the next solve's first inverse: a load
  // increment starts next to the equilibrium whose tangent was last factorised, and a
  // factorisation costs as much as 50-100 iterations (Land's ventricle at 18,616 particles: 23 s
  // against 0.3-0.4 s). A solve that fails drops it, so that a bisected increment starts from a
  // fresh tangent. The quasi-Newton history is not kept: its pairs measured the last load.
  NewtonOutcome solve(Eigen::VectorXd& x, const Residual& residual, const Tangent& tangent,
                      const NewtonSettings& settings);

  // Whether the next solve starts on a kept factorisation (no tangent call before its first
  // step).
  bool has_factorisation() const { return kept_; }
  // The next solve starts on a fresh tangent (a guess far from the last equilibrium).
  void drop_factorisation() { kept_ = false; }
  // Factorises K as if a converged solve had left it (a restart rebuilds the kept factorisation
  // from the checkpoint). Not counted in any outcome. Returns false where K does not factorise.
  bool adopt_tangent(const Eigen::SparseMatrix<double>& K);

  NewtonSolver();
  ~NewtonSolver();
  NewtonSolver(NewtonSolver&&) noexcept;
  NewtonSolver& operator=(NewtonSolver&&) noexcept;

  // Where a solve's time went, summed over every solve of this solver: the factorisations, the
  // triangular solves of the directions, and the residual calls (line-search trials included).
  double factorisation_seconds() const { return factorisation_seconds_; }
  double triangular_solve_seconds() const { return triangular_solve_seconds_; }
  double residual_seconds() const { return residual_seconds_; }

 private:
  struct Factorisation;  // the sparse solvers (newton_solver.cpp), kept out of this header
  struct Iterate {
    Eigen::VectorXd x, r;
    double norm = 0.0, scale = 0.0;
  };
  struct HistoryPair {
    Eigen::VectorXd s, y;
    double rho = 0.0;
  };

  Eigen::VectorXd direction(const Eigen::VectorXd& r);
  void evaluate(const Residual& residual, Iterate& at, NewtonOutcome& outcome);
  bool line_search(const Eigen::VectorXd& step, const Residual& residual, Iterate& at,
                   NewtonOutcome& outcome);
  int factorise(const Eigen::SparseMatrix<double>& K);  // shifted attempts, or -1
  bool refresh_tangent(const Eigen::VectorXd& x, const Tangent& tangent, NewtonOutcome& outcome);

  std::unique_ptr<Factorisation> factorisation_;
  std::vector<HistoryPair> history_;
  Iterate trial_;
  double factorisation_seconds_ = 0.0, triangular_solve_seconds_ = 0.0, residual_seconds_ = 0.0;
  bool factorised_ = false;  // the last factorisation succeeded
  bool kept_ = false;  // it is from a converged solve (or adopted): the next solve starts on it
};

}  // namespace cosph
