// Fills a shape with particles on a cubic lattice, at the cells' centres or at their vertices. The
// lattice is fixed in space by an anchor, so bodies generated with the same anchor and spacing
// interleave without gaps or overlaps: a particle of one body never sits closer than one spacing to
// a particle of another.
#pragma once

#include "core/types.hpp"
#include "geometry/particle_cloud.hpp"
#include "geometry/shapes.hpp"

namespace cosph {

// Upper bound on the lattice sites examined (the sites of the shape's bounding box): beyond it
// the request is almost certainly a unit mistake, and it would exhaust memory anyway.
inline constexpr double kMaxLatticeSites = 2e8;

// Where the particles sit on the lattice of cells anchor + [k, k + 1] * spacing (k integer):
// - cell: at the cells' centres anchor + (k + 1/2) * spacing, each with volume spacing^D (SPH's
//   usual filling; the outermost particles sit half a spacing inside a lattice-aligned face);
// - vertex: at the cells' vertices anchor + k * spacing, as the nodes of a finite-element grid
//   (seed 000 places its particles so), each with the volume of its dual cell
//   [x - spacing/2, x + spacing/2]^D that lies inside the shape: for a box whose faces lie on the
//   lattice, half, a quarter and an eighth of spacing^D on its faces, edges and corners, so that
//   the volumes sum to the box's exactly. The fraction is measured on 4^D sub-points per dual
//   cell (exact for faces through a vertex or halfway between vertices; across a curved face the
//   dual cells of the nodes just outside are lost, a first-order deficit); a site within 1e-9
//   spacings of the shape counts as on it, so that rounding cannot drop a face's layer.
// - conforming: not a lattice; a shape's own structured grid (shell_nodes.hpp), built by the
//   scene's body builder, never by lattice_fill.
enum class LatticePlacement { cell, vertex, conforming };

// The sites of the placement that the shape contains, with their volumes. Order: axis 0 (x)
// fastest, then y, then z, i.e. increasing (z, y, x) lexicographically; the result does not depend
// on the number of threads. Throws std::invalid_argument if spacing is not positive and finite, if
// the bounding box holds more than kMaxLatticeSites sites, or if no site lies inside the shape.
template <int D>
ParticleCloud<D> lattice_fill(const Shape<D>& shape, double spacing,
                              const Vec<D>& anchor = Vec<D>::Zero(),
                              LatticePlacement placement = LatticePlacement::cell);

// The depth of a vertex site's dual cell inside the shape along a unit direction (a surface's
// outward normal): the length of the segment x + t direction, |t| <= spacing/2, that the shape
// contains, measured on the 4 sub-points per axis that measure the dual cell's volume (each
// within 1e-9 spacings of the shape counts, as a site does: the segment of a node on an edge runs
// along a face). With the
// volume V of lattice_fill, V / depth is the site's share of the face: exact for a face
// perpendicular to an axis wherever it falls between two vertices (an edge site's share is half
// of spacing^(D-1) when the edge lies on a vertex, more when the cell reaches past it).
template <int D>
double dual_cell_depth(const Shape<D>& shape, const Vec<D>& x, const Vec<D>& direction,
                       double spacing);

// The centroid (relative to the site) and the covariance of the part of a site's cell that the
// shape contains: the first two moments that a quadrature over the cell must reproduce to
// integrate quadratic fields exactly. For cell placement the whole cell [x - spacing/2,
// x + spacing/2]^D (centroid 0, covariance spacing^2 / 12 I); for vertex placement its dual cell,
// measured on the 4^D sub-points that measure its volume, each standing for its sub-cell (whose
// own covariance is added): exact wherever lattice_fill's volume is.
template <int D>
CellMoments<D> cell_moments(const Shape<D>& shape, const Vec<D>& x, double spacing,
                            LatticePlacement placement);

}  // namespace cosph
