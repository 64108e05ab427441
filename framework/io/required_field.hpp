// Field look-up for output code: a missing field is the user's doing (a probe or reduction named
// in the scene that the body does not have), so it is reported as a cosph::RuntimeError naming
// the body, the field and what it was needed for, instead of ParticleSet's std::out_of_range.
#pragma once

#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/particles.hpp"

namespace cosph {

template <int D>
void require_field(const ParticleSet<D>& particles, const std::string& field, FieldKind kind,
                   const std::string& purpose) {
  static const char* const kKindNames[] = {"scalar", "vector", "matrix"};
  const char* wanted = kKindNames[static_cast<int>(kind)];
  if (!particles.has(field))
    throw RuntimeError("body '" + particles.name() + "' has no field '" + field + "' (a " + wanted +
                       " field, needed for " + purpose + ")");
  if (particles.info(field).kind != kind)
    throw RuntimeError("field '" + field + "' of body '" + particles.name() + "' is not a " +
                       wanted + " field, as needed for " + purpose);
}

template <int D>
const std::vector<double>& required_scalar(const ParticleSet<D>& particles,
                                           const std::string& field, const std::string& purpose) {
  require_field(particles, field, FieldKind::Scalar, purpose);
  return particles.scalar(field);
}

template <int D>
const std::vector<Vec<D>>& required_vector(const ParticleSet<D>& particles,
                                           const std::string& field, const std::string& purpose) {
  require_field(particles, field, FieldKind::Vector, purpose);
  return particles.vector(field);
}

}  // namespace cosph
