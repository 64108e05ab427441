// The quasi-Newton solver (solid_tlsph/newton_solver.hpp) on a small nonlinear system: a chain of
// springs that stiffen as they stretch, R(x) = b - K x - c x^3 (componentwise cubic), loaded in
// increments as the solid's steady state loads a body. What is tested is the factorisation's
// life: a converged solve's factorisation is the next solve's first inverse, a failed solve drops
// it, and an adopted tangent stands in for the kept one.
#include "solid_tlsph/newton_solver.hpp"

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

namespace cosph {
namespace {

constexpr int kUnknowns = 40;
constexpr double kCubic = 50.0;

Eigen::SparseMatrix<double> chain_stiffness() {
  std::vector<Eigen::Triplet<double>> entries;
  for (int i = 0; i < kUnknowns; ++i) {
    entries.emplace_back(i, i, 2.0);
    if (i > 0) entries.emplace_back(i, i - 1, -1.0);
  }
  Eigen::SparseMatrix<double> K(kUnknowns, kUnknowns);
  K.setFromTriplets(entries.begin(), entries.end());
  return K;  // lower triangle, as the solver reads it
}

struct Chain {
  Eigen::SparseMatrix<double> K0 = chain_stiffness();
  Eigen::SparseMatrix<double> K_full = K0.selfadjointView<Eigen::Lower>();
  double load = 0.0;
  int tangent_calls = 0;

  Eigen::VectorXd force() const { return Eigen::VectorXd::Constant(kUnknowns, load); }

  NewtonSolver::Residual residual() {
    return [this](const Eigen::VectorXd& x, Eigen::VectorXd& r) {
      const Eigen::VectorXd internal = K_full * x + kCubic * x.array().cube().matrix();
      r = force() - internal;
      return std::max(force().norm(), internal.norm());
    };
  }
  NewtonSolver::Tangent tangent() {
    return [this](const Eigen::VectorXd& x) {
      ++tangent_calls;
      Eigen::SparseMatrix<double> K = K0;
      for (int i = 0; i < kUnknowns; ++i) K.coeffRef(i, i) += 3.0 * kCubic * x[i] * x[i];
      return K;
    };
  }
};

NewtonSettings settings() {
  NewtonSettings s;
  s.tolerance = 1e-10;
  return s;
}

TEST(NewtonSolver, AConvergedSolvesFactorisationStartsTheNextIncrement) {
  Chain chain;
  NewtonSolver solver;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(kUnknowns);
  EXPECT_FALSE(solver.has_factorisation());
  chain.load = 0.5;
  const NewtonOutcome first = solver.solve(x, chain.residual(), chain.tangent(), settings());
  ASSERT_TRUE(first.converged);
  EXPECT_EQ(first.factorisations, chain.tangent_calls);
  EXPECT_GE(first.factorisations, 1);
  EXPECT_TRUE(solver.has_factorisation());

  // The next increment starts on the kept factorisation: no tangent before its first step.
  const int calls = chain.tangent_calls;
  chain.load = 0.6;
  const NewtonOutcome second = solver.solve(x, chain.residual(), chain.tangent(), settings());
  ASSERT_TRUE(second.converged);
  EXPECT_EQ(second.factorisations, 0);
  EXPECT_EQ(chain.tangent_calls, calls);
  EXPECT_GT(second.iterations, 0);
  Eigen::VectorXd r(kUnknowns);
  chain.residual()(x, r);
  EXPECT_LT(r.norm(), 1e-10 * chain.force().norm() * 10.0);
}

TEST(NewtonSolver, AFailedSolveDropsItsFactorisation) {
  Chain chain;
  NewtonSolver solver;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(kUnknowns);
  chain.load = 0.5;
  ASSERT_TRUE(solver.solve(x, chain.residual(), chain.tangent(), settings()).converged);
  ASSERT_TRUE(solver.has_factorisation());
  // Two iterations cannot reach 1e-10 on a large increment.
  NewtonSettings short_settings = settings();
  short_settings.max_iterations = 2;
  chain.load = 50.0;
  Eigen::VectorXd y = x;
  EXPECT_FALSE(solver.solve(y, chain.residual(), chain.tangent(), short_settings).converged);
  EXPECT_FALSE(solver.has_factorisation());
  // The retry (a bisected increment) assembles its own first tangent.
  chain.load = 0.6;
  const NewtonOutcome retry = solver.solve(x, chain.residual(), chain.tangent(), settings());
  EXPECT_TRUE(retry.converged);
  EXPECT_GE(retry.factorisations, 1);
}

// A restart rebuilds the kept factorisation from where it was taken: the continued solve is then
// bit for bit the uninterrupted one.
TEST(NewtonSolver, AnAdoptedTangentContinuesBitForBit) {
  Chain chain;
  NewtonSolver uninterrupted;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(kUnknowns);
  Eigen::VectorXd at_factorisation;
  NewtonSolver::Tangent tangent = [&](const Eigen::VectorXd& y) {
    at_factorisation = y;
    return chain.tangent()(y);
  };
  chain.load = 0.5;
  ASSERT_TRUE(uninterrupted.solve(x, chain.residual(), tangent, settings()).converged);
  const Eigen::VectorXd checkpoint = x, kept_at = at_factorisation;

  chain.load = 0.6;
  Eigen::VectorXd continued = checkpoint;
  ASSERT_TRUE(uninterrupted.solve(continued, chain.residual(), tangent, settings()).converged);

  NewtonSolver restarted;
  ASSERT_TRUE(restarted.adopt_tangent(chain.tangent()(kept_at)));
  EXPECT_TRUE(restarted.has_factorisation());
  Eigen::VectorXd resumed = checkpoint;
  const NewtonOutcome outcome = restarted.solve(resumed, chain.residual(), tangent, settings());
  ASSERT_TRUE(outcome.converged);
  EXPECT_EQ(outcome.factorisations, 0);
  for (int i = 0; i < kUnknowns; ++i) EXPECT_EQ(resumed[i], continued[i]) << i;
}

TEST(NewtonSolver, RefusesToAdoptATangentThatDoesNotFactorise) {
  NewtonSolver solver;
  Eigen::SparseMatrix<double> K = chain_stiffness();
  K *= -1e12;  // negative definite beyond what the diagonal shifts reach
  EXPECT_FALSE(solver.adopt_tangent(K));
  EXPECT_FALSE(solver.has_factorisation());
}

}  // namespace
}  // namespace cosph
