// The tangent stiffness of the total-Lagrangian SPH forces, for the steady-state (Newton) solver.
//
// Every force of the solid depends on the displacements through the particles' deformation
// gradients F_i = I + sum_j (u_j - u_i) g_ij^T (tlsph_operators.hpp), which are linear in u:
// dF_i = sum_k du_k (x) c_ik with c_ik = g_ik for a neighbour k and c_ii = -sum_j g_ij. The
// internal force is f = -dE/du of the discrete energy E = sum_i V_i Psi(F_i), so its stiffness
//     K_jk = -df_j/du_k = sum_i V_i H_ij^T C_i H_ik,    C_i = dP/dF at F_i,
// (H_ik maps du_k to dF_i: dF_ab = du_a c_ik,b) is symmetric; a force that acts on particle i alone
// and depends on F_i (the follower pressure p J F^-T N dA) adds -L_i H_ik to row i, with
// L_i = df_i/dF_i. The pattern joins particles that share a neighbour: two kernel supports.
//
// Rows are gathered (row j sums over the particles i that see j), so the assembly needs no atomics
// and its result does not depend on the number of threads.
#pragma once

#include <Eigen/SparseCore>
#include <vector>

#include "core/types.hpp"
#include "solid_tlsph/fit_residual_control.hpp"
#include "solid_tlsph/tlsph_operators.hpp"

namespace cosph {

// dP/dF (or df/dF) flattened with F's entry (a, b) at a * D + b.
template <int D>
using MaterialTangent = Eigen::Matrix<double, D * D, D * D>;
template <int D>
using ForceTangent = Eigen::Matrix<double, D, D * D>;

// Which particles' stiffness rows and columns couple (those within two kernel supports through a
// common neighbour), built once from the reference pairs.
struct TangentPattern {
  std::vector<std::size_t> offset;  // per particle, into column
  std::vector<Index> column;        // sorted within a row
};

template <int D>
TangentPattern build_tangent_pattern(const ReferencePairs<D>& pairs);

// The stiffness restricted to the free degrees of freedom: dof[i * D + a] is the unknown's index of
// component a of particle i, or -1 where the component is prescribed. C holds C_i for every
// particle; force_tangent_particles / force_tangents the L_i of particles with a force of their
// own (may be empty). Returns the lower triangle of the symmetric part (K + K^T) / 2, the matrix
// a Cholesky-type solver takes (selfadjointView<Lower> gives the whole): the follower pressure's
// own stiffness is not symmetric, and Newton's iteration with the symmetric part converges linearly
// at the rate of the pressure's share of the stiffness of the deformation being solved for (small
// against the material's, but not against a slender body's bending: 0.15-0.2 per iteration near the
// solution of Land's beam, measured). A zero-energy control (fit_residual_control.hpp), where
// given, adds its constant stiffness.
template <int D>
Eigen::SparseMatrix<double> assemble_tangent(const ReferencePairs<D>& pairs,
                                             const TangentPattern& pattern,
                                             const std::vector<double>& volume,
                                             const std::vector<MaterialTangent<D>>& C,
                                             const std::vector<Index>& force_tangent_particles,
                                             const std::vector<ForceTangent<D>>& force_tangents,
                                             const std::vector<long long>& dof, long long unknowns,
                                             const FitResidualControl<D>* control = nullptr,
                                             const EnergyQuadrature<D>* quadrature = nullptr);

}  // namespace cosph
