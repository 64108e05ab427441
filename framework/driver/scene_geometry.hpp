// Builds framework objects (shapes, bodies, domain, kernel) from their scene messages. Errors
// become ConfigErrors naming the scene key path, so the user sees the line they wrote.
#pragma once

#include <string>

#include "core/particles.hpp"
#include "geometry/lattice.hpp"
#include "geometry/particle_cloud.hpp"
#include "geometry/shapes.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/domain.hpp"
#include "scene.pb.h"

namespace cosph {

template <int D>
Vec<D> to_vec(const google::protobuf::RepeatedField<double>& values);

template <int D>
ShapePtr<D> build_shape(const proto::Shape& spec, const std::string& key_path);

// Particles of a body: its shape filled on a lattice, or its CSV point cloud.
template <int D>
ParticleCloud<D> build_body(const proto::BodySpec& spec, const std::string& key_path,
                            const std::string& scene_directory);

// Where a body's lattice puts its particles (body.placement); a point cloud has none and reads as
// cell placement (its volumes are its own).
LatticePlacement lattice_placement(const proto::BodySpec& spec);

template <int D>
Domain<D> build_domain(const proto::Scene& scene);

Kernel build_kernel(const proto::BodySpec& body, int dimension);

// Throws ConfigError at key_path if the cloud has more particles than run.max_particles or any
// position lies outside the scene's domain (when one is given).
template <int D>
void check_body_cloud(const proto::Scene& scene, const ParticleCloud<D>& cloud,
                      const std::string& key_path);

// Particles that never move (diffusion, monodomain): the body's cloud checked against the domain,
// sorted by cell once for memory locality, wrapped into periodic axes, with the fields "position"
// and "volume" registered (output) in `particles`. The placement's boundary faces, if it knows
// any, go to `faces` (indices into `particles`) when it is given, and so do its particles' cells
// (in the particles' order; left alone where the placement does not know them).
template <int D>
void build_static_body(const proto::Scene& scene, const proto::BodySpec& spec,
                       const std::string& key_path, const std::string& scene_directory,
                       const Kernel& kernel, ParticleSet<D>& particles,
                       std::vector<BoundaryFace<D>>* faces = nullptr,
                       std::vector<CellMoments<D>>* cells = nullptr);

}  // namespace cosph
