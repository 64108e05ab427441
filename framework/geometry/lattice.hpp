// Fills a shape with particles on a cubic lattice. The lattice is fixed in space by an anchor, so
// bodies generated with the same anchor and spacing interleave without gaps or overlaps: a
// particle of one body never sits closer than one spacing to a particle of another.
#pragma once

#include "core/types.hpp"
#include "geometry/particle_cloud.hpp"
#include "geometry/shapes.hpp"

namespace cosph {

// Upper bound on the lattice sites examined (the sites of the shape's bounding box): beyond it
// the request is almost certainly a unit mistake, and it would exhaust memory anyway.
inline constexpr double kMaxLatticeSites = 2e8;

// Sites anchor + (k + 1/2) * spacing (k integer, per axis) that the shape contains, each with
// volume spacing^D. Order: axis 0 (x) fastest, then y, then z, i.e. increasing (z, y, x)
// lexicographically; the result does not depend on the number of threads.
// Throws std::invalid_argument if spacing is not positive and finite, if the bounding box holds
// more than kMaxLatticeSites sites, or if no site lies inside the shape.
template <int D>
ParticleCloud<D> lattice_fill(const Shape<D>& shape, double spacing,
                              const Vec<D>& anchor = Vec<D>::Zero());

}  // namespace cosph
