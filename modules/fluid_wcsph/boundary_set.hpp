// The particles a fluid sees but does not move: its own walls (filled from the scene's shapes,
// fixed or moving with a prescribed velocity) and the contact particles of other bodies that a
// coupler hands in through the `contact` port (e.g. a solid's surface). Both enter every pair
// loop in the same way, through the one-sided Riemann problem of seed 003 eqs. 14-16.
#pragma once

#include <optional>
#include <vector>

#include "core/particles.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "neighbour/neighbour_list.hpp"

namespace cosph {

// Per pair of a neighbour list, the unit vector e_ij = (x_j - x_i) / r_ij and -dW/dr(r_ij) >= 0
// at the configuration of the advection step (the acoustic sub-steps reuse them).
template <int D>
struct PairGeometry {
  std::vector<Vec<D>> direction;
  std::vector<double> gradient;
};

template <int D>
struct BoundarySet {
  explicit BoundarySet(std::string name) : particles(std::move(name)) {}
  // position, velocity, volume; acceleration for contact particles (the pressure extension);
  // force when the scene or a coupler asks for the fluid's force on them.
  ParticleSet<D> particles;
  NeighbourList list;  // fluid particle -> boundary particles
  PairGeometry<D> geometry;
  std::optional<CellLinkedList<D>> cells;  // kept between steps while the set does not move
  bool moves = false;

  bool empty() const { return particles.size() == 0; }
};

// The state a boundary particle w presents to fluid particle i: the fluid's velocity mirrored
// about the boundary's (no penetration, and no slip for the viscous term) and the fluid's
// pressure extended hydrostatically to w, including the boundary's own acceleration a_w:
// p_w = p_i + rho_i (g - a_w) . (x_w - x_i).
template <int D>
struct OneSidedState {
  double pressure;
  Vec<D> velocity;
};

template <int D>
inline OneSidedState<D> one_sided_state(double p_i, double rho_i, const Vec<D>& v_i,
                                        const Vec<D>& v_w, const Vec<D>& g_minus_a,
                                        const Vec<D>& x_w_minus_x_i) {
  return {p_i + rho_i * g_minus_a.dot(x_w_minus_x_i), 2.0 * v_w - v_i};
}

}  // namespace cosph
