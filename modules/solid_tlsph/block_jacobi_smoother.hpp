// Damped block-Jacobi smoothing of a nonlinear residual: the smoother of a multigrid cycle, used
// on a guess interpolated from a coarser solution (grid sequencing, solid_module.cpp). The guess
// is right at the coarse scale and wrong at the fine particles' scale; the sweeps remove the
// particle-scale part of its error, which Jacobi damps fast, and leave the smooth part to Newton.
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "solid_tlsph/newton_solver.hpp"

namespace cosph {

struct SmoothingOutcome {
  int sweeps = 0;                 // taken (the best iterate is kept: it may be an earlier one)
  double initial_residual = 0.0;  // |R| / scale at the guess
  double final_residual = 0.0;    // and at the returned x
};

// Sweeps x += omega B^-1 R(x), B the diagonal blocks of K (K = -dR/dx at x, its lower triangle
// stored; block b spans the unknowns [block_start[b], block_start[b + 1])), omega = 1 / lambda
// with lambda the largest eigenvalue of B^-1 K estimated by power iteration. Power iteration
// approaches lambda_max from below, and the sweeps are stable for omega < 2 / lambda_max, so an
// estimate above half of it is safe; the modes near lambda_max, the particle-scale ones, are
// damped most. A block that is not positive definite (an indefinite tangent at the guess) takes
// the inverse of its diagonal's magnitudes. `r` and `scale` are R(x) and its force scale on
// entry; on return x is the iterate of least |R| (a sweep that makes R non-finite, or grows it
// tenfold, ends the smoothing).
SmoothingOutcome smooth_block_jacobi(Eigen::VectorXd& x, Eigen::VectorXd r, double scale,
                                     const NewtonSolver::Residual& residual,
                                     const Eigen::SparseMatrix<double>& K,
                                     const std::vector<Eigen::Index>& block_start, int sweeps);

}  // namespace cosph
