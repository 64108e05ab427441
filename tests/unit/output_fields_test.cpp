// The values of derived output fields against closed forms: the fluid's vorticity of a rigid
// rotation and of a shear flow (2D scalar, 3D vector), the solid's von Mises stress, J and fibre
// strains under a uniform stretch (plane strain in 2D: the out-of-plane stress counts), and the
// monodomain's millivolt output.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>
#include <vector>

#include "../support/simulation_setup.hpp"

namespace cosph {
namespace {

using test::make_simulation;
using test::particles_of;

// ---- Vorticity -----------------------------------------------------------------------------
// A block of fluid at rest in pressure but moving with a linear velocity field; the output is
// computed from the initial state. The corrected velocity gradient is exact for linear fields
// (to round-off; the uncorrected one read the rotation's 3 as 2.92 and with the wrong sign).
// Every particle is checked, the surface and corner ones (half a support missing) included.
template <int D>
std::string fluid_block(const std::string& velocity) {
  const std::string upper = D == 2 ? "[1, 1]" : "[1, 1, 1]";
  return std::string("dimension: ") + (D == 2 ? "2" : "3") + R"(
end_time: 1
modules:
  - name: water
    fluid:
      body: {spacing: 0.05, shape: {box: {lower: )" +
         (D == 2 ? "[0, 0]" : "[0, 0, 0]") + ", upper: " + upper + R"(}}}
      density: 1000
      max_velocity: 1
      initial_velocity: )" +
         velocity + R"(
      outputs: [vorticity]
)";
}

TEST(OutputFields, VorticityOfARigidRotationAndAShear2D) {
  // v = Omega (-(y - 0.5), x - 0.5): omega = 2 Omega = 3; v = (a y, 0): omega = -a = -2.
  for (const auto& [velocity, expected] : std::vector<std::pair<std::string, double>>{
           {R"v(["-1.5 * (y - 0.5)", "1.5 * (x - 0.5)"])v", 3.0}, {R"v(["2 * y", "0"])v", -2.0}}) {
    auto simulation = make_simulation(fluid_block<2>(velocity));
    simulation->module(0).prepare_output();
    const auto& p = particles_of<2>(*simulation);
    const auto& w = p.scalar("vorticity");
    int checked = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
      EXPECT_NEAR(w[i], expected, 1e-10 * std::abs(expected)) << velocity << " particle " << i;
      ++checked;
    }
    EXPECT_EQ(checked, 400);
  }
}

TEST(OutputFields, VorticityIsTheCurlIn3D) {
  // v = (0.5 z, 1.5 x, -y): curl = (dvz/dy - dvy/dz, dvx/dz - dvz/dx, dvy/dx - dvx/dy)
  //   = (-1, 0.5, 1.5).
  auto simulation = make_simulation(fluid_block<3>(R"v(["0.5 * z", "1.5 * x", "-y"])v"));
  simulation->module(0).prepare_output();
  const auto& p = particles_of<3>(*simulation);
  const auto& w = p.vector("vorticity");
  const Vec<3> expected(-1.0, 0.5, 1.5);
  int checked = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_LT((w[i] - expected).norm(), 1e-10 * expected.norm()) << "particle " << i;
    ++checked;
  }
  EXPECT_EQ(checked, 8000);
}

// ---- Solid: von Mises, J, fibre strain under a uniform stretch -------------------------------
// Every particle's displacement is prescribed as u = (0.02 x, -0.01 y): after one step F is
// uniform (the linear correction is exact for it), F = diag(1.02, 0.99).
const char* const kStretched = R"yaml(
dimension: 2
end_time: 1
modules:
  - name: sheet
    solid:
      body: {spacing: 0.05, shape: {box: {lower: [0, 0], upper: [1, 0.5]}}}
      material: {density: 1000, neo_hookean: {young: 1.0e6, poisson: 0.4}}
      fibres: {fibre: [0.6, 0.8], sheet: [-0.8, 0.6]}
      constraints:
        - region: {name: all, shape: {box: {lower: [-1, -1], upper: [2, 2]}}}
          displacement: {values: ["0.02 * x", "-0.01 * y"]}
      outputs: [von_mises, fibre_strain, stress]
)yaml";

