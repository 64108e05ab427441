// Particles of one body before they become a ParticleSet: positions and the volume each one
// stands for. Produced by lattice filling and by point-cloud files.
#pragma once

#include <vector>

#include "core/types.hpp"

namespace cosph {

template <int D>
struct ParticleCloud {
  std::vector<Vec<D>> positions;
  std::vector<double> volumes;  // one per position, > 0
};

}  // namespace cosph
