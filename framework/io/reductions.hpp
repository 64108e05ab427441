// Whole-body quantities reduced over a ParticleSet, for time-series output and validation:
// kinetic energy, extent, total force, integrals. Every sum goes through deterministic_sum, so
// the results are bit-identical whatever the number of threads.
#pragma once

#include <string>

#include "core/particles.hpp"
#include "core/types.hpp"
#include "kernels/kernel.hpp"

namespace cosph {

// Sum of 0.5 m |v|^2 over the particles, from the scalar field "mass" and the vector field
// "velocity". Throws cosph::RuntimeError naming the body and the missing field if either is
// absent or of another kind.
template <int D>
double total_kinetic_energy(const ParticleSet<D>& particles);

// max - min of the vector field "position" along `axis` (0 <= axis < D; std::invalid_argument
// otherwise); 0 for an empty set. Throws cosph::RuntimeError if "position" is missing.
// Free-surface height at a wave gauge, the line through `at` along `axis` whose base (the floor)
// is at[axis]: the top of the continuous water column over the base, where the kernel-summed
// volume fraction sum_j V_j W(|p - x_j|) first falls below 1/2 going up from one smoothing length
// above the base (linear between samples h/8 apart). Isolated drops and thin spray above the
// column do not count (a lone particle reaches a fraction of about 1/3). Returns at[axis] when
// the gauge is dry.
template <int D>
double surface_height(const ParticleSet<D>& particles, const Kernel& kernel, const Vec<D>& at,
                      int axis);

// The leading edge of a body along +axis: the largest coordinate plus half a particle's size
// (V^(1/D) / 2), e.g. the surge front of a dam break.
template <int D>
double front(const ParticleSet<D>& particles, int axis);

template <int D>
double extent(const ParticleSet<D>& particles, int axis);

// Sum over the particles of a vector field (e.g. total force or momentum).
template <int D>
Vec<D> total_vector(const ParticleSet<D>& particles, const std::string& field);

// Sum over the particles of a scalar field (e.g. total mass).
template <int D>
double total_scalar(const ParticleSet<D>& particles, const std::string& field);

// SPH volume integral sum_i V_i f_i of a scalar field, with V_i from the scalar field "volume".
template <int D>
double integral(const ParticleSet<D>& particles, const std::string& scalar_field);

#define COSPH_DECLARE_REDUCTIONS(D)                                                             \
  extern template double total_kinetic_energy<D>(const ParticleSet<D>&);                        \
  extern template double extent<D>(const ParticleSet<D>&, int);                                 \
  extern template double front<D>(const ParticleSet<D>&, int);                                  \
  extern template double surface_height<D>(const ParticleSet<D>&, const Kernel&, const Vec<D>&, \
                                           int);                                                \
  extern template Vec<D> total_vector<D>(const ParticleSet<D>&, const std::string&);            \
  extern template double total_scalar<D>(const ParticleSet<D>&, const std::string&);            \
  extern template double integral<D>(const ParticleSet<D>&, const std::string&);
COSPH_DECLARE_REDUCTIONS(2)
COSPH_DECLARE_REDUCTIONS(3)
#undef COSPH_DECLARE_REDUCTIONS

}  // namespace cosph
