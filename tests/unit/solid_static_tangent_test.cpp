// The tangent stiffness of the steady-state solver (modules/solid_tlsph/static_tangent.hpp)
// against finite differences of the forces it linearises: the stress divergence of a jittered,
// unequal-volume body (linear and quadratic correction, so that no lattice symmetry hides an
// index error), with clamped and fixed components and a follower pressure, in 2D and 3D, and with
// the fit-residual hourglass control. The assembled matrix is the symmetric part of the Jacobian;
// every entry is compared.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <optional>
#include <random>

#include "../support/tlsph_body.hpp"
#include "solid_tlsph/material_model.hpp"
#include "solid_tlsph/static_equilibrium.hpp"

namespace cosph {
namespace {

using test::kTestSpacing;

template <int D>
struct Problem {
  test::TlsphBody<D> body;
  MaterialModel<D> material;
  std::vector<Index> loaded;  // particles under the follower pressure
  std::vector<Vec<D>> area;   // their reference area vectors N dA
  double pressure = 0.0;
  std::vector<long long> dof;  // -1: prescribed
  long long unknowns = 0;
  // The hourglass control, where tested; mutable: force() refreshes its residual storage.
  mutable std::optional<FitResidualControl<D>> control;
  // The dual-cell energy quadrature, where tested (empty: the energy at the particles).
  EnergyQuadrature<D> quadrature;

  // P_i at the particles, or the quadrature's mean stresses and moments (and F at its points).
  std::vector<Mat<D>> stresses(const std::vector<Vec<D>>& u, const std::vector<Mat<D>>& F,
                               std::vector<StressMoments<D>>& T,
                               std::vector<std::array<Mat<D>, 2 * D>>& Fq) const {
    const std::size_t n = u.size();
    std::vector<Mat<D>> P(n);
    T.resize(n);
    Fq.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      P[i] = quadrature.offset.empty()
                 ? material.stress(F[i], Mat<D>::Identity())
                 : integrate_stress<D>(
                       quadrature, i, F[i], deformation_gradient_slopes<D>(body.pairs, u, i),
                       [&](const Mat<D>& G) { return material.stress(G, Mat<D>::Identity()); },
                       T[i], &Fq[i]);
    return P;
  }

