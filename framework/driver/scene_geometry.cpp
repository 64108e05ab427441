#include "driver/scene_geometry.hpp"

#include <filesystem>
#include <random>
#include <sstream>

#include "core/error.hpp"
#include "geometry/lattice.hpp"
#include "geometry/point_cloud_csv.hpp"
#include "geometry/shell_nodes.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {

template <int D>
Vec<D> to_vec(const google::protobuf::RepeatedField<double>& values) {
  Vec<D> v = Vec<D>::Zero();
  for (int a = 0; a < D && a < values.size(); ++a) v[a] = values[a];
  return v;
}

namespace {

template <int D>
ShapePtr<D> make_shape(const proto::Shape& spec, const std::string& path) {
  switch (spec.kind_case()) {
    case proto::Shape::kBox:
      return std::make_shared<Box<D>>(to_vec<D>(spec.box().lower()), to_vec<D>(spec.box().upper()));
    case proto::Shape::kEllipsoid: {
      const auto& e = spec.ellipsoid();
      if (e.has_radius() == (e.radii_size() > 0))
        throw ConfigError(path + ".ellipsoid", "give either radius (a sphere) or radii");
      const Vec<D> radii = e.has_radius() ? Vec<D>::Constant(e.radius()) : to_vec<D>(e.radii());
      return std::make_shared<Ellipsoid<D>>(to_vec<D>(e.center()), radii);
    }
    case proto::Shape::kTruncatedEllipsoidalShell:
      if constexpr (D == 3) {
        const auto& s = spec.truncated_ellipsoidal_shell();
        return std::make_shared<TruncatedEllipsoidalShell>(
            s.inner_short_radius(), s.inner_long_radius(), s.outer_short_radius(),
            s.outer_long_radius(), s.truncation());
      } else {
        throw ConfigError(path + ".truncated_ellipsoidal_shell", "is a 3D shape; the scene is 2D");
      }
    case proto::Shape::kPolygon:
      if constexpr (D == 2) {
        std::vector<Vec<2>> vertices;
        for (const auto& p : spec.polygon().vertices())
          vertices.push_back(to_vec<2>(p.coordinates()));
        return std::make_shared<Polygon>(vertices);
      } else {
        throw ConfigError(path + ".polygon", "is a 2D shape; the scene is 3D");
      }
    case proto::Shape::kUnion: {
      std::vector<ShapePtr<D>> parts;
      for (int k = 0; k < spec.union_().shapes_size(); ++k)
        parts.push_back(build_shape<D>(spec.union_().shapes(k),
                                       path + ".union.shapes[" + std::to_string(k) + "]"));
      return std::make_shared<Union<D>>(parts);
    }
    case proto::Shape::kDifference:
      return std::make_shared<Difference<D>>(
          build_shape<D>(spec.difference().base(), path + ".difference.base"),
          build_shape<D>(spec.difference().subtract(), path + ".difference.subtract"));
    case proto::Shape::KIND_NOT_SET:
      break;
  }
  throw ConfigError(path,
                    "a shape needs one of: box, ellipsoid, truncated_ellipsoidal_shell, "
                    "polygon, union, difference");
}

// The nodes of a shape's own structured grid (placement: conforming); only the truncated
// ellipsoidal shell has one.
template <int D>
ParticleCloud<D> conforming_body(const proto::BodySpec& spec, const Shape<D>& shape,
                                 const std::string& key_path) {
  if constexpr (D == 3) {
    if (const auto* shell = dynamic_cast<const TruncatedEllipsoidalShell*>(&shape)) {
      if (spec.lattice_anchor_size() > 0)
        throw ConfigError(key_path + ".lattice_anchor",
                          "a conforming placement follows the shape, not a lattice anchor");
      if (spec.perturbation() > 0.0)
        throw ConfigError(key_path + ".perturbation",
                          "a conforming placement's faces are exact; perturbation would move "
                          "its face nodes off them");
      try {
        return conforming_shell_nodes(*shell, spec.spacing());
      } catch (const std::invalid_argument& e) {
        throw ConfigError(key_path, e.what());
      }
    }
  }
  throw ConfigError(key_path + ".placement",
                    "placement conforming needs a truncated_ellipsoidal_shell shape (a box's "
                    "conforming grid is placement: vertex)");
}

}  // namespace

template <int D>
ShapePtr<D> build_shape(const proto::Shape& spec, const std::string& key_path) {
  try {
    return make_shape<D>(spec, key_path);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(key_path, e.what());
  }
}

template <int D>
ParticleCloud<D> build_body(const proto::BodySpec& spec, const std::string& key_path,
                            const std::string& scene_directory) {
  if (spec.has_shape() == spec.has_points_csv())
    throw ConfigError(key_path, "a body needs either a shape or points_csv (not both)");
  if (spec.has_points_csv()) {
    if (spec.has_placement())
      throw ConfigError(key_path + ".placement",
                        "placement applies to a lattice-filled shape; a points_csv body gives "
                        "its own volumes");
    std::filesystem::path file(spec.points_csv());
    if (file.is_relative()) file = std::filesystem::path(scene_directory) / file;
    try {
      return read_point_cloud_csv<D>(file.string());
    } catch (const RuntimeError& e) {
      throw ConfigError(key_path + ".points_csv", e.what());
    }
  }
  auto shape = build_shape<D>(spec.shape(), key_path + ".shape");
  if (lattice_placement(spec) == LatticePlacement::conforming)
    return conforming_body<D>(spec, *shape, key_path);
  ParticleCloud<D> cloud;
  try {
    cloud = lattice_fill<D>(*shape, spec.spacing(), to_vec<D>(spec.lattice_anchor()),
                            lattice_placement(spec));
  } catch (const std::invalid_argument& e) {
    throw ConfigError(key_path, e.what());
  }
  if (spec.perturbation() > 0.0) {
    // Uniform displacement in [-a, a] per axis, a = perturbation * spacing, from a fixed seed;
    // particles pushed outside the shape are kept where they were.
    std::mt19937_64 rng(spec.perturbation_seed());
    std::uniform_real_distribution<double> u(-spec.perturbation() * spec.spacing(),
                                             spec.perturbation() * spec.spacing());
    for (auto& x : cloud.positions) {
      Vec<D> moved = x;
      for (int a = 0; a < D; ++a) moved[a] += u(rng);
      if (shape->contains(moved)) x = moved;
    }
  }
  return cloud;
}

