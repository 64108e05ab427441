#include "geometry/regions.hpp"

#include <cstdint>

#include "core/parallel.hpp"

namespace cosph {

template <int D>
std::vector<Index> select_region(const std::vector<Vec<D>>& positions, const Shape<D>& shape) {
  // Flags in parallel (each index writes its own), then a serial compaction keeps the order.
  std::vector<std::uint8_t> inside(positions.size());
  parallel_for_each_index(positions.size(),
                          [&](std::size_t i) { inside[i] = shape.contains(positions[i]); });
  std::vector<Index> selected;
  for (std::size_t i = 0; i < positions.size(); ++i)
    if (inside[i]) selected.push_back(static_cast<Index>(i));
  return selected;
}

template std::vector<Index> select_region<2>(const std::vector<Vec<2>>&, const Shape<2>&);
template std::vector<Index> select_region<3>(const std::vector<Vec<3>>&, const Shape<3>&);

}  // namespace cosph
