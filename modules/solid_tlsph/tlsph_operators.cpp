#include "solid_tlsph/tlsph_operators.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <string>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "kernels/kernel_correction.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {

namespace {

// The quadratic correction at one particle: g_ij = omega_ij [I 0] M^-1 p(s_ij) / h with the
// scaled offsets s = X_ij / h, the basis p(s) = (s, s_a s_b for a <= b) and the moment matrix
// M = sum_j omega_ij p p^T. Returns false (and leaves g alone) when M cannot be inverted
// reliably or the fit would stiffen the operator too much: then the linear correction stays.
template <int D>
bool quadratic_gradients(const std::vector<Vec<D>>& X, const NeighbourList& nl,
                         const std::vector<double>& omega, double h, std::size_t i,
                         std::vector<Vec<D>>& g, std::vector<Mat<D>>* curvature) {
  constexpr int m = D + D * (D + 1) / 2;
  using Basis = Eigen::Matrix<double, m, 1>;
  auto basis = [&](const Vec<D>& X_ij) {
    const Vec<D> s = X_ij / h;
    Basis p;
    int row = D;
    for (int a = 0; a < D; ++a) {
      p[a] = s[a];
      for (int b = a; b < D; ++b) p[row++] = s[a] * s[b];
    }
    return p;
  };
  Eigen::Matrix<double, m, m> M = Eigen::Matrix<double, m, m>::Zero();
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
    const Basis p = basis(X[nl.index[k]] - X[i]);
    M.noalias() += omega[k] * p * p.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, m, m>> eigen(M);
  const auto& lambda = eigen.eigenvalues();  // ascending
  // A neighbourhood that spans fewer than three layers along some direction makes M singular
  // (its quadratic in that direction equals its linear term); nearly so, the fit would amplify
  // round-off into the stresses.
  if (!(lambda[0] > 1e-6 * lambda[m - 1])) return false;
  const Eigen::Matrix<double, m, m> inverse =
      eigen.eigenvectors() * lambda.cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose();
  // The stable step goes as 1 / |g|: keep the fit only where it amplifies sum_j |g_ij|^2 at
  // most kMaxAmplification times over the linear correction's (still in g). On a lattice at
  // h = 1.3 dp a surface particle's fit amplifies it 4.5 times in 2D (up to 5.2 with the
  // positions jittered by 0.15 dp) and a face particle's 3.7 in 3D; edges (3D) 6.2-6.4, corners
  // 6.9 (2D) and 8.4 (3D). Edges and corners keep the linear correction: the rubber gate's stable
  // step grows by a fifth, its swing and the oscillating plate's period stay (docs/ARCHITECTURE).
  constexpr double kMaxAmplification = 6.0;
  const std::size_t begin = nl.offset[i], count = nl.offset[i + 1] - begin;
  std::vector<Vec<D>> fitted(count);
  std::vector<Mat<D>> second(curvature ? count : 0);
  double linear = 0.0, quadratic = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const Basis c = inverse * basis(X[nl.index[begin + k]] - X[i]);
    fitted[k] = (omega[begin + k] / h) * c.template head<D>();
    linear += g[begin + k].squaredNorm();
    quadratic += fitted[k].squaredNorm();
    if (!curvature) continue;
    // The fit's term for s_a s_b is (1/2) H_ab h^2 on the diagonal and H_ab h^2 off it.
    const double scale = omega[begin + k] / (h * h);
    int row = D;
    for (int a = 0; a < D; ++a)
      for (int b = a; b < D; ++b, ++row) {
        const double value = scale * c[row] * (a == b ? 2.0 : 1.0);
        second[k](a, b) = second[k](b, a) = value;
      }
  }
  if (!(quadratic <= kMaxAmplification * linear)) return false;
  std::copy(fitted.begin(), fitted.end(), g.begin() + static_cast<std::ptrdiff_t>(begin));
  if (curvature)
    std::copy(second.begin(), second.end(),
              curvature->begin() + static_cast<std::ptrdiff_t>(begin));
  return true;
}

