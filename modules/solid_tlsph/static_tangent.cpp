#include "solid_tlsph/static_tangent.hpp"

#include <algorithm>

#include "core/parallel.hpp"

namespace cosph {

namespace {

// The particles whose displacements enter F_i: i itself first, then its neighbours in list order.
// Slot s of particle i is pair offset[i] + s - 1 for s >= 1.
template <int D>
Vec<D> coefficient(const ReferencePairs<D>& pairs, std::size_t i, std::size_t slot) {
  if (slot == 0) return -pairs.gradient_sum[i];
  return pairs.gradient[pairs.neighbours.offset[i] + slot - 1];
}

// The second-derivative coefficients in the same slots: -sum_j h_ij for i itself, h_ik for k.
template <int D>
Mat<D> curvature_coefficient(const ReferencePairs<D>& pairs, std::size_t i, std::size_t slot) {
  if (slot == 0) return -pairs.curvature_sum[i];
  return pairs.curvature[pairs.neighbours.offset[i] + slot - 1];
}

template <int D>
Index node(const ReferencePairs<D>& pairs, std::size_t i, std::size_t slot) {
  return slot == 0 ? static_cast<Index>(i)
                   : pairs.neighbours.index[pairs.neighbours.offset[i] + slot - 1];
}

std::size_t slots(const NeighbourList& nl, std::size_t i) {
  return nl.offset[i + 1] - nl.offset[i] + 1;
}

// Position of column k in row j of the pattern (present by construction).
std::size_t find_column(const TangentPattern& pattern, std::size_t j, Index k) {
  const auto begin = pattern.column.begin() + static_cast<std::ptrdiff_t>(pattern.offset[j]);
  const auto end = pattern.column.begin() + static_cast<std::ptrdiff_t>(pattern.offset[j + 1]);
  return static_cast<std::size_t>(std::lower_bound(begin, end, k) - pattern.column.begin());
}

}  // namespace

template <int D>
TangentPattern build_tangent_pattern(const ReferencePairs<D>& pairs) {
  const NeighbourList& nl = pairs.neighbours;
  const std::size_t n = nl.particle_count();
  std::vector<std::vector<Index>> rows(n);
  parallel_for_each_index(n, [&](std::size_t j) {
    std::vector<Index>& row = rows[j];
    row.push_back(static_cast<Index>(j));
    for (Index i : nl.of(j)) {
      row.push_back(i);
      for (Index k : nl.of(i)) row.push_back(k);
    }
    for (Index k : nl.of(j)) row.push_back(k);
    std::sort(row.begin(), row.end());
    row.erase(std::unique(row.begin(), row.end()), row.end());
  });
  TangentPattern pattern;
  pattern.offset.assign(n + 1, 0);
  for (std::size_t j = 0; j < n; ++j) pattern.offset[j + 1] = pattern.offset[j] + rows[j].size();
  pattern.column.resize(pattern.offset[n]);
  parallel_for_each_index(n, [&](std::size_t j) {
    std::copy(rows[j].begin(), rows[j].end(),
              pattern.column.begin() + static_cast<std::ptrdiff_t>(pattern.offset[j]));
  });
  return pattern;
}

namespace {

template <int D>
using Block = Mat<D>;
// The material stiffness in moment form. At point q of particle i's energy quadrature, dF_i =
// sum_k du_k (x) c_ik(q) with c_ik(q) = c_ik + h_ik d_q = G_ik e_q, where G_ik = [c_ik | h_ik] is
// D x E and e_q = (1, d_q) (E = D + 1; without a quadrature the one point is the particle, G_ik =
// c_ik and E = 1). The block particle i adds between rows j and columns k,
//     V_i sum_q w_q sum_{b,d} c_ij(q)_b C_iq[(a, b), (c, d)] c_ik(q)_d,
// is then G_ij contracted with the moments M_i[(a, b, m), (c, d, l)] = V_i sum_q w_q e_q[m]
// e_q[l] C_iq[(a, b), (c, d)] and with G_ik: one contraction per pair (j, k) instead of one per
// point, and one look-up of the block's place in the pattern.
template <int D, int E>
struct StiffnessMoments {
  static constexpr int size = D * D * E;  // index (a * D + b) * E + m
  using Moments = Eigen::Matrix<double, size, size>;
  using Coefficients = Eigen::Matrix<double, D * E, 1>;  // G_ik flattened: index d * E + l
  using Contracted = Eigen::Matrix<double, D, size>;     // G_ij contracted with M_i

