// Free-surface particles of a body and their outward normals, for boundary conditions (loads,
// traction-free faces) and contact. Works on any particle cloud, lattice or not, given its
// typical spacing.
#pragma once

#include <vector>

#include "core/types.hpp"

namespace cosph {

template <int D>
struct Surface {
  std::vector<Index> particles;  // increasing
  std::vector<Vec<D>> normals;   // outward unit normal of particles[k]
};

// Surface particles of the cloud (positions with their volumes; spacing is the typical distance
// between neighbours) and their outward unit normals; the criterion and its measured accuracy
// are documented in surface.cpp. For a lattice-filled box the result is exactly the outermost
// layer, and a face particle more than 5 spacings from the other faces gets the face's axis
// normal to rounding. Bodies should be at least about 6 spacings thick for accurate normals.
// Deterministic for any number of threads.
// Throws std::invalid_argument if the sizes differ or spacing is not positive.
template <int D>
Surface<D> detect_surface(const std::vector<Vec<D>>& positions, const std::vector<double>& volumes,
                          double spacing);

}  // namespace cosph