  // Net force on every particle: V_i (stress divergence) minus p J F^-T N dA.
  std::vector<Vec<D>> force(const std::vector<Vec<D>>& u) const {
    const std::size_t n = u.size();
    std::vector<Mat<D>> F(n);
    deformation_gradients<D>(body.pairs, u, F);
    std::vector<StressMoments<D>> T;
    std::vector<std::array<Mat<D>, 2 * D>> Fq;
    const std::vector<Mat<D>> P = stresses(u, F, T, Fq);
    std::vector<Vec<D>> f(n);
    for (std::size_t i = 0; i < n; ++i)
      f[i] = body.V[i] * (quadrature.offset.empty()
                              ? pair_stress_divergence<D>(body.pairs, P, i)
                              : quadrature_stress_divergence<D>(body.pairs, P, T, i));
    for (std::size_t k = 0; k < loaded.size(); ++k) {
      const Mat<D>& Fi = F[loaded[k]];
      f[loaded[k]] -= pressure * Fi.determinant() * (Fi.inverse().transpose() * area[k]);
    }
    if (control) {
      control->update_residuals(u);
      for (std::size_t i = 0; i < n; ++i) f[i] += control->force(i);
    }
    return f;
  }
};

proto::MaterialSpec neo_hookean() {
  proto::MaterialSpec spec;
  spec.set_density(1000.0);
  spec.mutable_neo_hookean()->set_young(1e6);
  spec.mutable_neo_hookean()->set_poisson(0.45);
  return spec;
}

template <int D>
Problem<D> make_problem(GradientCorrection correction, unsigned seed, bool control,
                        bool quadrature) {
  std::array<int, D> n;
  n.fill(4);
  n[0] = 6;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> volume_jitter(0.8, 1.2);
  auto X = test::lattice_box<D>(n, 0.15, seed);
  std::vector<double> V(X.size());
  for (double& v : V) v = std::pow(kTestSpacing, D) * volume_jitter(rng);
  Problem<D> p{test::make_tlsph_body<D>(X, V, correction, false),
               {neo_hookean(), "material"},
               {},
               {},
               0.0,
               {},
               0,
               {},
               {}};
  // kappa mu at half of E: the control's stiffness comparable to the material's.
  if (control) p.control.emplace(p.body.X, p.body.V, p.body.pairs, p.body.kernel, 5e5);
  if (quadrature) {  // the curvature, and cells of random centroids and covariances
    p.body.pairs =
        build_reference_pairs<D>(p.body.X, p.body.V, p.body.kernel, correction, false, true);
    p.quadrature = test::random_cells<D>(p.body.X.size(), rng);
  }
  const std::size_t count = p.body.X.size();
  p.dof.assign(count * D, 0);
  for (std::size_t i = 0; i < count; ++i) {
    const double x = p.body.X[i][0], y = p.body.X[i][1];
    for (int a = 0; a < D; ++a) {
      const bool clamped = x < kTestSpacing;              // the first layer
      const bool fixed = a == 1 && x > 4 * kTestSpacing;  // a roller at the far end
      p.dof[i * D + a] = clamped || fixed ? -1 : p.unknowns++;
    }
    if (y > 3 * kTestSpacing) {  // the top layer: a pressure on a face of normal +y
      p.loaded.push_back(static_cast<Index>(i));
      Vec<D> N = Vec<D>::Zero();
      N[1] = kTestSpacing;  // dA = dp^(D-1) up to the common factor
      p.area.push_back(std::pow(kTestSpacing, D - 2) * N);
    }
  }
  p.pressure = 2e4;  // 2% of E: a follower stiffness comparable to the geometric one
  return p;
}

template <int D>
void check_tangent(GradientCorrection correction, unsigned seed, bool control = false,
                   bool quadrature = false) {
  const Problem<D> p = make_problem<D>(correction, seed, control, quadrature);
  const std::size_t n = p.body.X.size();
  std::mt19937 rng(seed + 7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Vec<D>> u(n);
  for (std::size_t i = 0; i < n; ++i)  // a large, non-affine deformation (strains of 10-20%)
    for (int a = 0; a < D; ++a)
      u[i][a] = p.dof[i * D + a] < 0 ? 0.0 : 0.03 * kTestSpacing * unit(rng) + 0.1 * p.body.X[i][a];

  std::vector<Mat<D>> F(n);
  deformation_gradients<D>(p.body.pairs, u, F);
  std::vector<StressMoments<D>> T;
  std::vector<std::array<Mat<D>, 2 * D>> Fq;
  p.stresses(u, F, T, Fq);
  const int points = quadrature ? EnergyQuadrature<D>::points : 1;
  std::vector<MaterialTangent<D>> C(n * points);
  for (std::size_t i = 0; i < n; ++i)
    for (int q = 0; q < points; ++q)
      C[i * points + q] = derivative_in_F<D, D * D>(
          [&](const Mat<D>& G) { return flatten<D>(p.material.stress(G, Mat<D>::Identity())); },
          quadrature ? Fq[i][q] : F[i]);
  std::vector<ForceTangent<D>> L(p.loaded.size());
  for (std::size_t k = 0; k < p.loaded.size(); ++k)
    L[k] = derivative_in_F<D, D>(
        [&](const Mat<D>& G) -> Vec<D> {
          return -p.pressure * G.determinant() * (G.inverse().transpose() * p.area[k]);
        },
        F[p.loaded[k]]);
  const TangentPattern pattern = build_tangent_pattern<D>(p.body.pairs);
  const Eigen::SparseMatrix<double> lower =
      assemble_tangent<D>(p.body.pairs, pattern, p.body.V, C, p.loaded, L, p.dof, p.unknowns,
                          p.control ? &*p.control : nullptr, quadrature ? &p.quadrature : nullptr);
  const Eigen::MatrixXd upper_part = Eigen::MatrixXd(lower).triangularView<Eigen::StrictlyUpper>();
  EXPECT_EQ(upper_part.norm(), 0.0);  // the lower triangle only
  const Eigen::SparseMatrix<double> whole = lower.selfadjointView<Eigen::Lower>();
  const Eigen::MatrixXd K = Eigen::MatrixXd(whole);

  // J = -dR/du column by column, by central differences of the force.
  Eigen::MatrixXd J(p.unknowns, p.unknowns);
  const double eps = 1e-7 * kTestSpacing;
  for (std::size_t k = 0; k < p.dof.size(); ++k) {
    if (p.dof[k] < 0) continue;
    std::vector<Vec<D>> plus = u, minus = u;
    plus[k / D][k % D] += eps;
    minus[k / D][k % D] -= eps;
    const auto fp = p.force(plus), fm = p.force(minus);
    for (std::size_t r = 0; r < p.dof.size(); ++r)
      if (p.dof[r] >= 0)
        J(p.dof[r], p.dof[k]) = -(fp[r / D][r % D] - fm[r / D][r % D]) / (2.0 * eps);
  }
  const Eigen::MatrixXd symmetric = 0.5 * (J + J.transpose());
  const double error = (K - symmetric).norm() / symmetric.norm();
  const double asymmetry = (J - J.transpose()).norm() / J.norm();
  std::cout << D << "D " << (correction == GradientCorrection::linear ? "linear" : "quadratic")
            << ": |K - sym(J_fd)| / |J| = " << error << ", follower asymmetry " << asymmetry << ", "
            << p.unknowns << " unknowns" << (control ? ", with the fit-residual control" : "")
            << (quadrature ? ", dual-cell quadrature" : "") << "\n";
  EXPECT_LT(error, 1e-8);  // measured 0.98e-9 to 6.1e-9 (the differences' own error)
  // The pressure makes J unsymmetric; a test whose J were symmetric could not see the
  // symmetrisation at all.
  EXPECT_GT(asymmetry, 1e-4);
}

TEST(SolidStaticTangent, MatchesTheSymmetricPartOfTheForceJacobian2D) {
  check_tangent<2>(GradientCorrection::linear, 3);
  check_tangent<2>(GradientCorrection::quadratic, 4);
}

TEST(SolidStaticTangent, MatchesTheSymmetricPartOfTheForceJacobian3D) {
  check_tangent<3>(GradientCorrection::linear, 5);
  check_tangent<3>(GradientCorrection::quadratic, 6);
}

// The fit-residual hourglass control's constant stiffness joins the tangent: the same comparison
// with its force in the residual.
TEST(SolidStaticTangent, IncludesTheFitResidualControl) {
  check_tangent<2>(GradientCorrection::linear, 8, true);
  check_tangent<3>(GradientCorrection::quadratic, 9, true);
}

// The dual-cell energy quadrature (C at every point, F there through the fit's curvature).
TEST(SolidStaticTangent, IntegratesTheEnergyOverTheDualCells) {
  check_tangent<2>(GradientCorrection::quadratic, 10, false, true);
  check_tangent<3>(GradientCorrection::quadratic, 11, false, true);
}

}  // namespace
}  // namespace cosph
