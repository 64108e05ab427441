// Reads a body's particles from a CSV file, for geometries made elsewhere (meshers, image
// segmentation, other codes).
#pragma once

#include <string>

#include "geometry/particle_cloud.hpp"

namespace cosph {

// Format: comma-separated; lines that are blank or start with '#' (after blanks) are skipped; the
// first other line is the header naming the columns (names trimmed, case-insensitive, optionally
// in double quotes). Required columns: x, y, z (D = 3 only) and volume, in any order; other
// columns are ignored. Every data line has as many fields as the header. Particles keep the
// file's order.
// Throws cosph::RuntimeError whose message starts with "<path>:<line>: " (or "<path>: " when no
// line applies) if the file cannot be read, has no header, lacks a required column or repeats
// one, has a line with the wrong number of fields, a required field that is not a finite number,
// a volume that is not positive, or no data line at all.
template <int D>
ParticleCloud<D> read_point_cloud_csv(const std::string& path);

}  // namespace cosph
