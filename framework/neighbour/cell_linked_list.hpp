// Cell-linked list: particles binned into cubic cells half a cut-off radius wide, so that every
// neighbour of a particle lies within two cells of its own (5^D cells; widened where a sparse
// cloud would make most cells empty, then one cell and 3^D). Half-width cells visit 25/36 of the
// candidates in 2D (125/216 in 3D) that cut-off-wide ones do, for two more ranges per row. Used to
// build inner lists (one set with itself), contact lists (one set against another, the larger
// cut-off governs) and the cell-order permutation that sorts particles for memory locality.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "core/types.hpp"
#include "neighbour/domain.hpp"
#include "neighbour/neighbour_list.hpp"

namespace cosph {

template <int D>
class CellLinkedList {
 public:
  // Bins `positions` (kept by reference: they must outlive the list). On periodic axes the domain
  // bounds are used (the axis must be at least three cut-offs long); on the others the cells span
  // the particles' bounding box.
  CellLinkedList(const std::vector<Vec<D>>& positions, double cutoff, const Domain<D>& domain);

  // All particles of the binned set within `cutoff` of x (strictly closer), excluding `self`.
  // Calls f(j) in deterministic order.
  template <typename F>
  void for_each_neighbour(const Vec<D>& x, double cutoff, Index self, const F& f) const;

  // The same neighbours, in the same order, written to out[0..) without a branch per candidate
  // (every candidate is stored, and the write position advances only on a hit: a third of the
  // candidates are neighbours, a coin toss for branch prediction). out must have room for
  // candidate_bound() indices; returns the end of what was written.
  Index* write_neighbours(const Vec<D>& x, double cutoff, Index self, Index* out) const;

  // The most candidates one search visits: the stencil's cells of the fullest cell's size.
  std::size_t candidate_bound() const { return candidate_bound_; }

  // Particle indices in cell order: positions[order[k]] are sorted by cell.
  std::vector<Index> cell_order() const { return particles_; }

 private:
  std::array<int, D> cell_of_position(const Vec<D>& x) const;
  std::size_t linear(const std::array<int, D>& c) const;
  // Calls f(begin, end) for the ranges of particles_ that hold the stencil around x (wrapped
  // on periodic axes, clipped elsewhere), in increasing cell order.
  template <typename F>
  void for_each_range_around(const Vec<D>& x, const F& f) const;

  const std::vector<Vec<D>>& positions_;
  Domain<D> domain_;
  Vec<D> origin_;
  double cell_size_;
  int reach_ = 2;  // the stencil: cells within reach_ of a particle's own, per axis
  std::array<int, D> cells_{};
  std::vector<std::size_t> cell_start_;  // CSR over cells
  std::vector<Index> particles_;         // particle indices grouped by cell
  std::vector<Vec<D>>
      sorted_positions_;  // positions in the same order: candidates stream from memory
  std::size_t candidate_bound_ = 0;
};

// Neighbours of every particle of one set among the same set (self excluded).
template <int D>
NeighbourList build_inner_list(const std::vector<Vec<D>>& positions, double cutoff,
                               const Domain<D>& domain);

// Neighbours of every particle of set a among the particles of set b. The cut-off is the larger
// of the two sets' support radii (the caller passes it).
template <int D>
NeighbourList build_contact_list(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b,
                                 double cutoff, const Domain<D>& domain);

// The same against a cell list of set b built beforehand (b static: built once, searched often).
template <int D>
NeighbourList build_contact_list(const std::vector<Vec<D>>& a, const CellLinkedList<D>& b_cells,
                                 double cutoff);

// Reference O(N^2) search used by the tests.
template <int D>
NeighbourList brute_force_list(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b,
                               double cutoff, const Domain<D>& domain, bool same_set);

// Permutation that sorts particles by cell (new[i] = old[order[i]]), for ParticleSet::permute.
template <int D>
std::vector<Index> cell_sort_order(const std::vector<Vec<D>>& positions, double cell_size,
                                   const Domain<D>& domain);

template <int D>
template <typename F>
void CellLinkedList<D>::for_each_range_around(const Vec<D>& x, const F& f) const {
  const auto c = cell_of_position(x);
  std::array<int, D> lo, hi;
  for (int a = 0; a < D; ++a) {
    lo[a] = c[a] - reach_;
    hi[a] = c[a] + reach_;
    if (!domain_.periodic[a]) {
      lo[a] = std::max(lo[a], 0);
      hi[a] = std::min(hi[a], cells_[a] - 1);
    }
  }
  // Cells along axis 0 are consecutive in the linear index, so a row of the stencil is one range
  // of particles_, except where it wraps around a periodic axis 0.
  const int n0 = cells_[0];
  std::array<int, D> k = lo;
  while (true) {
    std::array<int, D> w = k;
    for (int a = 1; a < D; ++a)
      if (domain_.periodic[a]) w[a] = (w[a] + cells_[a]) % cells_[a];
    auto row = [&](int from, int to) {  // cells [from, to] of axis 0, in range
      w[0] = from;
      const std::size_t first = linear(w);
      f(cell_start_[first], cell_start_[first + static_cast<std::size_t>(to - from) + 1]);
    };
    if (lo[0] < 0) {  // periodic, wraps below: cells n0 + lo .. n0 - 1, then 0 .. hi
      row(n0 + lo[0], n0 - 1);
      row(0, hi[0]);
    } else if (hi[0] >= n0) {  // periodic, wraps above: lo .. n0 - 1, then 0 .. hi - n0
      row(lo[0], n0 - 1);
      row(0, hi[0] - n0);
    } else {
      row(lo[0], hi[0]);
    }
    int a = 1;
    for (; a < D; ++a) {
      if (++k[a] <= hi[a]) break;
      k[a] = lo[a];
    }
    if (a == D) break;
  }
}

template <int D>
template <typename F>
void CellLinkedList<D>::for_each_neighbour(const Vec<D>& x, double cutoff, Index self,
                                           const F& f) const {
  const double cutoff2 = cutoff * cutoff;
  const bool periodic = domain_.any_periodic();
  for_each_range_around(x, [&](std::size_t begin, std::size_t end) {
    if (periodic) {
      for (std::size_t p = begin; p < end; ++p)
        if (particles_[p] != self &&
            domain_.displacement(x, sorted_positions_[p]).squaredNorm() < cutoff2)
          f(particles_[p]);
    } else {
      for (std::size_t p = begin; p < end; ++p)
        if (particles_[p] != self && (x - sorted_positions_[p]).squaredNorm() < cutoff2)
          f(particles_[p]);
    }
  });
}

template <int D>
Index* CellLinkedList<D>::write_neighbours(const Vec<D>& x, double cutoff, Index self,
                                           Index* out) const {
  const double cutoff2 = cutoff * cutoff;
  const bool periodic = domain_.any_periodic();
  for_each_range_around(x, [&](std::size_t begin, std::size_t end) {
    for (std::size_t p = begin; p < end; ++p) {
      const Index j = particles_[p];
      const double r2 = periodic ? domain_.displacement(x, sorted_positions_[p]).squaredNorm()
                                 : (x - sorted_positions_[p]).squaredNorm();
      *out = j;
      out += static_cast<int>(r2 < cutoff2) & static_cast<int>(j != self);
    }
  });
  return out;
}

}  // namespace cosph
