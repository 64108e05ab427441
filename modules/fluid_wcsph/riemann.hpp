// The inter-particle Riemann problem of weakly-compressible SPH (seed 003 section 2.2; Zhang, Hu
// & Adams 2017). Along the unit vector e from particle i (left) to j (right), the linearised
// (acoustic) solution for equal impedances Z = rho0 c is
//   P* = (p_L + p_R)/2 + beta Z (u_L - u_R)/2,     U* = (u_L + u_R)/2 + (p_L - p_R)/(2 Z),
// with u = v . e. beta = 1 is the plain acoustic solver; the low-dissipation limiter
// beta = min(3 max(u_L - u_R, 0) / c, 1) keeps the dissipation only where particles approach
// fast (impacts) and removes it from smooth flow. The limiter acts on the momentum equation only.
// Without momentum dissipation (beta = 0) only the pressure jump in U* dissipates, as a density
// diffusion in the continuity equation: in shear the velocity-jump term acts like an artificial
// viscosity (1.5 rho0 (u_L - u_R)^2 per approaching pair under the limiter), which confined viscous
// flows do not want.
#pragma once

#include <algorithm>

namespace cosph {

// What the velocity jump does to P*: the full acoustic dissipation, the limited one, or nothing.
enum class MomentumDissipation { acoustic, limited, none };

struct RiemannSolver {
  RiemannSolver(double impedance, double sound_speed, MomentumDissipation momentum)
      : impedance_(impedance),
        limiter_scale_(3.0 / sound_speed),
        inverse_impedance_(1.0 / impedance),
        momentum_(momentum) {}

  double pressure(double p_left, double p_right, double u_left, double u_right) const {
    const double mean = 0.5 * (p_left + p_right);
    if (momentum_ == MomentumDissipation::none) return mean;
    const double jump = u_left - u_right;
    const double beta = momentum_ == MomentumDissipation::limited
                            ? std::min(limiter_scale_ * std::max(jump, 0.0), 1.0)
                            : 1.0;
    return mean + 0.5 * beta * impedance_ * jump;
  }
  double velocity(double p_left, double p_right, double u_left, double u_right) const {
    return 0.5 * (u_left + u_right) + 0.5 * (p_left - p_right) * inverse_impedance_;
  }

 private:
  double impedance_;          // Z = rho0 c
  double limiter_scale_;      // 3 / c
  double inverse_impedance_;  // 1 / Z
  MomentumDissipation momentum_;
};

}  // namespace cosph