TEST(OutputFields, SolidVonMisesJAndFibreStrainOfAUniformStretch) {
  auto simulation = make_simulation(kStretched);
  simulation->module(0).advance(simulation->module(0).max_dt());
  simulation->module(0).prepare_output();
  const auto& p = particles_of<2>(*simulation);

  // Plane strain: F3 = diag(1.02, 0.99, 1), neo-Hookean sigma = (mu (B - I) + lambda ln J I) / J.
  const double E = 1.0e6, nu = 0.4;
  const double mu = E / (2 * (1 + nu)), lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  const double J = 1.02 * 0.99, lnJ = std::log(J);
  const double sxx = (mu * (1.02 * 1.02 - 1) + lambda * lnJ) / J;
  const double syy = (mu * (0.99 * 0.99 - 1) + lambda * lnJ) / J;
  const double szz = lambda * lnJ / J;  // the out-of-plane stress that holds F_zz = 1
  const double mean = (sxx + syy + szz) / 3;
  const double von_mises =
      std::sqrt(1.5 * ((sxx - mean) * (sxx - mean) + (syy - mean) * (syy - mean) +
                       (szz - mean) * (szz - mean)));
  // Green strain E = (F^T F - I) / 2 = diag(0.0202, -0.00995); along f = (0.6, 0.8) and
  // s = (-0.8, 0.6): E_ff = 0.36 E_xx + 0.64 E_yy, E_ss = 0.64 E_xx + 0.36 E_yy.
  const double Exx = 0.5 * (1.02 * 1.02 - 1), Eyy = 0.5 * (0.99 * 0.99 - 1);
  const double Eff = 0.36 * Exx + 0.64 * Eyy, Ess = 0.64 * Exx + 0.36 * Eyy;
  for (std::size_t i = 0; i < p.size(); ++i) {
    ASSERT_NEAR(p.scalar("J")[i], J, 1e-12) << i;
    ASSERT_NEAR(p.scalar("von_mises")[i], von_mises, 1e-9 * von_mises) << i;
    ASSERT_NEAR(p.matrix("stress")[i](0, 0), sxx, 1e-9 * std::abs(sxx)) << i;
    ASSERT_NEAR(p.matrix("stress")[i](1, 1), syy, 1e-9 * std::abs(syy)) << i;
    ASSERT_NEAR(p.vector("fibre_strain")[i][0], Eff, 1e-12) << i;
    ASSERT_NEAR(p.vector("fibre_strain")[i][1], Ess, 1e-12) << i;
  }
  std::cout << "von Mises " << von_mises << " Pa (without the plane-strain sigma_zz it would be "
            << std::sqrt(sxx * sxx - sxx * syy + syy * syy) << ")\n";
}

// ---- Monodomain: output in millivolts --------------------------------------------------------
TEST(OutputFields, MonodomainMillivoltsAreTheAlievPanfilovScaling) {
  auto simulation = make_simulation(R"yaml(
dimension: 2
end_time: 1
modules:
  - name: tissue
    monodomain:
      body: {spacing: 0.1, shape: {box: {lower: [0, 0], upper: [1, 1]}}}
      diffusivity: 1.0e-3
      ionic_model: {preset: aliev_panfilov_table1}
      initial_voltage: "x * y"
      output_millivolts: true
)yaml");
  simulation->module(0).advance(simulation->module(0).max_dt());
  simulation->module(0).prepare_output();
  const auto& p = particles_of<2>(*simulation);
  const auto& V = p.scalar("voltage");
  ASSERT_TRUE(p.has("voltage_mV"));
  for (std::size_t i = 0; i < p.size(); ++i)
    ASSERT_DOUBLE_EQ(p.scalar("voltage_mV")[i], 100.0 * V[i] - 80.0) << i;
}

}  // namespace
}  // namespace cosph
