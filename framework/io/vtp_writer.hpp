// VTK XML PolyData (.vtp) output of one body's particles, opened directly by ParaView.
#pragma once

#include <string>

#include "core/particles.hpp"

namespace cosph {

// Writes `particles` to `path` as a VTK XML PolyData file:
//  - one point per particle, coordinates from the vector field `position_field` (padded to three
//    components in 2D, as VTK points are always 3D), and one vertex cell per point so that
//    ParaView renders the points without a Glyph filter;
//  - every field whose FieldFlags::output is set, as point data in registration order: scalars as
//    1 component, vectors as 3 (z = 0 in 2D), matrices as 9 in row-major order (2D matrices
//    embedded in the upper-left of a 3x3 with zeros elsewhere). The position field is not
//    repeated as point data, it is the points.
// Data is appended raw binary (Float64 values, Int64 cell arrays, UInt64 block headers, native
// byte order): no base64 or ASCII conversion, so writing costs little more than the copy.
// The file is replaced atomically. Throws cosph::RuntimeError naming `path` if it cannot be
// written, or naming the body if `position_field` is not a vector field of it.
template <int D>
void write_vtp(const std::string& path, const ParticleSet<D>& particles,
               const std::string& position_field = "position");

extern template void write_vtp<2>(const std::string&, const ParticleSet<2>&, const std::string&);
extern template void write_vtp<3>(const std::string&, const ParticleSet<3>&, const std::string&);

}  // namespace cosph