// Per pair (i, j) the index of the pair (j, i). Reference neighbour lists are symmetric (j sees i
// whenever i sees j); a list that is not is refused, naming the particle.
std::vector<std::size_t> reverse_pairs(const NeighbourList& nl) {
  std::vector<std::size_t> reverse(nl.pair_count());
  parallel_for_each_index(nl.particle_count(), [&](std::size_t i) {
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
      const Index j = nl.index[k];
      std::size_t back = nl.offset[j];
      while (back < nl.offset[j + 1] && nl.index[back] != Index(i)) ++back;
      if (back == nl.offset[j + 1])
        throw RuntimeError("reference neighbour list is not symmetric at particle " +
                           std::to_string(i));
      reverse[k] = back;
    }
  });
  return reverse;
}

// b_ij = -(V_j / V_i) g_ji, through the reverse pair.
template <int D>
void reverse_gradients(const NeighbourList& nl, const std::vector<double>& volume,
                       ReferencePairs<D>& pairs) {
  pairs.reverse.resize(nl.pair_count());
  pairs.curvature_reverse.resize(pairs.curvature.size());
  parallel_for_each_index(volume.size(), [&](std::size_t i) {
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
      const Index j = nl.index[k];
      pairs.reverse[k] = -(volume[j] / volume[i]) * pairs.gradient[pairs.reverse_pair[k]];
      if (!pairs.curvature.empty())
        pairs.curvature_reverse[k] =
            -(volume[j] / volume[i]) * pairs.curvature[pairs.reverse_pair[k]];
    }
  });
}

}  // namespace

template <int D>
ReferencePairs<D> build_reference_pairs(const std::vector<Vec<D>>& X,
                                        const std::vector<double>& volume, const Kernel& kernel,
                                        GradientCorrection correction, bool hourglass,
                                        bool curvature) {
  ReferencePairs<D> pairs;
  const Domain<D> free_space;  // a solid body is never periodic
  pairs.neighbours = build_inner_list<D>(X, kernel.support_radius(), free_space);
  std::vector<Mat<D>> B;
  compute_correction_matrices<D>(X, volume, pairs.neighbours, kernel, free_space, B);
  const auto& nl = pairs.neighbours;
  const double h = kernel.smoothing_length();
  pairs.gradient.resize(nl.pair_count());
  pairs.gradient_sum.resize(X.size());
  std::vector<double> omega(nl.pair_count());
  if (hourglass) pairs.hourglass_weight.resize(nl.pair_count());
  std::vector<char> quadratic(X.size(), 0);
  if (curvature) {
    pairs.curvature.assign(nl.pair_count(), Mat<D>::Zero());
    pairs.curvature_sum.assign(X.size(), Mat<D>::Zero());
  }
  parallel_for_each_index(X.size(), [&](std::size_t i) {
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
      const Index j = nl.index[k];
      const double distance = (X[i] - X[j]).norm();
      // w_ij = V_j W'(r) (X_i - X_j) / r = omega_ij X_ij with omega_ij = -V_j W'(r) / r >= 0.
      omega[k] = -volume[j] * kernel.derivative(distance) / distance;
      pairs.gradient[k] = B[i].transpose() * (omega[k] * (X[j] - X[i]));
      if (hourglass)
        pairs.hourglass_weight[k] = volume[j] * kernel.value(distance) / (distance * distance);
    }
    if (correction == GradientCorrection::quadratic)
      quadratic[i] = quadratic_gradients<D>(X, nl, omega, h, i, pairs.gradient,
                                            curvature ? &pairs.curvature : nullptr);
    Vec<D> sum = Vec<D>::Zero();
    for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) sum += pairs.gradient[k];
    pairs.gradient_sum[i] = sum;
    if (curvature) {
      Mat<D> second = Mat<D>::Zero();
      for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) second += pairs.curvature[k];
      pairs.curvature_sum[i] = second;
    }
  });
  pairs.quadratic = std::move(quadratic);
  pairs.reverse_pair = reverse_pairs(nl);
  reverse_gradients<D>(nl, volume, pairs);
  return pairs;
}

