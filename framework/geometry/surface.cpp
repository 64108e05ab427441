#include "geometry/surface.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "core/parallel.hpp"
#include "kernels/kernel.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {

// Criterion. With the Wendland C2 kernel at h = 1.3 * spacing, particle i gets
//   g_i = sum_j V_j grad_i W_ij     and     L_i = sum_j V_j (r_j - r_i) (x) grad_i W_ij.
// In a full neighbourhood g_i = 0 (odd integrand) and L_i = I; where the support is cut by a
// free surface, g_i points into the body, so the outward direction is -g_i / |g_i|.
// 1. |g_i| h >= kGradientThreshold: the support is visibly one-sided. On a lattice-filled box the
//    outermost layer has |g| h in [0.58, 0.67] (2D and 3D, faces to corners), the second layer
//    at most 0.064 and deeper layers 0 (their support does not reach the surface), so 0.25 sits
//    in the gap with a wide margin either side.
// 2. The site one spacing outwards, r_i - spacing * g_i / |g_i|, is free: no particle lies within
//    kFreeSiteRadius * spacing of it, i.e. another particle could be placed there. In a box the
//    second layer fails it (its free site is an outer-layer particle) and the outer layer passes
//    it (nearest particle >= 1.1 spacings away even where the direction tilts near an edge). On
//    lattice-filled bodies criteria 1 and 2 each give the same set on their own; on irregular
//    clouds the gradient of interior particles is no longer zero and criterion 2 is what keeps
//    them out (a 12^D box lattice jittered by +-0.2 spacing: 14 (2D) and 34 (3D) interior
//    particles pass criterion 1, none passes both). On lattice-filled discs the result equals
//    the particles with an empty axis-neighbour site; on spheres it adds a few particles that
//    are exposed only diagonally. The inner corner of a concave notch, exposed only diagonally
//    too, is not a surface particle (its free site is 0.77 spacings from the notch's walls).
// 3. Degenerate clouds whose support is cut symmetrically (a single particle, a line or sheet
//    one particle thick) have g_i ~ 0 but an L_i that is far from I: the smallest eigenvalue is
//    below kDegenerateEigenvalue (a full neighbourhood has ~0.97, the second layer of a box
//    ~0.9). Such particles are surface particles; the normal is the eigenvector of the smallest
//    eigenvalue, whose sign cannot be inferred: it is chosen with its largest component positive.
//
// Normals. The direction from h = 1.3 * spacing follows the lattice staircase of a curved
// surface (up to 28 degrees off on tilted planes). The normal of a surface particle is therefore
// recomputed as -g/|g| with a wider kernel, h = 2.6 * spacing, which averages over more steps:
// measured worst case over random plane orientations 15 degrees (2D) and 9 degrees (3D), mean
// 2.6 and 1.6. The price is that a face's normal tilts within 5.2 spacings of its edges, and that
// a body must be about 6 spacings thick for one face not to see the other; where the wide
// normal departs by more than 45 degrees from the narrow direction (thin parts), the narrow one
// is kept.
namespace {
constexpr double kSmoothingRatio = 1.3;
constexpr double kNormalSmoothingRatio = 2.6;
constexpr double kGradientThreshold = 0.25;
constexpr double kFreeSiteRadius = 0.9;
constexpr double kDegenerateEigenvalue = 0.5;
const double kNormalAgreement = std::cos(std::numbers::pi / 4.0);

// Kernel-sum gradient of the cloud at x (particle `self`, excluded), over the cell list's
// neighbours within the kernel's support.
template <int D>
Vec<D> kernel_sum_gradient(const Kernel& kernel, const CellLinkedList<D>& cells, const Vec<D>& x,
                           Index self, const std::vector<Vec<D>>& positions,
                           const std::vector<double>& volumes) {
  Vec<D> g = Vec<D>::Zero();
  cells.for_each_neighbour(x, kernel.support_radius(), self, [&](Index j) {
    const Vec<D> d = x - positions[j];
    const double r = d.norm();
    if (r > 0.0) g += (volumes[j] * kernel.derivative(r) / r) * d;  // coincident: no direction
  });
  return g;
}
}  // namespace