  static Coefficients coefficients(const ReferencePairs<D>& pairs, std::size_t i,
                                   std::size_t slot) {
    Coefficients g;
    const Vec<D> c = coefficient(pairs, i, slot);
    if constexpr (E == 1) {
      g = c;
    } else {
      const Mat<D> h = curvature_coefficient(pairs, i, slot);
      for (int d = 0; d < D; ++d) {
        g[d * E] = c[d];
        for (int k = 0; k < D; ++k) g[d * E + 1 + k] = h(d, k);
      }
    }
    return g;
  }

  static Moments moments(const std::vector<MaterialTangent<D>>& C, std::size_t i, double volume,
                         const EnergyQuadrature<D>* quadrature) {
    constexpr int points = E == 1 ? 1 : EnergyQuadrature<D>::points;
    Moments M = Moments::Zero();
    for (int q = 0; q < points; ++q) {
      Eigen::Matrix<double, E, 1> e;
      e[0] = 1.0;
      if constexpr (E > 1) e.template tail<D>() = quadrature->offset[i][q];
      const Eigen::Matrix<double, E, E> ee = (volume / points) * e * e.transpose();
      const MaterialTangent<D>& Cq = C[i * points + q];
      for (int r = 0; r < D * D; ++r)
        for (int col = 0; col < D * D; ++col)
          M.template block<E, E>(r * E, col * E) += Cq(r, col) * ee;
    }
    return M;
  }

  // G_ij^T M_i: P[a, (c, d, l)] = sum_{b, m} G_ij[b, m] M_i[(a, b, m), (c, d, l)].
  static Contracted contract(const Coefficients& g, const Moments& M) {
    Contracted P = Contracted::Zero();
    for (int a = 0; a < D; ++a)
      for (int bm = 0; bm < D * E; ++bm) P.row(a) += g[bm] * M.row(a * D * E + bm);
    return P;
  }