template <int D>
Domain<D> build_domain(const proto::Scene& scene) {
  Domain<D> domain;
  if (!scene.has_domain()) return domain;
  domain.lower = to_vec<D>(scene.domain().lower());
  domain.upper = to_vec<D>(scene.domain().upper());
  for (int a = 0; a < D; ++a) {
    if (!(domain.upper[a] > domain.lower[a]))
      throw ConfigError("domain.upper[" + std::to_string(a) + "]",
                        "must be greater than domain.lower");
    domain.periodic[a] = a < scene.domain().periodic_size() && scene.domain().periodic(a);
  }
  return domain;
}

LatticePlacement lattice_placement(const proto::BodySpec& spec) {
  if (spec.has_points_csv()) return LatticePlacement::cell;
  if (spec.placement() == "vertex") return LatticePlacement::vertex;
  if (spec.placement() == "conforming") return LatticePlacement::conforming;
  return LatticePlacement::cell;
}

Kernel build_kernel(const proto::BodySpec& body, int dimension) {
  const auto& k = body.kernel();
  return Kernel(kernel_type_from_name(k.type()), dimension,
                k.smoothing_length_ratio() * body.spacing());
}

template <int D>
void check_body_cloud(const proto::Scene& scene, const ParticleCloud<D>& cloud,
                      const std::string& key_path) {
  if (static_cast<double>(cloud.positions.size()) > scene.run().max_particles()) {
    std::ostringstream msg;
    msg << cloud.positions.size()
        << " particles, more than run.max_particles = " << scene.run().max_particles()
        << " (is the spacing in the geometry's unit? raise run.max_particles for a run this large)";
    throw ConfigError(key_path, msg.str());
  }
  if (!scene.has_domain()) return;
  const Domain<D> domain = build_domain<D>(scene);
  for (std::size_t i = 0; i < cloud.positions.size(); ++i) {
    const Vec<D>& x = cloud.positions[i];
    for (int a = 0; a < D; ++a)
      if (x[a] < domain.lower[a] || x[a] > domain.upper[a]) {
        std::ostringstream msg;
        msg << "particle at (" << x.transpose() << ") lies outside the domain";
        throw ConfigError(key_path, msg.str());
      }
  }
}

template <int D>
void build_static_body(const proto::Scene& scene, const proto::BodySpec& spec,
                       const std::string& key_path, const std::string& scene_directory,
                       const Kernel& kernel, ParticleSet<D>& particles,
                       std::vector<BoundaryFace<D>>* faces, std::vector<CellMoments<D>>* cells) {
  const ParticleCloud<D> cloud = build_body<D>(spec, key_path, scene_directory);
  check_body_cloud<D>(scene, cloud, key_path);
  const Domain<D> domain = build_domain<D>(scene);
  const auto order = cell_sort_order<D>(cloud.positions, kernel.support_radius(), domain);
  particles.resize(cloud.positions.size());
  auto& x = particles.add_vector("position", {.output = true});
  auto& V = particles.add_scalar("volume", {.output = true});
  for (std::size_t k = 0; k < order.size(); ++k) {
    x[k] =
        domain.any_periodic() ? domain.wrap(cloud.positions[order[k]]) : cloud.positions[order[k]];
    V[k] = cloud.volumes[order[k]];
  }
  if (cells && !cloud.cells.empty()) {
    cells->resize(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) (*cells)[k] = cloud.cells[order[k]];
  }
  if (!faces) return;
  std::vector<std::size_t> position_of(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) position_of[order[k]] = k;
  *faces = cloud.faces;
  for (auto& face : *faces)
    for (auto& i : face.particles) i = position_of[i];
}

#define COSPH_INSTANTIATE(D)                                                                \
  template Vec<D> to_vec<D>(const google::protobuf::RepeatedField<double>&);                \
  template ShapePtr<D> build_shape<D>(const proto::Shape&, const std::string&);             \
  template ParticleCloud<D> build_body<D>(const proto::BodySpec&, const std::string&,       \
                                          const std::string&);                              \
  template Domain<D> build_domain<D>(const proto::Scene&);                                  \
  template void check_body_cloud<D>(const proto::Scene&, const ParticleCloud<D>&,           \
                                    const std::string&);                                    \
  template void build_static_body<D>(const proto::Scene&, const proto::BodySpec&,           \
                                     const std::string&, const std::string&, const Kernel&, \
                                     ParticleSet<D>&, std::vector<BoundaryFace<D>>*,        \
                                     std::vector<CellMoments<D>>*);
COSPH_INSTANTIATE(2)
COSPH_INSTANTIATE(3)

}  // namespace cosph
