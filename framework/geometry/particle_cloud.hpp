// Particles of one body before they become a ParticleSet: positions and the volume each one
// stands for. Produced by lattice filling, by shape-conforming placements and by point-cloud
// files.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace cosph {

// A named face of a body's boundary (e.g. a ventricle's endocardium) as a placement that knows
// it exactly gives it: the particles on the face and the outward area vector N dA each one
// carries, which sum to the face's own area vector.
template <int D>
struct BoundaryFace {
  std::string name;
  std::vector<std::size_t> particles;  // indices into the cloud (or body) they come with
  std::vector<Vec<D>> areas;           // outward N dA of particles[k], reference configuration
};

// The centroid (relative to the particle) and covariance of the region a particle stands for: what
// an integration over the particles' cells needs (solid energy_quadrature: dual_cell).
template <int D>
struct CellMoments {
  Vec<D> centroid;
  Mat<D> covariance;
};

template <int D>
struct ParticleCloud {
  std::vector<Vec<D>> positions;
  std::vector<double> volumes;         // one per position, > 0
  std::vector<BoundaryFace<D>> faces;  // empty unless the placement knows the faces
  std::vector<CellMoments<D>> cells;   // one per position where the placement knows its cells
};

}  // namespace cosph
