// Neighbour lists in compressed-sparse-row form: the neighbours of particle i are
// index[offset[i] .. offset[i+1]), in a deterministic order (cell by cell, then by index).
#pragma once

#include <span>
#include <vector>

#include "core/types.hpp"

namespace cosph {

struct NeighbourList {
  std::vector<std::size_t> offset{0};
  std::vector<Index> index;

  std::size_t particle_count() const { return offset.size() - 1; }
  std::size_t pair_count() const { return index.size(); }
  std::span<const Index> of(std::size_t i) const {
    return {index.data() + offset[i], offset[i + 1] - offset[i]};
  }
};

}  // namespace cosph
