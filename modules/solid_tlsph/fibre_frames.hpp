// Fibre frames of a solid body: per particle the unit fibre f, sheet s (and, in 3D, sheet-normal
// n = f x s) directions as the columns of a matrix, in the reference configuration. Anisotropic
// laws (Holzapfel-Ogden, Guccione), the active stress and the fibre-frame strain output use them.
#pragma once

#include <string>
#include <vector>

#include "core/types.hpp"
#include "scene.pb.h"

namespace cosph {

// The frame with fibre along f and sheet along the part of s orthogonal to f. Throws
// std::invalid_argument if f is zero or s is (nearly) parallel to f.
template <int D>
Mat<D> orthonormal_frame(const Vec<D>& f, const Vec<D>& s);

// The Land et al. (2015) ventricle rule at point x: transmural depth t in [0, 1] from the
// confocal-free family of ellipsoids r_s(t), r_l(t) interpolating the two walls, helix angle
// linear in t, fibre = cos(angle) e_circumferential + sin(angle) e_longitudinal, sheet along the
// wall normal. Orientation of e_longitudinal follows Land's parametrisation (u negative, pointing
// from the apex towards the base on the wall).
Mat<3> land_ellipsoid_frame(const proto::EllipsoidFibreRule& rule, const Vec<3>& x);

// Per particle 1 where the scene's fibre rule leaves the fibre's direction within the wall
// undefined, else 0; empty where it is defined everywhere (constant and CSV fibres). The ellipsoid
// rule is singular on the long axis (rho = 0, the apex nodes of a conforming placement): there the
// helix field turns through every direction of the wall's plane around the point, and only its
// average over those directions, (I - s0 (x) s0) / 2 with s0 the sheet (the wall normal), has a
// limit. The frame the rule gives there has an arbitrary fibre in that plane.
template <int D>
std::vector<char> fibre_undefined_in_wall(const proto::FibreSpec& spec,
                                          const std::vector<Vec<D>>& X);

// Frames of all particles (reference positions X) from the scene's fibre spec: constant (default
// fibre x, sheet y), nearest row of a CSV file (within 2 spacings), or the ellipsoid rule.
// Errors are ConfigErrors at `key` (e.g. "modules[0].solid.fibres").
template <int D>
std::vector<Mat<D>> build_fibre_frames(const proto::FibreSpec& spec, const std::vector<Vec<D>>& X,
                                       double spacing, const std::string& key,
                                       const std::string& scene_directory);

}  // namespace cosph
