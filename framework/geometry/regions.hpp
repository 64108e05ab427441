// Named regions of a body (where a load is applied, which particles are fixed, where a port
// couples) are the particles whose positions a shape contains.
#pragma once

#include <vector>

#include "core/types.hpp"
#include "geometry/shapes.hpp"

namespace cosph {

// Indices of the positions the shape contains, in increasing order (possibly none).
template <int D>
std::vector<Index> select_region(const std::vector<Vec<D>>& positions, const Shape<D>& shape);

}  // namespace cosph
