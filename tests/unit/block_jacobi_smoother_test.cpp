// The damped block-Jacobi smoother (solid_tlsph/block_jacobi_smoother.hpp) on a linear problem,
// R(x) = b - K x with K a chain of 2 x 2 blocks coupled to their neighbours: it damps the
// particle-scale part of an error fast and the smooth part slowly, as a smoother should; it never
// diverges on the step it picks itself; and it keeps the best iterate when the residual turns bad.
#include "solid_tlsph/block_jacobi_smoother.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cmath>
#include <numbers>
#include <vector>

namespace cosph {
namespace {

constexpr int kBlocks = 64;
constexpr int kUnknowns = 2 * kBlocks;

// Lower triangle, as the smoother reads it: the chain's Laplacian (2, -1) times the coupling
// [[1, 0.25], [0.25, 1]] of a block's two components, so that B^-1 K is the Laplacian / 2 in each
// component and the chain's modes are its eigenvectors.
Eigen::SparseMatrix<double> chain() {
  std::vector<Eigen::Triplet<double>> entries;
  const double coupling[2][2] = {{1.0, 0.25}, {0.25, 1.0}};
  for (int b = 0; b < kBlocks; ++b)
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 2; ++c) {
        if (c <= a) entries.emplace_back(2 * b + a, 2 * b + c, 2.0 * coupling[a][c]);
        if (b > 0) entries.emplace_back(2 * b + a, 2 * (b - 1) + c, -coupling[a][c]);
      }
  Eigen::SparseMatrix<double> K(kUnknowns, kUnknowns);
  K.setFromTriplets(entries.begin(), entries.end());
  return K;
}

std::vector<Eigen::Index> block_starts() {
  std::vector<Eigen::Index> start;
  for (int b = 0; b <= kBlocks; ++b) start.push_back(2 * b);
  return start;
}

// A mode of the chain: sin(k pi (b + 1) / (kBlocks + 1)) in both components of block b.
Eigen::VectorXd mode(int k) {
  Eigen::VectorXd v(kUnknowns);
  for (int b = 0; b < kBlocks; ++b)
    v[2 * b] = v[2 * b + 1] = std::sin(k * std::numbers::pi * (b + 1) / (kBlocks + 1));
  return v;
}

struct Linear {
  Eigen::SparseMatrix<double> K = chain();
  Eigen::SparseMatrix<double> K_full = K.selfadjointView<Eigen::Lower>();
  Eigen::VectorXd solution = Eigen::VectorXd::LinSpaced(kUnknowns, 0.0, 1.0);
  Eigen::VectorXd b = K_full * solution;
  int calls = 0;

