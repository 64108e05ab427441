// The particles a fluid sees but does not move: its own walls (filled from the scene's shapes,
// fixed or moving with a prescribed velocity) and the contact particles of other bodies that a
// coupler hands in through the `contact` port (e.g. a solid's surface). Both enter every pair
// loop in the same way, through the one-sided Riemann problem of seed 003 eqs. 14-16.
#pragma once

#include <algorithm>
#include <optional>
#include <vector>

#include "core/particles.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "neighbour/neighbour_list.hpp"

namespace cosph {

// Per pair of a neighbour list, the unit vector e_ij = (x_j - x_i) / r_ij, -dW/dr(r_ij) >= 0 and
// r_ij at the configuration of the advection step (the acoustic sub-steps reuse them, and so do
// the advection step's own loops until the transport shift moves the particles).
template <int D>
struct PairGeometry {
  std::vector<Vec<D>> direction;
  std::vector<double> gradient;  // -dW/dr
  std::vector<double> distance;
  // -dW/dr / r, only with viscosity: its force is recomputed at every split step when the viscous
  // limit is below the advection step, and the division would be redone each time.
  std::vector<double> gradient_over_distance;
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
  // Per fluid particle, the boundary's unit normal as that particle sees it, pointing into the
  // boundary: the direction of the gradient of the boundary's kernel-summed volume,
  // sum_w V_w grad_i W_iw, at the configuration of the advection step (zero where the particle
  // has no neighbour in the set, or where the sum cancels). Only for an inviscid fluid, whose
  // Riemann dissipation acts along it: a slip boundary resists the fluid's approach, not its
  // sliding (seed 003 eq. 14).
  std::vector<Vec<D>> normal;
  // Per boundary particle, its own unit normal into the boundary: the direction of the gradient of
  // the set's kernel-summed volume at the particle (zero deep inside, where the sum is flat).
  // Only for walls (a body's one-layer contact surface has no volume gradient across it), and
  // only for an inviscid fluid; rebuilt with the set's cell list.
  std::vector<Vec<D>> own_normal;

  // The fluid's force on each boundary particle, recorded pair by pair inside the fluid's own
  // loops (only for sets whose force is asked for: a coupler's contact body, walls with the
  // `wall_force` or `wall_viscous_force` output): the pressure force of the last acoustic sub-step,
  // the reaction of the very Riemann pressures the fluid used in it, and the viscous force of the
  // advection step (of the last acoustic sub-step, the mean over its split steps, where the viscous
  // force is sub-cycled). The impulse the fluid receives is then exactly opposite to what the
  // boundary receives. (The walls' output is these records' mean over the step, pair_impulse
  // below.)
  bool records = false;
  std::vector<Vec<D>> pair_pressure_force, pair_viscous_force;
  NeighbourList pairs_of;  // boundary particle -> indices of its pairs in `list`
  // Walls with a force output: the recorded pair forces integrated over the open
  // advection step's acoustic sub-steps, and the time they cover. The output is their mean, whose
  // impulse is the one the fluid received over the step. The last sub-step's force alone is one
  // phase of the step's cycle (the density is reinitialised or summed at its start), not the
  // step's force: in a tank at rest it read 0.35% under what the water's momentum says the walls
  // carry, 0.74% with the free-surface shift, where the mean reads within 0.002% of it, and the
  // Re = 100 cylinder's drag 10% under the mean at D/20.
  std::vector<Vec<D>> pair_impulse;
  // The viscous share of pair_impulse alone (walls with the `wall_viscous_force` output).
  std::vector<Vec<D>> pair_viscous_impulse;
  double impulse_time = 0.0;

