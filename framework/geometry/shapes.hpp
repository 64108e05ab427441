// Solid shapes that bodies are cut from: a shape answers "is this point inside?" and gives an
// axis-aligned bounding box, which is all lattice filling and region selection need. Primitives
// are closed sets (points on the boundary are inside); CSG combines shapes by reference so that
// a scene can reuse one shape in several places.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "core/types.hpp"

namespace cosph {

// contains() is called concurrently from several threads (lattice filling, region selection):
// implementations must not modify state.
template <int D>
class Shape {
 public:
  virtual ~Shape() = default;
  virtual bool contains(const Vec<D>& x) const = 0;
  // Axis-aligned bounding box (lower, upper) enclosing every point the shape contains.
  virtual std::pair<Vec<D>, Vec<D>> bounds() const = 0;
};

template <int D>
using ShapePtr = std::shared_ptr<const Shape<D>>;

// lower <= x <= upper on every axis. Requires upper > lower on every axis.
template <int D>
class Box final : public Shape<D> {
 public:
  Box(const Vec<D>& lower, const Vec<D>& upper);
  bool contains(const Vec<D>& x) const override;
  std::pair<Vec<D>, Vec<D>> bounds() const override { return {lower_, upper_}; }
  const Vec<D>& lower() const { return lower_; }
  const Vec<D>& upper() const { return upper_; }

 private:
  Vec<D> lower_, upper_;
};

// sum_a ((x_a - c_a) / r_a)^2 <= 1, axis-aligned; a sphere (circle) has equal radii.
template <int D>
class Ellipsoid final : public Shape<D> {
 public:
  Ellipsoid(const Vec<D>& center, const Vec<D>& radii);
  bool contains(const Vec<D>& x) const override;
  std::pair<Vec<D>, Vec<D>> bounds() const override;
  const Vec<D>& center() const { return center_; }
  const Vec<D>& radii() const { return radii_; }

 private:
  Vec<D> center_, radii_;
};

// The idealised left ventricle of Land et al. (2015, Proc. R. Soc. A 471:20150641): the region
// between two prolate spheroids centred at the origin with the long axis along z,
//   (x^2 + y^2) / rs_in^2 + z^2 / rl_in^2 >= 1  and  (x^2 + y^2) / rs_out^2 + z^2 / rl_out^2 <= 1,
// cut by the base plane z <= z_truncation (benchmark: 7, 17, 10, 20, 5 mm). Requires positive
// radii, the inner ellipsoid strictly inside the outer one, and -rl_out < z_truncation.
class TruncatedEllipsoidalShell final : public Shape<3> {
 public:
  TruncatedEllipsoidalShell(double inner_short, double inner_long, double outer_short,
                            double outer_long, double z_truncation);
  bool contains(const Vec<3>& x) const override;
  std::pair<Vec<3>, Vec<3>> bounds() const override;

  double inner_short() const { return inner_short_; }
  double inner_long() const { return inner_long_; }
  double outer_short() const { return outer_short_; }
  double outer_long() const { return outer_long_; }
  double z_truncation() const { return z_truncation_; }

 private:
  double inner_short_, inner_long_, outer_short_, outer_long_, z_truncation_;
};

// A simple (non-self-intersecting) polygon given by its vertices in either orientation; the last
// vertex connects back to the first. Requires at least 3 finite vertices, non-zero area and no
// crossing edges (checked in O(n^2), fine for hand-written or traced outlines).
class Polygon final : public Shape<2> {
 public:
  explicit Polygon(std::vector<Vec<2>> vertices);
  bool contains(const Vec<2>& x) const override;
  std::pair<Vec<2>, Vec<2>> bounds() const override { return {lower_, upper_}; }
  const std::vector<Vec<2>>& vertices() const { return vertices_; }

 private:
  std::vector<Vec<2>> vertices_;
  Vec<2> lower_, upper_;
};

// Points inside any of the parts. Requires at least one part and no null part.
template <int D>
class Union final : public Shape<D> {
 public:
  explicit Union(std::vector<ShapePtr<D>> parts);
  bool contains(const Vec<D>& x) const override;
  std::pair<Vec<D>, Vec<D>> bounds() const override { return {lower_, upper_}; }

 private:
  std::vector<ShapePtr<D>> parts_;
  Vec<D> lower_, upper_;
};

// Points inside a and not inside b. The bounding box is a's (b only removes points).
template <int D>
class Difference final : public Shape<D> {
 public:
  Difference(ShapePtr<D> a, ShapePtr<D> b);
  bool contains(const Vec<D>& x) const override;
  std::pair<Vec<D>, Vec<D>> bounds() const override { return a_->bounds(); }

 private:
  ShapePtr<D> a_, b_;
};

extern template class Box<2>;
extern template class Box<3>;
extern template class Ellipsoid<2>;
extern template class Ellipsoid<3>;
extern template class Union<2>;
extern template class Union<3>;
extern template class Difference<2>;
extern template class Difference<3>;

}  // namespace cosph
