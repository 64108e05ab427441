// Wall pressure sensors: what a transducer flush with a wall measures, the mean pressure over its
// face, from the force a fluid exerts on the wall particles behind that face.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "core/particles.hpp"
#include "core/types.hpp"
#include "neighbour/domain.hpp"

namespace cosph {

// Sensors on one flat stretch of wall (one outward normal), each a face of the given diameter
// centred on a point of the wall's surface: a segment across the normal in 2D, a disc in 3D.
//
// Every wall particle w behind the face (at a depth between 0 and `depth` along -normal) owns a
// share of the wall's surface: the segment (2D) or square (3D) of side a_w = V_w^(1/D) centred on
// its projection onto the face's plane. The sensor reads
//   p = sum_w A_w (-F_w . n) / a_w^(D-1) / A,
// with A_w the area of w's share that the face covers, F_w the force on w and A the face's area
// (its length in 2D): the pressure on each column of wall particles (the force summed over the
// column's layers per unit of its share), averaged over the face. It is exact for a uniform
// pressure whatever the face's size, and a sensor narrower than a particle reads the column in
// front of it. In a concave corner, where another wall's first layer lies in front of the plane,
// the particles behind that layer are not behind the face: the water pushes them along the pairs'
// diagonals, and each passes its force to the nearest particle behind the face (within `depth`),
// so that a face at the wall's foot reads the push on its end. The meeting wall must be in the
// same particle set (a fluid's walls all are; a solid module's body is not, and a sensor at its
// foot reads the corner's share low), and any wall particle of the set within one spacing in
// front of the plane counts as one (a moving wall passing the face too, while it is there). The
// face must lie on the wall (a face over a wall's edge reads low), and a sensor that no wall
// particle covers reads NaN.
template <int D>
class WallSensor {
 public:
  // Throws std::invalid_argument if the normal is zero or the diameter is not positive or finite.
  WallSensor(std::vector<Vec<D>> centres, const Vec<D>& normal, double diameter);

  const std::vector<Vec<D>>& centres() const { return centres_; }

  // What sample() needs of the wall, per sensor: the wall particles behind its face (and the
  // corner particles that pass their force to them) and each one's weight, the covered area over
  // its column's share. It depends only on the wall's
  // positions and volumes, so a static wall's is computed once.
  struct Coverage {
    std::vector<std::vector<std::pair<std::size_t, double>>> weights;
  };
  // From the wall particles' "position" and "volume". `depth` bounds how far behind the face a
  // particle still counts (the fluid's kernel support: deeper particles get no force, and a far
  // wall must not count). Offsets, and the separations of the particles near a face, are minimum
  // images on the domain's periodic axes. Throws std::invalid_argument where a periodic axis is
  // shorter than the face's diameter plus one particle's share (as far as the face's plane runs
  // along it): there two images of one column could both lie under the face, and a minimum image
  // would count one of them only.
  Coverage coverage(const ParticleSet<D>& wall, double depth, const Domain<D>& domain = {}) const;
  // The pressures, one per sensor (NaN where no particle covers it), from the force on each wall
  // particle.
  std::vector<double> sample(const Coverage& coverage, const std::vector<Vec<D>>& force) const;
  // Both at once, from the wall particles' "position", "volume" and `force`.
  std::vector<double> sample(const ParticleSet<D>& wall, const std::vector<Vec<D>>& force,
                             double depth, const Domain<D>& domain = {}) const;
  // The area of a particle's share (side a, centred at `offset` from the face's centre) that the
  // face covers: exact in 2D; in 3D the share of the face's quadrature points (about 800 over
  // the disc) that fall in the square, times the face's area, so that the squares of a wall
  // covering the face add up to exactly its area.
  double covered(const Vec<D>& offset, double a) const;
  double face_area() const;  // length in 2D

 private:
  struct Near {
    std::size_t w;  // the wall particle
    Vec<D> r;       // x_w - the face's centre (minimum image)
    double a;       // its side, V_w^(1/D)
  };
  // The wall particles behind sensor s's plane within the depth, and those in front of it within
  // their own side (the first layer of a wall that meets this one), near the face.
  void near_face(const ParticleSet<D>& wall, double depth, const Domain<D>& domain, std::size_t s,
                 std::vector<Near>& behind, std::vector<Near>& front) const;
  // Per particle behind the plane, the particle whose column of the face it counts in: itself
  // for a face particle, the nearest face particle for a corner particle (wall_sensor.cpp), or
  // behind.size() for none.
  std::vector<std::size_t> receivers(const std::vector<Near>& behind,
                                     const std::vector<Near>& front, double depth,
                                     const Domain<D>& domain) const;
  // Throws std::invalid_argument for a periodic axis shorter than the face and one share.
  void require_period(const ParticleSet<D>& wall, const Domain<D>& domain) const;
  // Calls f(w, covered area, share area) for every wall particle w behind sensor s's face, and
  // for each corner particle with its receiver's area and share.
  template <typename F>
  void for_each_covered(const ParticleSet<D>& wall, double depth, const Domain<D>& domain,
                        std::size_t s, const F& f) const;

  std::vector<Vec<D>> centres_;
  Vec<D> normal_;                 // unit, out of the wall
  std::vector<Vec<D>> tangents_;  // D - 1 unit vectors spanning the face's plane
  double radius_;
  std::vector<std::pair<double, double>> face_points_;  // 3D: the face's quadrature points
};

// A sensor's coverage kept while the wall's positions stay where they were: a static wall's is
// computed once, a moving wall's again whenever it has moved.
template <int D>
class CoverageCache {
 public:
  const typename WallSensor<D>::Coverage& of(const WallSensor<D>& sensor,
                                             const ParticleSet<D>& wall, double depth,
                                             const Domain<D>& domain) {
    const auto& x = wall.vector("position");
    if (!coverage_ || x != positions_) {
      coverage_ = sensor.coverage(wall, depth, domain);
      positions_ = x;
    }
    return *coverage_;
  }

 private:
  std::optional<typename WallSensor<D>::Coverage> coverage_;
  std::vector<Vec<D>> positions_;
};

extern template class WallSensor<2>;
extern template class WallSensor<3>;

}  // namespace cosph
