#include "neighbour/cell_linked_list.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/error.hpp"
#include "core/parallel.hpp"

namespace cosph {

template <int D>
CellLinkedList<D>::CellLinkedList(const std::vector<Vec<D>>& positions, double cutoff,
                                  const Domain<D>& domain)
    : positions_(positions), domain_(domain), cell_size_(0.5 * cutoff) {
  if (!(cutoff > 0.0)) throw std::invalid_argument("cell-linked list: cut-off must be positive");
  // The bounds of the finite positions: a non-finite one (a blown-up run, a damaged
  // checkpoint, before the health monitor reports it) goes to cell 0 (cell_of_position) and
  // must not make the grid's size NaN, whose conversion to a cell count is undefined.
  Vec<D> lo = Vec<D>::Constant(0.0), hi = Vec<D>::Constant(0.0);
  bool first = true;
  for (const auto& x : positions) {
    if (!x.allFinite()) continue;
    lo = first ? x : Vec<D>(lo.cwiseMin(x));
    hi = first ? x : Vec<D>(hi.cwiseMax(x));
    first = false;
  }
  // Sparse clouds in a large box would create mostly empty cells: widen the cells so that there
  // are at most a few per particle (a wider cell is still correct, only less selective).
  double volume = 1.0;
  for (int a = 0; a < D; ++a)
    volume *= std::max(domain.periodic[a] ? domain.length(a) : hi[a] - lo[a], cutoff);
  const double max_cells = 4.0 * static_cast<double>(std::max<std::size_t>(positions.size(), 1));
  if (volume / std::pow(cell_size_, D) > max_cells)
    cell_size_ = std::max(cell_size_, std::pow(volume / max_cells, 1.0 / D));
  reach_ = cell_size_ >= cutoff ? 1 : 2;

  for (int a = 0; a < D; ++a) {
    if (domain.periodic[a]) {
      origin_[a] = domain.lower[a];
      const double L = domain.length(a);
      if (std::floor(L / cutoff) < 3)
        // A scene's input (its domain against its spacing): a ConfigError, which every caller
        // reports with its key path (found by scene_fuzz: std::invalid_argument escaped the run).
        throw ConfigError("domain.periodic", "periodic axis " + std::to_string(a) + " is " +
                                                 std::to_string(L) +
                                                 " long, shorter than three cut-off radii (" +
                                                 std::to_string(3 * cutoff) +
                                                 "): make the spacing finer or the period longer");
      // On a periodic axis the cells must tile the period exactly; they stay at least
      // cell_size_ wide, and there are at least 2 reach + 1 of them so that a stencil never
      // meets the same cell twice (then L / (2 reach + 1) times reach still covers the cut-off,
      // as L >= 3 cut-offs).
      cells_[a] = std::max(2 * reach_ + 1, static_cast<int>(std::floor(L / cell_size_)));
    } else {
      origin_[a] = lo[a];
      cells_[a] = std::max(1, static_cast<int>(std::floor((hi[a] - lo[a]) / cell_size_)) + 1);
    }
  }

  std::size_t total = 1;
  for (int a = 0; a < D; ++a) total *= static_cast<std::size_t>(cells_[a]);
  const std::size_t n = positions.size();
  std::vector<std::size_t> cell(n);
  parallel_for_each_index(n,
                          [&](std::size_t i) { cell[i] = linear(cell_of_position(positions[i])); });
  // Counting sort: stable, so particles in a cell stay in index order (deterministic lists).
  cell_start_.assign(total + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++cell_start_[cell[i] + 1];
  for (std::size_t c = 0; c < total; ++c) cell_start_[c + 1] += cell_start_[c];
  particles_.resize(n);
  std::vector<std::size_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) particles_[fill[cell[i]]++] = static_cast<Index>(i);
  std::size_t fullest = 0;
  for (std::size_t c = 0; c < total; ++c)
    fullest = std::max(fullest, cell_start_[c + 1] - cell_start_[c]);
  candidate_bound_ = fullest;
  for (int a = 0; a < D; ++a) candidate_bound_ *= static_cast<std::size_t>(2 * reach_ + 1);
  sorted_positions_.resize(n);
  parallel_for_each_index(n,
                          [&](std::size_t p) { sorted_positions_[p] = positions[particles_[p]]; });
}

template <int D>
std::array<int, D> CellLinkedList<D>::cell_of_position(const Vec<D>& x) const {
  std::array<int, D> c;
  for (int a = 0; a < D; ++a) {
    double width = cell_size_;
    if (domain_.periodic[a]) width = domain_.length(a) / cells_[a];
    double s = (x[a] - origin_[a]) / width;
    if (domain_.periodic[a]) s -= cells_[a] * std::floor(s / cells_[a]);
    // Clamp in floating point first: converting a far-away (or NaN) coordinate to int is UB.
    const double clamped =
        std::isnan(s) ? 0.0 : std::clamp(std::floor(s), 0.0, double(cells_[a] - 1));
    c[a] = static_cast<int>(clamped);
  }
  return c;
}

template <int D>
std::size_t CellLinkedList<D>::linear(const std::array<int, D>& c) const {
  std::size_t k = 0;
  for (int a = D - 1; a >= 0; --a) k = k * static_cast<std::size_t>(cells_[a]) + c[a];
  return k;
}

namespace {

// One search per particle: fixed blocks of particles (independent of the thread count) collect
// their neighbours into block-local buffers in parallel; a prefix sum over the blocks then places
// every block in the CSR arrays. The lists come out in the same order whatever the number of
// threads, without atomics, and the search runs once instead of the count-then-fill twice.
// write(i, out) stores particle i's neighbours from out on and returns their end; out has room
// for `bound` indices.
template <typename Write>
NeighbourList build_list(std::size_t n, std::size_t bound, const Write& write) {
  constexpr std::size_t kBlock = 128;
  const std::size_t blocks = (n + kBlock - 1) / kBlock;
  std::vector<std::vector<Index>> found(blocks);
  NeighbourList list;
  list.offset.assign(n + 1, 0);
  // One task per block (parallel_for_each_index's grain of 256 would run all blocks in one).
  const auto each_block = [&](const auto& body) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t b = r.begin(); b != r.end(); ++b) body(b);
                      });
  };
  each_block([&](std::size_t b) {
    auto& buffer = found[b];
    std::size_t used = 0;
    const std::size_t end = std::min(n, (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i) {
      if (buffer.size() < used + bound) buffer.resize(std::max(2 * buffer.size(), used + bound));
      Index* const from = buffer.data() + used;
      const std::size_t count = static_cast<std::size_t>(write(i, from) - from);
      list.offset[i + 1] = count;  // count for now, offsets below
      used += count;
    }
    buffer.resize(used);
  });
  for (std::size_t i = 0; i < n; ++i) list.offset[i + 1] += list.offset[i];
  list.index.resize(list.offset[n]);
  each_block([&](std::size_t b) {
    std::copy(found[b].begin(), found[b].end(),
              list.index.begin() + static_cast<std::ptrdiff_t>(list.offset[b * kBlock]));
  });
  return list;
}

}  // namespace