template <int D>
Surface<D> detect_surface(const std::vector<Vec<D>>& positions, const std::vector<double>& volumes,
                          double spacing) {
  if (positions.size() != volumes.size()) {
    std::ostringstream s;
    s << "surface detection: " << positions.size() << " positions but " << volumes.size()
      << " volumes";
    throw std::invalid_argument(s.str());
  }
  if (!(spacing > 0.0) || !std::isfinite(spacing)) {
    std::ostringstream s;
    s << "surface detection: spacing must be positive and finite, got " << spacing;
    throw std::invalid_argument(s.str());
  }
  const double h = kSmoothingRatio * spacing;
  const Kernel kernel(KernelType::WendlandC2, D, h);
  const Kernel wide(KernelType::WendlandC2, D, kNormalSmoothingRatio * spacing);
  const Domain<D> open_domain{};  // no periodic axis: a surface is where the particles end
  // Neighbours are visited through cell lists (one per kernel, so that each scans cells of its
  // own support) rather than stored neighbour lists, which would cost ~70 (3D) indices per
  // particle for the narrow kernel and ~600 for the wide one.
  const CellLinkedList<D> cells(positions, kernel.support_radius(), open_domain);
  const CellLinkedList<D> wide_cells(positions, wide.support_radius(), open_domain);

  const std::size_t n = positions.size();
  std::vector<std::uint8_t> on_surface(n, 0);
  std::vector<std::uint8_t> degenerate(n, 0);
  std::vector<Vec<D>> normal(n, Vec<D>::Zero());
  parallel_for_each_index(n, [&](std::size_t i) {
    const Vec<D>& xi = positions[i];
    const auto self = static_cast<Index>(i);
    const Vec<D> g = kernel_sum_gradient<D>(kernel, cells, xi, self, positions, volumes);
    if (g.norm() * h >= kGradientThreshold) {
      const Vec<D> n_i = -g.normalized();
      const Vec<D> site = xi + spacing * n_i;
      bool free = true;
      cells.for_each_neighbour(site, kFreeSiteRadius * spacing, self, [&](Index) { free = false; });
      if (free) {
        on_surface[i] = 1;
        normal[i] = n_i;
        return;
      }
    }
    // Not exposed along -g: still a surface particle if its support is degenerate (criterion 3;
    // e.g. the second particle of a one-particle-thick line has a gradient along the line).
    Mat<D> L = Mat<D>::Zero();
    cells.for_each_neighbour(xi, kernel.support_radius(), self, [&](Index j) {
      const Vec<D> d = xi - positions[j];
      const double r = d.norm();
      if (r > 0.0) L -= (volumes[j] * kernel.derivative(r) / r) * d * d.transpose();
    });
    // Closed-form 2x2 / 3x3 solver: cheap, and it avoids the iterative one's
    // false maybe-uninitialized warnings with GCC 12.
    Eigen::SelfAdjointEigenSolver<Mat<D>> eigen;
    eigen.computeDirect(0.5 * (L + L.transpose()));
    if (eigen.eigenvalues()[0] < kDegenerateEigenvalue) {
      Vec<D> n_i = eigen.eigenvectors().col(0);
      Eigen::Index largest = 0;
      n_i.cwiseAbs().maxCoeff(&largest);
      if (n_i[largest] < 0.0) n_i = -n_i;
      on_surface[i] = 1;
      degenerate[i] = 1;
      normal[i] = n_i.normalized();
    }
  });

  // Wide-kernel normals, for the particles found through the gradient (not the degenerate ones).
  parallel_for_each_index(n, [&](std::size_t i) {
    if (!on_surface[i] || degenerate[i]) return;
    const Vec<D> g = kernel_sum_gradient<D>(wide, wide_cells, positions[i], static_cast<Index>(i),
                                            positions, volumes);
    const double norm = g.norm();
    if (norm == 0.0) return;
    const Vec<D> n_wide = -g / norm;
    if (n_wide.dot(normal[i]) >= kNormalAgreement) normal[i] = n_wide;
  });

  Surface<D> surface;
  for (std::size_t i = 0; i < n; ++i)
    if (on_surface[i]) {
      surface.particles.push_back(static_cast<Index>(i));
      surface.normals.push_back(normal[i]);
    }
  return surface;
}

template Surface<2> detect_surface<2>(const std::vector<Vec<2>>&, const std::vector<double>&,
                                      double);
template Surface<3> detect_surface<3>(const std::vector<Vec<3>>&, const std::vector<double>&,
                                      double);

}  // namespace cosph
