#include "kernels/kernel.hpp"

#include <stdexcept>

namespace cosph {

KernelType kernel_type_from_name(const std::string& name) {
  if (name == "wendland_c2" || name == "quintic_wendland") return KernelType::WendlandC2;
  if (name == "wendland_c4") return KernelType::WendlandC4;
  if (name == "cubic_spline") return KernelType::CubicSpline;
  throw std::invalid_argument("unknown kernel '" + name +
                              "' (expected wendland_c2, quintic_wendland, wendland_c4 or "
                              "cubic_spline)");
}

std::string kernel_name(KernelType type) {
  switch (type) {
    case KernelType::WendlandC2:
      return "wendland_c2";
    case KernelType::WendlandC4:
      return "wendland_c4";
    case KernelType::CubicSpline:
      return "cubic_spline";
  }
  return "unknown";
}

Kernel::Kernel(KernelType type, int dimension, double smoothing_length)
    : type_(type), dimension_(dimension), h_(smoothing_length), inv_h_(1.0 / smoothing_length) {
  if (dimension != 2 && dimension != 3)
    throw std::invalid_argument("kernel dimension must be 2 or 3");
  if (!(smoothing_length > 0.0)) throw std::invalid_argument("smoothing length must be positive");
  const double pi = std::numbers::pi;
  // Normalisation constants: the integral of the dimensionless profile over the support, in
  // units of h^D (Dehnen & Aly 2012, table 1, rescaled to support 2h). Tested by quadrature.
  double c = 0.0;
  switch (type) {
    case KernelType::WendlandC2:
      c = dimension == 2 ? 7.0 / (4.0 * pi) : 21.0 / (16.0 * pi);
      break;
    case KernelType::WendlandC4:
      c = dimension == 2 ? 9.0 / (4.0 * pi) : 495.0 / (256.0 * pi);
      break;
    case KernelType::CubicSpline:
      c = dimension == 2 ? 10.0 / (7.0 * pi) : 1.0 / pi;
      break;
  }
  norm_ = c * std::pow(inv_h_, dimension);
}

}  // namespace cosph