  // The block: K[a, c] = sum_{d, l} P[a, (c, d, l)] G_ik[d, l].
  static Mat<D> block(const Contracted& P, const Coefficients& g) {
    Mat<D> b;
    for (int c = 0; c < D; ++c) b.col(c) = P.template middleCols<D * E>(c * D * E) * g;
    return b;
  }
};

// Adds sum_i (the stiffness of particle i's energy) and the zero-energy control's constant
// stiffness to the pattern's blocks K. Row j gathers over the particles i whose F depends on u_j
// (j itself and its neighbours).
template <int D, int E>
void add_material_stiffness(const ReferencePairs<D>& pairs, const TangentPattern& pattern,
                            const std::vector<double>& volume,
                            const std::vector<MaterialTangent<D>>& C,
                            const FitResidualControl<D>* control,
                            const EnergyQuadrature<D>* quadrature, std::vector<Block<D>>& K) {
  using Form = StiffnessMoments<D, E>;
  const NeighbourList& nl = pairs.neighbours;
  const std::size_t n = nl.particle_count();
  std::vector<typename Form::Moments> M(n);
  parallel_for_each_index(
      n, [&](std::size_t i) { M[i] = Form::moments(C, i, volume[i], quadrature); });
  parallel_for_each_index(n, [&](std::size_t j) {
    auto add_particle = [&](std::size_t i, std::size_t slot_of_j) {
      const typename Form::Contracted P =
          Form::contract(Form::coefficients(pairs, i, slot_of_j), M[i]);
      for (std::size_t s = 0; s < slots(nl, i); ++s) {
        Block<D> b = Form::block(P, Form::coefficients(pairs, i, s));
        if (control) b.diagonal().array() += control->stiffness(i, slot_of_j, s);
        K[find_column(pattern, j, node(pairs, i, s))] += b;
      }
    };
    add_particle(j, 0);
    // Neighbour i's slot of j: the reverse pair's place in i's list (slot 0 is i itself).
    for (std::size_t k = nl.offset[j]; k < nl.offset[j + 1]; ++k)
      add_particle(nl.index[k], pairs.reverse_pair[k] - nl.offset[nl.index[k]] + 1);
  });
}

// Subtracts L_i H_ik from row i for the particles with a force of their own (L_i = df_i/dF_i).
template <int D>
void add_own_force_stiffness(const ReferencePairs<D>& pairs, const TangentPattern& pattern,
                             const std::vector<Index>& force_tangent_particles,
                             const std::vector<ForceTangent<D>>& force_tangents,
                             std::vector<Block<D>>& K) {
  const NeighbourList& nl = pairs.neighbours;
  parallel_for_each_index(force_tangent_particles.size(), [&](std::size_t m) {
    const std::size_t j = force_tangent_particles[m];
    const ForceTangent<D>& L = force_tangents[m];
    for (std::size_t s = 0; s < slots(nl, j); ++s) {
      const Vec<D> c = coefficient(pairs, j, s);
      Block<D> b = Block<D>::Zero();
      for (int col = 0; col < D; ++col)
        for (int d = 0; d < D; ++d) b.col(col) += L.col(col * D + d) * c[d];
      K[find_column(pattern, j, node(pairs, j, s))] -= b;
    }
  });
}

// The lower triangle of the symmetric part of the blocks K on the free unknowns, in compressed
// column storage (what the Cholesky factorisation reads). Column dof(j, a) holds rows
// dof(k, c) >= dof(j, a) of the blocks (j, k), k ascending: K_s(k, j)[c][a] = K_s(j, k)[a][c].
template <int D>
Eigen::SparseMatrix<double> lower_symmetric_part(const TangentPattern& pattern,
                                                 const std::vector<Block<D>>& K,
                                                 const std::vector<long long>& dof,
                                                 long long unknowns) {
  const std::size_t n = pattern.offset.size() - 1;
  auto for_each_lower_entry = [&](std::size_t j, int a, auto&& visit) {
    const long long col = dof[j * D + a];
    for (std::size_t p = pattern.offset[j]; p < pattern.offset[j + 1]; ++p) {
      const Index k = pattern.column[p];
      for (int c = 0; c < D; ++c) {
        const long long row = dof[k * D + c];
        if (row >= col) visit(p, k, c, row);
      }
    }
  };
  std::vector<long long> column_start(static_cast<std::size_t>(unknowns) + 1, 0);
  parallel_for_each_index(n, [&](std::size_t j) {
    for (int a = 0; a < D; ++a) {
      const long long col = dof[j * D + a];
      if (col < 0) continue;
      long long count = 0;
      for_each_lower_entry(j, a, [&](std::size_t, Index, int, long long) { ++count; });
      column_start[static_cast<std::size_t>(col) + 1] = count;
    }
  });
  for (long long c = 0; c < unknowns; ++c)
    column_start[static_cast<std::size_t>(c) + 1] += column_start[static_cast<std::size_t>(c)];
  Eigen::SparseMatrix<double> matrix(unknowns, unknowns);
  matrix.resizeNonZeros(static_cast<Eigen::Index>(column_start.back()));
  for (long long c = 0; c <= unknowns; ++c)
    matrix.outerIndexPtr()[c] = static_cast<int>(column_start[static_cast<std::size_t>(c)]);
  int* const inner = matrix.innerIndexPtr();
  double* const value = matrix.valuePtr();
  parallel_for_each_index(n, [&](std::size_t j) {
    for (int a = 0; a < D; ++a) {
      const long long col = dof[j * D + a];
      if (col < 0) continue;
      long long at = column_start[static_cast<std::size_t>(col)];
      for_each_lower_entry(j, a, [&](std::size_t p, Index k, int c, long long row) {
        const Block<D>& backward = K[find_column(pattern, k, static_cast<Index>(j))];
        inner[at] = static_cast<int>(row);
        value[at] = 0.5 * (K[p](a, c) + backward(c, a));
        ++at;
      });
    }
  });
  return matrix;
}

}  // namespace

template <int D>
Eigen::SparseMatrix<double> assemble_tangent(const ReferencePairs<D>& pairs,
                                             const TangentPattern& pattern,
                                             const std::vector<double>& volume,
                                             const std::vector<MaterialTangent<D>>& C,
                                             const std::vector<Index>& force_tangent_particles,
                                             const std::vector<ForceTangent<D>>& force_tangents,
                                             const std::vector<long long>& dof, long long unknowns,
                                             const FitResidualControl<D>* control,
                                             const EnergyQuadrature<D>* quadrature) {
  std::vector<Block<D>> K(pattern.column.size(), Block<D>::Zero());
  if (quadrature)
    add_material_stiffness<D, D + 1>(pairs, pattern, volume, C, control, quadrature, K);
  else
    add_material_stiffness<D, 1>(pairs, pattern, volume, C, control, quadrature, K);
  add_own_force_stiffness<D>(pairs, pattern, force_tangent_particles, force_tangents, K);
  return lower_symmetric_part<D>(pattern, K, dof, unknowns);
}

#define COSPH_INSTANTIATE_STATIC_TANGENT(D)                                          \
  template TangentPattern build_tangent_pattern<D>(const ReferencePairs<D>&);        \
  template Eigen::SparseMatrix<double> assemble_tangent<D>(                          \
      const ReferencePairs<D>&, const TangentPattern&, const std::vector<double>&,   \
      const std::vector<MaterialTangent<D>>&, const std::vector<Index>&,             \
      const std::vector<ForceTangent<D>>&, const std::vector<long long>&, long long, \
      const FitResidualControl<D>*, const EnergyQuadrature<D>*);
COSPH_INSTANTIATE_STATIC_TANGENT(2)
COSPH_INSTANTIATE_STATIC_TANGENT(3)

}  // namespace cosph
