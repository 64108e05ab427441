// The fluid's contact interface, through which a coupler shows it another body's particles
// (`contact`) and takes back the fluid's force on them (`contact_force`): a tank handed in as
// contact particles behaves bit for bit as the same tank given as walls, the contact force
// averaged over a step's sub-steps is the walls' force output, the one-sided state extends the
// pressure with the boundary's acceleration, and malformed port data is refused with a message
// naming the port and the field.
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "driver/registry.hpp"
#include "fluid_wcsph/boundary_set.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace cosph {
namespace {

const char* kWater = R"yaml(
dimension: 2
end_time: 1.0
domain: {lower: [-0.2, -0.2], upper: [1.2, 1.4]}
modules:
  - name: water
    fluid:
      body: {spacing: 0.05, shape: {box: {lower: [0, 0], upper: [1, 0.6]}}}
      density: 1000
      max_velocity: 4.43
      gravity: [0, -9.81]
      viscosity: 1
      initial_velocity: ["0.3 * sin(3 * x)", "0"]
)yaml";

const char* kTankWalls = R"yaml(
      outputs: [wall_force]
      walls:
        - name: tank
          shape:
            difference:
              base: {box: {lower: [-0.15, -0.15], upper: [1.15, 1.3]}}
              subtract: {box: {lower: [0, 0], upper: [1, 1.3]}}
)yaml";

struct Built {
  LoadedScene scene;
  std::unique_ptr<Module> module;
};

Built build(const std::string& text) {
  Built b{load_scene_text(text, "contact.yaml"), nullptr};
  const ModuleContext context{&b.scene.scene, "modules[0]", "."};
  b.module = builtin_modules().create("fluid", b.scene.scene.modules(0), context);
  b.module->initialize();
  return b;
}

const ParticleSet<2>& body(const Module& m, std::size_t k) {
  BodyViews views;
  m.bodies(views);
  return *views.bodies2.at(k).particles;
}

FieldBuffer contact_of(const ParticleSet<2>& walls) {
  FieldBuffer in;
  in.points = walls.size();
  auto& x = in.arrays["position"];
  auto& v = in.arrays["velocity"];
  auto& V = in.arrays["volume"];
  x.components = v.components = 2;
  for (std::size_t i = 0; i < walls.size(); ++i) {
    for (int c = 0; c < 2; ++c) {
      x.values.push_back(walls.vector("position")[i][c]);
      v.values.push_back(0.0);
    }
    V.values.push_back(walls.scalar("volume")[i]);
  }
  return in;
}

TEST(FluidContact, TankAsContactParticlesIsBitIdenticalToTankAsWalls) {
  Built walls = build(std::string(kWater) + kTankWalls);
  Built contact = build(kWater);
  contact.module->read("contact", contact_of(body(*walls.module, 1)));
  // The contact body's force over the last step's sub-steps, as a coupler receives it; the
  // walls' output is its mean over that step.
  std::vector<double> impulse;
  double covered = 0.0;
  int substeps = 0;
  for (int step = 0; step < 40; ++step) {
    const double dt = walls.module->max_dt();
    ASSERT_EQ(dt, contact.module->max_dt()) << "step " << step;
    walls.module->advance(dt);
    contact.module->begin_step(dt);  // advance_in_substeps, with the force read at each sub-step
    impulse.clear(), covered = 0.0, substeps = 0;
    for (double h = contact.module->max_substep(); h > 0.0; h = contact.module->max_substep()) {
      contact.module->substep(h);
      FieldBuffer force;
      contact.module->write("contact_force", force);
      const auto& f = force.arrays.at("force").values;
      impulse.resize(f.size(), 0.0);
      for (std::size_t k = 0; k < f.size(); ++k) impulse[k] += h * f[k];
      covered += h, ++substeps;
    }
    contact.module->end_step();
  }
  const auto& a = body(*walls.module, 0);
  const auto& b = body(*contact.module, 0);
  ASSERT_EQ(a.size(), b.size());
  double moved = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 2; ++c) {
      ASSERT_EQ(a.vector("position")[i][c], b.vector("position")[i][c]) << "particle " << i;
      ASSERT_EQ(a.vector("velocity")[i][c], b.vector("velocity")[i][c]) << "particle " << i;
      moved = std::max(moved, std::abs(a.vector("velocity")[i][c]));
    }
  EXPECT_GT(moved, 0.01);  // the water sloshes: the comparison has something to compare

  walls.module->prepare_output();
  const auto& wall_force = body(*walls.module, 1).vector("force");
  ASSERT_EQ(impulse.size(), 2 * wall_force.size());
  EXPECT_GT(substeps, 1);  // a mean over several sub-steps, not one sub-step's force
  double total = 0.0;
  for (std::size_t i = 0; i < wall_force.size(); ++i)
    for (int c = 0; c < 2; ++c) {
      const double mean = impulse[i * 2 + c] / covered;
      ASSERT_NEAR(mean, wall_force[i][c], 1e-12 * (1.0 + std::abs(mean))) << "point " << i;
      total += std::abs(wall_force[i][c]);
    }
  EXPECT_GT(total, 1000.0);  // it carries the water's weight (5,886 N/m)
}