template <int D>
NeighbourList build_inner_list(const std::vector<Vec<D>>& positions, double cutoff,
                               const Domain<D>& domain) {
  CellLinkedList<D> cells(positions, cutoff, domain);
  return build_list(positions.size(), cells.candidate_bound(), [&](std::size_t i, Index* out) {
    return cells.write_neighbours(positions[i], cutoff, static_cast<Index>(i), out);
  });
}

template <int D>
NeighbourList build_contact_list(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b,
                                 double cutoff, const Domain<D>& domain) {
  const CellLinkedList<D> cells(b, cutoff, domain);
  return build_contact_list<D>(a, cells, cutoff);
}

template <int D>
NeighbourList build_contact_list(const std::vector<Vec<D>>& a, const CellLinkedList<D>& cells,
                                 double cutoff) {
  constexpr Index none = static_cast<Index>(-1);
  return build_list(a.size(), cells.candidate_bound(), [&](std::size_t i, Index* out) {
    return cells.write_neighbours(a[i], cutoff, none, out);
  });
}

template <int D>
NeighbourList brute_force_list(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b,
                               double cutoff, const Domain<D>& domain, bool same_set) {
  NeighbourList list;
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      if (same_set && i == j) continue;
      if (domain.displacement(a[i], b[j]).norm() < cutoff)
        list.index.push_back(static_cast<Index>(j));
    }
    list.offset.push_back(list.index.size());
  }
  return list;
}

template <int D>
std::vector<Index> cell_sort_order(const std::vector<Vec<D>>& positions, double cell_size,
                                   const Domain<D>& domain) {
  return CellLinkedList<D>(positions, cell_size, domain).cell_order();
}

#define COSPH_INSTANTIATE(D)                                                                   \
  template class CellLinkedList<D>;                                                            \
  template NeighbourList build_inner_list<D>(const std::vector<Vec<D>>&, double,               \
                                             const Domain<D>&);                                \
  template NeighbourList build_contact_list<D>(                                                \
      const std::vector<Vec<D>>&, const std::vector<Vec<D>>&, double, const Domain<D>&);       \
  template NeighbourList build_contact_list<D>(const std::vector<Vec<D>>&,                     \
                                               const CellLinkedList<D>&, double);              \
  template NeighbourList brute_force_list<D>(                                                  \
      const std::vector<Vec<D>>&, const std::vector<Vec<D>>&, double, const Domain<D>&, bool); \
  template std::vector<Index> cell_sort_order<D>(const std::vector<Vec<D>>&, double,           \
                                                 const Domain<D>&);
COSPH_INSTANTIATE(2)
COSPH_INSTANTIATE(3)

}  // namespace cosph
