// Fibre frames of a solid body: per particle the unit fibre f, sheet s (and, in 3D, sheet-normal
// n = f x s) directions as the columns of a matrix, in the reference configuration. Anisotropic
// laws (Holzapfel-Ogden, Guccione), the active stress and the fibre-frame strain output use them.
#pragma once

#include <numbers>
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
// limit. The frame the rule gives there has an arbitrary fibre in that plane; the solid takes the
// mean over the wall's fibres (below) of whatever depends on it.
template <int D>
std::vector<char> fibre_undefined_in_wall(const proto::FibreSpec& spec,
                                          const std::vector<Vec<D>>& X);

// Where the fibre is undefined within the wall, a particle stands for material whose fibres turn
// through every direction of the wall's plane: what depends on the fibre is averaged over
// `kWallFibres` fibres turned about the sheet s0 at equal steps over half a turn (f0 and -f0 are
// one fibre). A quantity of the frame whose dependence on the turn theta has period pi is a sum
// of harmonics of 2 theta, and the equal steps integrate those below 2 kWallFibres theta exactly:
// the stress of Land's Guccione law at about 10% strain changes by 1.3e-9 of itself from 8 to 16
// fibres (solid_tlsph_test.cpp, FibreFrames), and an F symmetric about s0 gives a stress exactly
// symmetric about it (its turn enters through 2 theta alone).
constexpr int kWallFibres = 8;

// The frame turned about its sheet (column 1) by `angle`: f' = cos f + sin n, n' = -sin f + cos n.
Mat<3> frame_turned_about_sheet(const Mat<3>& frame, double angle);

// The mean of value(frame turned by k pi / kWallFibres) over k = 0 .. kWallFibres - 1.
template <class Value>
auto mean_over_wall_fibres(const Mat<3>& frame, Value&& value) {
  auto sum = value(frame);
  for (int k = 1; k < kWallFibres; ++k)
    sum += value(frame_turned_about_sheet(frame, k * std::numbers::pi / kWallFibres));
  return decltype(sum)(sum / static_cast<double>(kWallFibres));
}

// Frames of all particles (reference positions X) from the scene's fibre spec: constant (default
// fibre x, sheet y), nearest row of a CSV file (within 2 spacings), or the ellipsoid rule.
// Errors are ConfigErrors at `key` (e.g. "modules[0].solid.fibres").
template <int D>
std::vector<Mat<D>> build_fibre_frames(const proto::FibreSpec& spec, const std::vector<Vec<D>>& X,
                                       double spacing, const std::string& key,
                                       const std::string& scene_directory);

}  // namespace cosph