TEST(FluidContact, OneSidedStateMirrorsVelocityAndExtendsPressureWithTheAcceleration) {
  const Vec<2> v_i(1.0, 2.0), v_w(0.5, -1.0), g(0.0, -9.81), r(0.0, -0.1);
  for (bool clamped : {false, true}) {
    const auto still = one_sided_state<2>(100.0, 1000.0, v_i, v_w, g, r, clamped);
    EXPECT_DOUBLE_EQ(still.pressure, 100.0 + 1000.0 * 9.81 * 0.1);  // hydrostatic below i
    EXPECT_EQ(still.velocity, Vec<2>(0.0, -4.0));                   // 2 v_w - v_i
    // A boundary falling freely (a_w = g) carries no hydrostatic pressure difference.
    const auto falling = one_sided_state<2>(100.0, 1000.0, v_i, v_w, Vec<2>(g - g), r, clamped);
    EXPECT_DOUBLE_EQ(falling.pressure, 100.0);
  }
  // A wall above i: hydrostatically lower, unless the extension is clamped at zero.
  const Vec<2> above(0.0, 0.1);
  EXPECT_DOUBLE_EQ(one_sided_state<2>(100.0, 1000.0, v_i, v_w, g, above, false).pressure,
                   100.0 - 1000.0 * 9.81 * 0.1);
  EXPECT_DOUBLE_EQ(one_sided_state<2>(100.0, 1000.0, v_i, v_w, g, above, true).pressure, 100.0);
}

TEST(FluidContact, MalformedPortDataIsRefused) {
  Built water = build(kWater);
  auto message = [&](const FieldBuffer& in, const std::string& port = "contact") {
    try {
      water.module->read(port, in);
    } catch (const RuntimeError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  FieldBuffer in;
  in.points = 2;
  in.arrays["position"] = {2, {0.1, 0.1, 0.2, 0.1}};
  in.arrays["velocity"] = {2, {0, 0, 0, 0}};
  EXPECT_NE(message(in).find("needs 'volume'"), std::string::npos) << message(in);
  in.arrays["volume"] = {1, {0.0025}};
  EXPECT_NE(message(in).find("'volume' needs 1 component(s) for each of 2"), std::string::npos)
      << message(in);
  in.arrays["volume"] = {1, {0.0025, -1.0}};
  EXPECT_NE(message(in).find("volume of point 1 is not positive"), std::string::npos)
      << message(in);
  in.arrays["volume"] = {1, {0.0025, 0.0025}};
  in.arrays["velocity"] = {3, {0, 0, 0, 0, 0, 0}};
  EXPECT_NE(message(in).find("'velocity' needs 2 component(s)"), std::string::npos) << message(in);
  EXPECT_NE(message(in, "external_force").find("reads 'contact'"), std::string::npos);
  // Inside an advection step the contact set may move but not change its size.
  in.arrays["velocity"] = {2, {0, 0, 0, 0}};
  EXPECT_EQ(message(in), "");
  water.module->begin_step(water.module->max_dt());
  FieldBuffer three = in;
  three.points = 3;
  three.arrays["position"] = {2, {0.1, 0.1, 0.2, 0.1, 0.3, 0.1}};
  three.arrays["velocity"] = {2, {0, 0, 0, 0, 0, 0}};
  three.arrays["volume"] = {1, {0.0025, 0.0025, 0.0025}};
  EXPECT_NE(message(three).find("3 points inside an advection step that began with 2"),
            std::string::npos)
      << message(three);
  EXPECT_EQ(message(in), "");  // moved, same size: fine
  water.module->end_step();
  FieldBuffer out;
  try {
    water.module->write("interface", out);
    ADD_FAILURE() << "an unknown port was written";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("contact_force"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cosph
