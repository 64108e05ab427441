// Particles on the nodes of a structured grid that follows a truncated ellipsoidal shell (the
// Land et al. 2015 ventricle), the way a finite-element mesh of it places its nodes (seed 000
// sets the FE nodes as particles for problems 2 and 3), instead of a Cartesian lattice that cuts
// the curved walls differently at every spacing.
//
// The shell is parametrised as in Land's benchmark: nested prolate spheroids of radii
//   r_s(t) = rs_in + t (rs_out - rs_in),  r_l(t) = rl_in + t (rl_out - rl_in),   t in [0, 1],
// and x = (r_s(t) sin u cos v, r_s(t) sin u sin v, r_l(t) cos u), where the latitude
// u = u_b(t) + s (pi - u_b(t)) runs from the base plane (s = 0, cos u_b(t) = z_truncation / r_l(t))
// to the apex (s = 1). Nodes sit on n_t + 1 layers uniform in t and n_s + 1 rings whose s lie at
// equal arc lengths along the mid-wall meridian (uniform in s, the rings would crowd at the apex,
// where the meridian follows the short radius), so that the endocardium (t = 0), epicardium
// (t = 1) and base (s = 0) carry nodes exactly; each
// ring holds round(2 pi rho / spacing) nodes (at least 3) equally spaced in v from v = 0, and the
// apex of each layer one node. n_t and n_s are the wall's thickness and the mid-wall meridian's
// length over the spacing, rounded.
//
// Each node carries the volume of its dual cell (half an interval either side in t, halfway to the
// neighbouring rings in s, clipped at the faces, and its share of the ring in v), integrated
// exactly enough (Gauss-Legendre) that
// the volumes sum to the shell's volume to round-off. The faces "inner", "outer" and "base" come
// with each node's outward area vector over the same dual cell, and each node its dual cell's
// centroid and covariance (ParticleCloud::cells), integrated the same way.
#pragma once

#include "geometry/particle_cloud.hpp"
#include "geometry/shapes.hpp"

namespace cosph {

// Throws std::invalid_argument if the spacing is not positive and finite or if the truncation
// plane does not cut the cavity open (z_truncation must lie strictly between -rl_in and rl_in).
ParticleCloud<3> conforming_shell_nodes(const TruncatedEllipsoidalShell& shell, double spacing);

}  // namespace cosph