  NewtonSolver::Residual residual() {
    return [this](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
      ++calls;
      r = b - K_full * x;
      return b.norm();
    };
  }
};

TEST(BlockJacobiSmoother, DampsTheParticleScaleErrorAndLeavesTheSmoothOne) {
  Linear problem;
  const auto residual = problem.residual();
  const Eigen::VectorXd smooth = mode(1), rough = mode(kBlocks);  // the longest and shortest
  Eigen::VectorXd x = problem.solution + smooth + rough, r(kUnknowns);
  const double scale = residual(x, r);
  const SmoothingOutcome outcome =
      smooth_block_jacobi(x, r, scale, residual, problem.K, block_starts(), 20);
  EXPECT_EQ(outcome.sweeps, 20);
  EXPECT_EQ(problem.calls, 21);  // one per sweep after the first
  // What is left of each mode (the modes are eigenvectors of B^-1 K): the rough one's eigenvalue
  // is the largest, which the step is set by, the smooth one's 1 - cos(pi / 65) = 1.2e-3.
  const Eigen::VectorXd error = x - problem.solution;
  const double left_smooth = error.dot(smooth) / smooth.squaredNorm();
  const double left_rough = error.dot(rough) / rough.squaredNorm();
  std::cout << "left of the smooth mode " << left_smooth << ", of the rough mode " << left_rough
            << "; residual " << outcome.final_residual / outcome.initial_residual
            << " of the start\n";
  // Measured 2.2e-16: the step is 1 / lambda of the rough mode itself, which one sweep removes
  // (round-off is what is left).
  EXPECT_LT(std::abs(left_rough), 1e-12);
  // Measured 0.988 (1.2% removed; (1 - 1.2e-3 / 1.93)^20 by the modes' eigenvalues): the smooth
  // error is Newton's to remove.
  EXPECT_GT(left_smooth, 0.98);
  EXPECT_LT(left_smooth, 0.995);
  // Measured 5.8e-4 of the start: what the smooth mode leaves.
  EXPECT_LT(outcome.final_residual, 8.7e-4 * outcome.initial_residual);
}

TEST(BlockJacobiSmoother, ItsOwnStepNeverAmplifiesAMode) {
  // omega = 1 / lambda_max(B^-1 K) from power iteration: every mode of the chain shrinks.
  for (int k : {1, 8, 32, 48, 63, kBlocks}) {
    Linear problem;
    const auto residual = problem.residual();
    Eigen::VectorXd x = problem.solution + mode(k), r(kUnknowns);
    const double scale = residual(x, r);
    const double before = (x - problem.solution).norm();
    const SmoothingOutcome outcome =
        smooth_block_jacobi(x, r, scale, residual, problem.K, block_starts(), 10);
    EXPECT_EQ(outcome.sweeps, 10) << "mode " << k;
    EXPECT_LT((x - problem.solution).norm(), before) << "mode " << k;
  }
}

TEST(BlockJacobiSmoother, KeepsTheBestIterateWhenTheResidualTurnsBad) {
  Linear problem;
  int calls = 0;
  // A residual that is fine at the guess and not finite anywhere else (an inverted particle).
  const Eigen::VectorXd guess = problem.solution + mode(kBlocks);
  const NewtonSolver::Residual residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
    ++calls;
    r = problem.b - problem.K_full * x;
    if ((x - guess).norm() > 0.0) r[0] = NAN;
    return problem.b.norm();
  };
  Eigen::VectorXd x = guess, r(kUnknowns);
  const double scale = residual(x, r);
  const SmoothingOutcome outcome =
      smooth_block_jacobi(x, r, scale, residual, problem.K, block_starts(), 10);
  EXPECT_EQ(outcome.sweeps, 1);  // the first bad sweep ends it
  EXPECT_EQ(x, guess);
  EXPECT_EQ(outcome.final_residual, outcome.initial_residual);
  // No sweeps asked: nothing is evaluated or moved.
  calls = 0;
  const SmoothingOutcome none =
      smooth_block_jacobi(x, r, scale, residual, problem.K, block_starts(), 0);
  EXPECT_EQ(none.sweeps, 0);
  EXPECT_EQ(calls, 0);
  EXPECT_EQ(x, guess);
}

TEST(BlockJacobiSmoother, ABlockThatIsNotPositiveDefiniteTakesItsDiagonal) {
  // An indefinite tangent at a poor guess: block 0's inner coupling exceeds its diagonal. The
  // sweeps stay finite and still reduce the residual.
  Linear problem;
  std::vector<Eigen::Triplet<double>> entries;
  for (int k = 0; k < problem.K.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(problem.K, k); it; ++it)
      entries.emplace_back(it.row(), it.col(), it.row() == 1 && it.col() == 0 ? 3.0 : it.value());
  Eigen::SparseMatrix<double> K(kUnknowns, kUnknowns);
  K.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd x = problem.solution + mode(kBlocks), r(kUnknowns);
  const auto residual = problem.residual();
  const double scale = residual(x, r);
  const SmoothingOutcome outcome =
      smooth_block_jacobi(x, r, scale, residual, K, block_starts(), 10);
  EXPECT_EQ(outcome.sweeps, 10);
  EXPECT_TRUE(x.allFinite());
  EXPECT_LT(outcome.final_residual, outcome.initial_residual);
}

}  // namespace
}  // namespace cosph
