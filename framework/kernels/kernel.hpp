// Smoothing kernels W(r, h) with compact support kappa*h, normalised so that their integral over
// the plane (D = 2) or space (D = 3) is 1. Value and radial derivative dW/dr are inline: pair
// loops call them without a virtual call; the kernel type is a switch that branch prediction
// makes free.
#pragma once

#include <cmath>
#include <numbers>
#include <string>

namespace cosph {

enum class KernelType {
  WendlandC2,   // (1-q/2)^4 (2q+1): the "quintic Wendland" of DualSPHysics; C2 continuous
  WendlandC4,   // (1-q/2)^6 (35/12 q^2 + 3q + 1); C4, smoother, more neighbours per support
  CubicSpline,  // Monaghan & Lattanzio (1985) M4 B-spline
};

KernelType kernel_type_from_name(const std::string& name);  // throws std::invalid_argument
std::string kernel_name(KernelType type);

class Kernel {
 public:
  Kernel(KernelType type, int dimension, double smoothing_length);

  KernelType type() const { return type_; }
  int dimension() const { return dimension_; }
  double smoothing_length() const { return h_; }
  // All three kernels vanish for r >= 2h.
  double support_radius() const { return 2.0 * h_; }

  double value(double r) const {
    const double q = r * inv_h_;
    if (q >= 2.0) return 0.0;
    switch (type_) {
      case KernelType::WendlandC2: {
        const double a = 1.0 - 0.5 * q;
        const double a2 = a * a;
        return norm_ * a2 * a2 * (2.0 * q + 1.0);
      }
      case KernelType::WendlandC4: {
        const double a = 1.0 - 0.5 * q;
        const double a2 = a * a;
        return norm_ * a2 * a2 * a2 * (35.0 / 12.0 * q * q + 3.0 * q + 1.0);
      }
      case KernelType::CubicSpline:
        if (q < 1.0) return norm_ * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
        return norm_ * 0.25 * (2.0 - q) * (2.0 - q) * (2.0 - q);
    }
    return 0.0;
  }

  // dW/dr (<= 0): the gradient is dW/dr * (r_i - r_j)/|r_i - r_j|.
  double derivative(double r) const {
    const double q = r * inv_h_;
    if (q >= 2.0) return 0.0;
    switch (type_) {
      case KernelType::WendlandC2: {
        // d/dq [(1-q/2)^4 (2q+1)] = -5 q (1-q/2)^3
        const double a = 1.0 - 0.5 * q;
        return norm_ * inv_h_ * (-5.0 * q * a * a * a);
      }
      case KernelType::WendlandC4: {
        // d/dq [(1-q/2)^6 (35/12 q^2 + 3q + 1)] = -(14/3) q (1-q/2)^5 (5q/2 + 1)
        const double a = 1.0 - 0.5 * q;
        const double a5 = a * a * a * a * a;
        return norm_ * inv_h_ * (-(14.0 / 3.0) * q * a5 * (2.5 * q + 1.0));
      }
      case KernelType::CubicSpline:
        if (q < 1.0) return norm_ * inv_h_ * (-3.0 * q + 2.25 * q * q);
        return norm_ * inv_h_ * (-0.75 * (2.0 - q) * (2.0 - q));
    }
    return 0.0;
  }

 private:
  KernelType type_;
  int dimension_;
  double h_;
  double inv_h_;
  double norm_;  // dimensional normalisation constant, includes h^-D
};

}  // namespace cosph