template <int D>
void deformation_gradients(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& u,
                           std::vector<Mat<D>>& F) {
  parallel_for_each_index(u.size(),
                          [&](std::size_t i) { F[i] = deformation_gradient<D>(pairs, u, i); });
}

template <int D>
Vec<D> artificial_viscosity(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& x,
                            const std::vector<Vec<D>>& v, const std::vector<double>& density,
                            const std::vector<Mat<D>>& A, const ViscosityParameters& p,
                            std::size_t i) {
  const auto& nl = pairs.neighbours;
  const double h = p.smoothing_length;
  // A_i is common to the pairs of i: sum q_ij g_ij first, one product with A_i at the end.
  Vec<D> own = Vec<D>::Zero(), others = Vec<D>::Zero();
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
    const Index j = nl.index[k];
    const Vec<D> r = x[i] - x[j];
    const double phi = h * (v[i] - v[j]).dot(r) / (r.squaredNorm() + 0.01 * h * h);
    if (phi >= 0.0) continue;
    const double q =
        0.25 * (density[i] + density[j]) * (-p.alpha * p.sound_speed * phi + p.beta * phi * phi);
    own.noalias() += q * pairs.gradient[k];
    others.noalias() += q * (A[j] * pairs.reverse[k]);
  }
  return -(A[i] * own + others);
}

template <int D>
Vec<D> hourglass_force(const ReferencePairs<D>& pairs, const std::vector<Vec<D>>& X,
                       const std::vector<Vec<D>>& x, const std::vector<Mat<D>>& F, double stiffness,
                       std::size_t i) {
  const auto& nl = pairs.neighbours;
  Vec<D> sum = Vec<D>::Zero();
  for (std::size_t k = nl.offset[i]; k < nl.offset[i + 1]; ++k) {
    const Index j = nl.index[k];
    const Vec<D> X_ij = X[j] - X[i];
    const Vec<D> x_ij = x[j] - x[i];
    const double length = x_ij.norm();
    if (!(length > 0.0)) continue;
    const Vec<D> e = x_ij / length;
    // eps from i: F_i X_ij - x_ij; from j (X_ji = -X_ij, x_ji = -x_ij): -(F_j X_ij - x_ij),
    // projected on x_ji = -x_ij: the same sign convention, so both add.
    const double delta = (F[i] * X_ij - x_ij).dot(e) + (F[j] * X_ij - x_ij).dot(e);
    sum.noalias() -= (0.5 * stiffness * pairs.hourglass_weight[k] * delta) * e;
  }
  return sum;
}

#define COSPH_INSTANTIATE_TLSPH(D)                                                                \
  template ReferencePairs<D> build_reference_pairs<D>(const std::vector<Vec<D>>&,                 \
                                                      const std::vector<double>&, const Kernel&,  \
                                                      GradientCorrection, bool, bool);            \
  template void deformation_gradients<D>(const ReferencePairs<D>&, const std::vector<Vec<D>>&,    \
                                         std::vector<Mat<D>>&);                                   \
  template Vec<D> artificial_viscosity<D>(const ReferencePairs<D>&, const std::vector<Vec<D>>&,   \
                                          const std::vector<Vec<D>>&, const std::vector<double>&, \
                                          const std::vector<Mat<D>>&, const ViscosityParameters&, \
                                          std::size_t);                                           \
  template Vec<D> hourglass_force<D>(const ReferencePairs<D>&, const std::vector<Vec<D>>&,        \
                                     const std::vector<Vec<D>>&, const std::vector<Mat<D>>&,      \
                                     double, std::size_t);
COSPH_INSTANTIATE_TLSPH(2)
COSPH_INSTANTIATE_TLSPH(3)

}  // namespace cosph