  bool empty() const { return particles.size() == 0; }
};

// The transpose of a fluid -> boundary list as pair indices, in ascending order for each boundary
// particle (a deterministic gather of per-pair values).
template <int D>
void build_pairs_of(BoundarySet<D>& b) {
  const std::size_t n = b.particles.size(), pairs = b.list.pair_count();
  b.pairs_of.offset.assign(n + 1, 0);
  for (std::size_t k = 0; k < pairs; ++k) ++b.pairs_of.offset[b.list.index[k] + 1];
  for (std::size_t w = 0; w < n; ++w) b.pairs_of.offset[w + 1] += b.pairs_of.offset[w];
  b.pairs_of.index.resize(pairs);
  std::vector<std::size_t> next(b.pairs_of.offset.begin(), b.pairs_of.offset.end() - 1);
  for (std::size_t k = 0; k < pairs; ++k) b.pairs_of.index[next[b.list.index[k]]++] = Index(k);
}

// Sums a per-pair value over each boundary particle's pairs, in ascending pair order (zero where
// the set has no pair transpose yet). add(sum, k) adds pair k's share to sum.
template <int D, class AddPair>
std::vector<Vec<D>> gather_pairs(const BoundarySet<D>& b, AddPair add) {
  std::vector<Vec<D>> sum(b.particles.size(), Vec<D>::Zero());
  if (b.pairs_of.offset.size() != sum.size() + 1) return sum;
  for (std::size_t w = 0; w < sum.size(); ++w)
    for (Index k : b.pairs_of.of(w)) add(sum[w], k);
  return sum;
}

// The recorded force on every boundary particle (zero before the fluid's first sub-step).
template <int D>
std::vector<Vec<D>> recorded_force(const BoundarySet<D>& b) {
  const std::size_t pairs = b.list.pair_count();
  const bool pressure = b.pair_pressure_force.size() == pairs,
             viscous = b.pair_viscous_force.size() == pairs;
  // Pressure before viscous, pair by pair: the order a coupler's contact force was always summed
  // in.
  return gather_pairs(b, [&](Vec<D>& force, Index k) {
    if (pressure) force += b.pair_pressure_force[k];
    if (viscous) force += b.pair_viscous_force[k];
  });
}

// The mean force on every boundary particle over the sub-steps impulse_time covers, from per-pair
// impulses (pair_impulse or its viscous share; zero before the first sub-step or where the
// impulses do not match the pair list).
template <int D>
std::vector<Vec<D>> mean_pair_force(const BoundarySet<D>& b, const std::vector<Vec<D>>& impulse) {
  if (!(b.impulse_time > 0.0) || impulse.size() != b.list.pair_count())
    return std::vector<Vec<D>>(b.particles.size(), Vec<D>::Zero());
  std::vector<Vec<D>> force = gather_pairs(b, [&](Vec<D>& sum, Index k) { sum += impulse[k]; });
  for (Vec<D>& f : force) f /= b.impulse_time;
  return force;
}

// The mean recorded force on every boundary particle over the sub-steps pair_impulse covers (the
// last sub-step's, recorded_force, where it covers none).
template <int D>
std::vector<Vec<D>> mean_recorded_force(const BoundarySet<D>& b) {
  if (!(b.impulse_time > 0.0) || b.pair_impulse.size() != b.list.pair_count())
    return recorded_force(b);
  return mean_pair_force(b, b.pair_impulse);
}

// The state a boundary particle w presents to fluid particle i: the fluid's velocity mirrored
// about the boundary's (no penetration, and no slip for the viscous term) and the fluid's
// pressure extended hydrostatically to w, including the boundary's own acceleration a_w:
// p_w = p_i + rho_i (g - a_w) . (x_w - x_i), the extension optionally clamped at zero.
template <int D>
struct OneSidedState {
  double pressure;
  Vec<D> velocity;
};

template <int D>
inline OneSidedState<D> one_sided_state(double p_i, double rho_i, const Vec<D>& v_i,
                                        const Vec<D>& v_w, const Vec<D>& g_minus_a,
                                        const Vec<D>& x_w_minus_x_i, bool clamped) {
  const double extension = rho_i * g_minus_a.dot(x_w_minus_x_i);
  return {p_i + (clamped ? std::max(0.0, extension) : extension), 2.0 * v_w - v_i};
}

}  // namespace cosph
