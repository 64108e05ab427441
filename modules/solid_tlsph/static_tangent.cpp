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
template <int D>
using Contracted = Eigen::Matrix<double, D * D, D>;

// Adds the material stiffness sum_i V_i sum_q w_q H^q_ij^T C_iq H^q_ik to the pattern's blocks K,
// one point q at a time (one point, at the particle, without a quadrature), and the zero-energy
// control's constant stiffness.
template <int D>
void add_material_stiffness(const ReferencePairs<D>& pairs, const TangentPattern& pattern,
                            const std::vector<double>& volume,
                            const std::vector<MaterialTangent<D>>& C,
                            const FitResidualControl<D>* control,
                            const EnergyQuadrature<D>* quadrature, std::vector<Block<D>>& K) {
  const NeighbourList& nl = pairs.neighbours;
  const std::size_t n = nl.particle_count();
  std::vector<std::size_t> slot_offset(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) slot_offset[i + 1] = slot_offset[i] + slots(nl, i);
  std::vector<Contracted<D>> Q(slot_offset[n]);
  const int points = quadrature ? EnergyQuadrature<D>::points : 1;
  const double weight = 1.0 / points;
  for (int q = 0; q < points; ++q) {
    // The coefficients of F at point q of particle i's dual cell: c_ik + h_ik d_q.
    auto coefficient_at = [&](std::size_t i, std::size_t slot) -> Vec<D> {
      if (!quadrature) return coefficient(pairs, i, slot);
      return coefficient(pairs, i, slot) +
             curvature_coefficient(pairs, i, slot) * quadrature->offset[i][q];
    };
    // Q_ik = C_i H_ik per slot: Q[(a, b), c] = sum_d C_i[(a, b), (c, d)] c_ik[d].
    parallel_for_each_index(n, [&](std::size_t i) {
      const MaterialTangent<D>& Ci = C[i * points + q];
      for (std::size_t s = 0; s < slots(nl, i); ++s) {
        const Vec<D> c = coefficient_at(i, s);
        Contracted<D>& out = Q[slot_offset[i] + s];
        for (int col = 0; col < D; ++col) {
          Eigen::Matrix<double, D * D, 1> sum = Eigen::Matrix<double, D * D, 1>::Zero();
          for (int d = 0; d < D; ++d) sum += Ci.col(col * D + d) * c[d];
          out.col(col) = sum;
        }
      }
    });
    // Row j of K: sum over the particles i whose F depends on u_j (j itself and its neighbours).
    parallel_for_each_index(n, [&](std::size_t j) {
      auto add_particle = [&](std::size_t i, std::size_t slot_of_j) {
        const Vec<D> c_ij = coefficient_at(i, slot_of_j);
        for (std::size_t s = 0; s < slots(nl, i); ++s) {
          const Contracted<D>& Qs = Q[slot_offset[i] + s];
          Block<D> b = Block<D>::Zero();
          for (int a = 0; a < D; ++a)
            for (int bb = 0; bb < D; ++bb) b.row(a) += c_ij[bb] * Qs.row(a * D + bb);
          b *= weight * volume[i];
          if (control && q == 0) b.diagonal().array() += control->stiffness(i, slot_of_j, s);
          K[find_column(pattern, j, node(pairs, i, s))] += b;
        }
      };
      add_particle(j, 0);
      // Neighbour i's slot of j: the reverse pair's place in i's list (slot 0 is i itself).
      for (std::size_t k = nl.offset[j]; k < nl.offset[j + 1]; ++k)
        add_particle(nl.index[k], pairs.reverse_pair[k] - nl.offset[nl.index[k]] + 1);
    });
  }
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
  add_material_stiffness<D>(pairs, pattern, volume, C, control, quadrature, K);
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
