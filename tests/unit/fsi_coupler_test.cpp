// The FSI coupler as a specification: the impulse the fluid gives the solid is the impulse the
// fluid loses (to round-off), the work the fluid's force does on the solid is the solid's energy
// change, coupled runs restart and change thread count bit for bit, coupling mistakes in a scene
// are refused with their key path, and the summary reports the coupler apart from its modules.
#include "fsi/fsi_coupler.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>

#include "../support/simulation_setup.hpp"
#include "core/error.hpp"
#include "driver/coupler_registry.hpp"
#include "driver/state_codec.hpp"
#include "driver/timed_module.hpp"
#include "io/checkpoint_file.hpp"
#include "scene/scene_loader.hpp"

namespace cosph {
namespace {

using test::make_simulation;
using test::particles_of;

// Water moving at 1 m/s into a free elastic block, no gravity, no walls: nothing outside the
// two bodies exerts a force, so their total momentum must stay what it was.
const char* kCollision = R"yaml(
dimension: 2
end_time: 0.05
domain: {lower: [-1, -1], upper: [2, 2]}
modules:
  - name: water
    fluid:
      body: {spacing: 0.02, shape: {box: {lower: [0, 0], upper: [0.3, 0.3]}}}
      density: 1000
      sound_speed: 20
      viscosity: 0.5
      initial_velocity: ["1", "0.2 * sin(10 * y)"]
  - name: block
    solid:
      body: {spacing: 0.01, shape: {box: {lower: [0.34, 0.05], upper: [0.4, 0.25]}}}
      material:
        density: 500
        neo_hookean: {young: 2.0e5, poisson: 0.3}
      outputs: [strain_energy]
couplers:
  - name: fsi
    fsi: {fluid: water, solid: block}
)yaml";

// Total momentum of the scene's two bodies (module 0 fluid, module 1 solid) and the sum of
// |m v| over both (the scale of the round-off).
std::pair<Vec<2>, double> momentum(Simulation& s) {
  Vec<2> total = Vec<2>::Zero();
  double scale = 0.0;
  for (std::size_t k = 0; k < 2; ++k) {
    BodyViews views;
    s.module(k).bodies(views);
    const auto& p = *views.bodies2.at(0).particles;
    for (std::size_t i = 0; i < p.size(); ++i) {
      const Vec<2> mv = p.scalar("mass")[i] * p.vector("velocity")[i];
      total += mv;
      scale += mv.norm();
    }
  }
  return {total, scale};
}

// The collision scene's fluid and solid, built and initialised outside a Simulation (for tests
// that compose the coupler themselves).
std::vector<std::unique_ptr<Module>> collision_modules(const LoadedScene& scene) {
  std::vector<std::unique_ptr<Module>> modules;
  for (int k = 0; k < 2; ++k) {
    const ModuleContext context{&scene.scene, "modules[" + std::to_string(k) + "]", "."};
    auto m = builtin_modules().create(k == 0 ? "fluid" : "solid", scene.scene.modules(k), context);
    m->initialize();
    modules.push_back(std::move(m));
  }
  return modules;
}

// Runs the collision 60 coupler steps; returns the change of the total momentum relative to the
// scale sum |m v|, and checks that the water has hit the block.
double collision_momentum_change(const std::vector<std::string>& overrides) {
  auto s = make_simulation(kCollision, overrides);
  const auto [before, scale] = momentum(*s);
  Module& root = s->coupler(0);
  for (int step = 0; step < 60; ++step) root.advance(root.max_dt());
  const auto [after, unused] = momentum(*s);
  BodyViews views;
  s->module(1).bodies(views);
  const auto& block = *views.bodies2.at(0).particles;
  double block_momentum = 0.0;
  for (std::size_t i = 0; i < block.size(); ++i)
    block_momentum += block.scalar("mass")[i] * block.vector("velocity")[i][0];
  std::cout << std::setprecision(17) << "momentum before " << before.transpose() << ", after "
            << after.transpose() << ", change " << (after - before).norm() << ", block "
            << block_momentum << " (scale " << scale << ")\n";
  // The water has hit the block: it carries a good part of the momentum now.
  EXPECT_GT(block_momentum, 0.02 * before[0]);
  return (after - before).norm() / scale;
}

TEST(FsiCoupler, ImpulseOnTheSolidBalancesTheFluidsToRoundOff) {
  // Measured: a change of 2.3e-13 against a scale of 91 (2.5e-15 relative).
  EXPECT_LT(collision_momentum_change({}), 4e-15);
}

// At eta = 500 the viscous limit (3.4e-4 s) lies below the acoustic sub-step (7.4e-4 s): the
// fluid applies its viscous force in split steps, and the block (2000 kg/m^3: its exchange
// interval may be twice the limit) is handed their mean, so over each sub-step it gets the
// impulse the water lost.
TEST(FsiCoupler, ImpulseBalancesWithTheViscousForceSubCycled) {
  // Measured: 1.7e-15 relative (handing over only the last split's force: 0.11).
  EXPECT_LT(collision_momentum_change(
                {"modules[0].fluid.viscosity=500", "modules[1].solid.material.density=2000"}),
            2.6e-15);
}

// A block lighter than the water (500 kg/m^3) in water of eta = 500 Pa s: held against the shear
// over three split steps per exchange it went non-finite within 60 steps; its exchange interval
// now keeps within the fluid's viscous limit, and the impulse still balances.
TEST(FsiCoupler, ALightBlockInAViscousFluidStaysFinite) {
  // Measured: 2.8e-15 relative.
  EXPECT_LT(collision_momentum_change({"modules[0].fluid.viscosity=500"}), 4.2e-15);
}

// Forwards every call to the solid, measuring the external force it is handed: the work it does
// over each advance, sum_i F_i . (x_i(after) - x_i(before)), and its impulse (force times the
// advance's length, per component) over the time `elapsed`; the last force, the one before it,
// and how many were handed. A test empties what it measures when it likes.
class ForceMeter final : public Module {
 public:
  explicit ForceMeter(std::unique_ptr<Module> solid) : solid_(std::move(solid)) {}
  double work = 0.0, elapsed = 0.0;
  std::vector<double> impulse, force, previous;
  int forces = 0;

  ModuleInfo info() const override { return solid_->info(); }
  void initialize() override { solid_->initialize(); }
  double max_dt() const override { return solid_->max_dt(); }
  void advance(double dt) override {
    FieldBuffer before, after;
    solid_->write("particles", before);
    solid_->advance(dt);
    solid_->write("particles", after);
    const auto& x0 = before.arrays.at("position").values;
    const auto& x1 = after.arrays.at("position").values;
    impulse.resize(force.size(), 0.0);
    for (std::size_t c = 0; c < x0.size(); ++c) {
      work += force[c] * (x1[c] - x0[c]);
      impulse[c] += force[c] * dt;
    }
    elapsed += dt;
  }
  double time() const override { return solid_->time(); }
  void write(const std::string& port, FieldBuffer& out) const override { solid_->write(port, out); }
  void read(const std::string& port, const FieldBuffer& in) override {
    if (port == "external_force") {
      previous = std::move(force);
      force = in.arrays.at("force").values;
      ++forces;
    }
    solid_->read(port, in);
  }
  void save(StateRecord& state) const override { solid_->save(state); }
  void load(const StateRecord& state) override { solid_->load(state); }
  void prepare_output() override { solid_->prepare_output(); }
  void bodies(BodyViews& views) const override { solid_->bodies(views); }
  std::size_t particle_count() const override { return solid_->particle_count(); }

 private:
  std::unique_ptr<Module> solid_;
};

// Kinetic plus strain energy of the solid.
double solid_energy(Module& solid) {
  solid.prepare_output();
  BodyViews views;
  solid.bodies(views);
  const auto& p = *views.bodies2.at(0).particles;
  double e = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i)
    e += 0.5 * p.scalar("mass")[i] * p.vector("velocity")[i].squaredNorm() +
         p.scalar("strain_energy")[i] * p.scalar("volume")[i];
  return e;
}

// The collision scene's FSI coupler with a ForceMeter between it and the solid, initialised.
struct MeteredCollision {
  MeteredCollision() {
    std::vector<std::unique_ptr<Module>> children = collision_modules(scene);
    auto owned = std::make_unique<ForceMeter>(std::move(children[1]));
    meter = owned.get();
    children[1] = std::move(owned);
    coupler = make_fsi_coupler(scene.scene.couplers(0), std::move(children),
                               {&scene.scene, "couplers[0]"});
    coupler->initialize();
  }
  const LoadedScene scene = load_scene_text(kCollision, "collision.yaml");
  ForceMeter* meter = nullptr;
  std::unique_ptr<Coupler> coupler;
};

TEST(FsiCoupler, WorkOfTheFluidForceIsTheSolidsEnergyChange) {
  MeteredCollision run;
  ForceMeter* meter = run.meter;
  Coupler* coupler = run.coupler.get();
  // Up to the impact, then over the steps in which the water pushes the block.
  while (meter->work == 0.0) coupler->advance(coupler->max_dt());
  const double e0 = solid_energy(*meter);
  meter->work = 0.0;
  for (int step = 0; step < 20; ++step) coupler->advance(coupler->max_dt());
  const double e1 = solid_energy(*meter);
  std::cout << "work on the solid " << meter->work << " J/m, its energy change " << e1 - e0
            << " J/m\n";
  EXPECT_GT(meter->work, 1e-4);
  // Measured: 1.73778 against 1.73767 (6.3e-5 relative, the solid's O(dt^2) Verlet energy error).
  EXPECT_NEAR(e1 - e0, meter->work, 1e-4 * meter->work);
}

// What the solid holds after a coupler step (its `external_force` output, a drag probe's input)
// is the step's mean force: times the step it is the impulse the solid received over the step's
// acoustic sub-steps, to round-off. The last sub-step's force alone, handed over before, is one
// phase of the fluid's cycle within the step.
TEST(FsiCoupler, TheSolidHoldsTheStepsMeanForceAfterEachStep) {
  MeteredCollision run;
  ForceMeter* meter = run.meter;
  Coupler* coupler = run.coupler.get();
  // The largest gaps over the run, and the largest mean force component (their scale).
  double held_gap = 0.0, last_substep_gap = 0.0, scale = 0.0;
  for (int step = 0; step < 60; ++step) {
    meter->impulse.assign(meter->impulse.size(), 0.0);
    meter->elapsed = 0.0;
    meter->forces = 0;
    coupler->advance(coupler->max_dt());
    ASSERT_GE(meter->forces, 3) << "step " << step << ": the test needs two sub-steps or more";
    for (std::size_t c = 0; c < meter->force.size(); ++c) {
      const double mean = meter->impulse[c] / meter->elapsed;
      scale = std::max(scale, std::abs(mean));
      held_gap = std::max(held_gap, std::abs(meter->force[c] - mean));
      last_substep_gap = std::max(last_substep_gap, std::abs(meter->previous[c] - mean));
    }
  }
  ASSERT_GT(scale, 0.0) << "the water never reached the block";
  held_gap /= scale;
  last_substep_gap /= scale;
  std::cout << "largest gap to the step's impulse / time: the held force " << held_gap
            << ", the last sub-step's " << last_substep_gap << " (of the largest mean component)\n";
  // Measured: 3.0e-16.
  EXPECT_LT(held_gap, 1.5 * 3.0e-16);
  // The test bites: at the impact the last sub-step's force is far from the step's mean.
  // Measured: 3.18 (the held force read this before the coupler handed over the mean).
  EXPECT_GT(last_substep_gap, 3.18 / 1.5);
}

// ---- Restart and threads -------------------------------------------------------------------

const char* kGate = COSPH_SOURCE_DIR "/examples/fsi_elastic_gate.yaml";

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct CoupledState {
  std::vector<Vec<2>> water, gate, gate_velocity;
};

CoupledState run_gate(const std::string& directory, int threads, const std::string& restart = "") {
  RunOptions options;
  options.threads = threads;
  options.output_directory = directory;
  options.restart_file = restart;
  options.end_time = 0.03;
  auto s = make_simulation(
      read_file(kGate),
      {"output.interval=0.01", "checkpoint.interval=0.015", "modules[0].fluid.body.spacing=0.01"},
      options);
  s->run();
  BodyViews views;
  s->module(1).bodies(views);
  return {particles_of<2>(*s).vector("position"), views.bodies2.at(0).particles->vector("position"),
          views.bodies2.at(0).particles->vector("velocity")};
}

void expect_bit_identical(const CoupledState& a, const CoupledState& b, const std::string& what) {
  ASSERT_EQ(a.water.size(), b.water.size()) << what;
  for (std::size_t i = 0; i < a.water.size(); ++i)
    ASSERT_EQ(a.water[i], b.water[i]) << what << ": water particle " << i;
  ASSERT_EQ(a.gate.size(), b.gate.size()) << what;
  for (std::size_t i = 0; i < a.gate.size(); ++i) {
    ASSERT_EQ(a.gate[i], b.gate[i]) << what << ": gate particle " << i;
    ASSERT_EQ(a.gate_velocity[i], b.gate_velocity[i]) << what << ": gate particle " << i;
  }
}

TEST(FsiCoupler, RestartAndThreadsAreBitIdentical) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(testing::TempDir()) / "cosph_fsi_restart";
  fs::remove_all(dir);
  const CoupledState full = run_gate((dir / "full").string(), 1);
  const fs::path checkpoint = dir / "full" / "checkpoint_000001.ckpt";
  ASSERT_TRUE(fs::exists(checkpoint));
  expect_bit_identical(full, run_gate((dir / "restart").string(), 1, checkpoint.string()),
                       "restart");
  expect_bit_identical(full, run_gate((dir / "two").string(), 2), "two threads");
  double moved = 0.0;
  for (const auto& v : full.gate_velocity) moved = std::max(moved, v.norm());
  EXPECT_GT(moved, 0.05);  // the gate is moving: the comparison compares something
}

// Regression (found by tests/fuzz/checkpoint_fuzz.cpp): a checkpoint whose solid record holds
// a stiffness eigenvalue of 1e30 made the solid's step 1e-15 s, and the coupler ran 1e13 solid
// sub-steps in one acoustic step: a hang. Such a checkpoint is refused with a message now, and a
// NaN or negative eigenvalue is refused by the solid itself.
TEST(FsiCoupler, CheckpointWithABrokenSolidStepIsRefused) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(testing::TempDir()) / "cosph_fsi_broken_checkpoint";
  fs::remove_all(dir);
  run_gate((dir / "full").string(), 1);
  const fs::path checkpoint = dir / "full" / "checkpoint_000001.ckpt";
  auto restart_with = [&](double eigenvalue) -> std::string {
    proto::Checkpoint c = read_checkpoint(checkpoint.string());
    proto::ModuleState* fsi = c.mutable_modules(0);
    EXPECT_EQ(fsi->type(), "fsi");
    proto::ModuleState* gate = fsi->mutable_children(1);
    EXPECT_EQ(gate->name(), "gate");
    (*gate->mutable_scalars())["stiffness_eigenvalue"] = eigenvalue;
    const fs::path edited = dir / "edited.ckpt";
    write_checkpoint(edited.string(), c);
    try {
      run_gate((dir / "restart").string(), 1, edited.string());
    } catch (const RuntimeError& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::string huge = restart_with(1e30);
  EXPECT_NE(huge.find("would take more than 1000000 sub-steps"), std::string::npos);
  // The step itself in significant digits (2 * 0.7 / sqrt(1e30) = 1.4e-15 s), not "0.000000".
  EXPECT_NE(huge.find("stable step 1.4e-15 s"), std::string::npos) << huge;
  EXPECT_NE(restart_with(std::nan("")).find("module 'gate': checkpoint's stiffness_eigenvalue"),
            std::string::npos);
  EXPECT_NE(restart_with(-1.0).find("is not an eigenvalue"), std::string::npos);
}

// ---- Scene errors ----------------------------------------------------------------------------

std::string scene_error(const std::string& couplers) {
  std::string text = read_file(kGate);
  text = text.substr(0, text.find("couplers:")) + couplers;
  try {
    make_simulation(text);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(FsiCoupler, CouplingMistakesNameTheirKey) {
  auto expect = [](const std::string& message, const std::string& key, const std::string& what) {
    EXPECT_NE(message.find(key), std::string::npos) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message;
  };
  expect(scene_error("couplers:\n  - name: f\n    fsi: {fluid: water, solid: door}\n"),
         "couplers[0].fsi.solid", "no module or coupler named 'door'");
  expect(scene_error("couplers:\n  - name: f\n    fsi: {fluid: water, solid: gate}\n"
                     "  - name: g\n    fsi: {fluid: water, solid: gate}\n"),
         "couplers[1].fsi.fluid", "already owned by coupler 'f'");
  expect(scene_error("couplers:\n  - name: f\n    fsi: {fluid: g, solid: gate}\n"
                     "  - name: g\n    fsi: {fluid: water, solid: f}\n"),
         "couplers[0]", "couplers own each other: f <- g <- f");
  expect(scene_error("couplers:\n  - name: f\n    fsi: {fluid: f, solid: gate}\n"),
         "couplers[0].fsi.fluid", "cannot own itself");
  expect(scene_error("couplers:\n  - name: gate\n    fsi: {fluid: water, solid: gate}\n"),
         "couplers[0].name", "already the name of a module");
  expect(scene_error("couplers:\n  - name: f\n    fsi: {fluid: gate, solid: water}\n"),
         "couplers[0].fsi.fluid", "does not read the port 'contact'");
  expect(scene_error("couplers:\n  - name: f\n"), "couplers[0]", "needs its type");
  EXPECT_EQ(scene_error("couplers:\n  - name: f\n    fsi: {fluid: water, solid: gate}\n"), "");
  // A solid coarser than the fluid: the gate at 1.25 mm against water at 1 mm.
  std::string text = read_file(kGate);
  try {
    make_simulation(text, {"modules[0].fluid.body.spacing=0.001"});
    ADD_FAILURE() << "a solid coarser than the fluid was accepted";
  } catch (const SceneError& e) {
    expect(e.what(), "couplers[0].fsi.solid", "coarser than the fluid's");
  }
}

// ---- Summary and what is built ---------------------------------------------------------------

TEST(FsiCoupler, SummaryReportsTheCouplerApartFromItsModules) {
  RunOptions options;
  options.end_time = 0.01;
  auto s = make_simulation(read_file(kGate), {}, options);
  const RunSummary summary = s->run();
  ASSERT_EQ(summary.couplers.size(), 1u);
  const auto& c = summary.couplers[0];
  EXPECT_EQ(c.type, "fsi");
  EXPECT_EQ(c.children, (std::vector<std::string>{"water", "gate"}));
  ASSERT_EQ(summary.modules.size(), 2u);
  const double children = summary.modules[0].advance_seconds + summary.modules[1].advance_seconds;
  EXPECT_GT(children, 0.0);
  EXPECT_GE(c.own_seconds, 0.0);
  EXPECT_NEAR(c.advance_seconds, children + c.own_seconds, 1e-9);
  bool substepping = false, multi_resolution = false;
  for (const auto& f : c.features) {
    substepping = substepping || f.find("solid sub-stepping") != std::string::npos;
    multi_resolution =
        multi_resolution || f.find("solid spacing / fluid spacing = 0.25") != std::string::npos;
  }
  EXPECT_TRUE(substepping);
  EXPECT_TRUE(multi_resolution);
  EXPECT_NE(summary.to_json().find("\"own_seconds\""), std::string::npos);
}

TEST(FsiCoupler, ASceneWithoutCouplersBuildsNone) {
  std::string text = read_file(kGate);
  text = text.substr(0, text.find("couplers:"));
  auto s = make_simulation(text);
  EXPECT_EQ(s->coupler_count(), 0u);
  RunOptions options;
  options.end_time = 0.002;
  options.bench = true;
  options.progress = false;
  auto run = make_simulation(text, {}, options);
  EXPECT_TRUE(run->run().couplers.empty());
}

}  // namespace
}  // namespace cosph

namespace cosph {
namespace {

// A coupler that owns one module and only forwards (what an electromechanics coupler is to the
// FSI coupler that owns it): its ports are the child's, named "child.port".
class Wrapper final : public Coupler {
 public:
  explicit Wrapper(std::unique_ptr<Module> child)
      : Coupler("wrapper", "wrapped", [&] {
          std::vector<std::unique_ptr<Module>> c;
          c.push_back(std::move(child));
          return c;
        }()) {}
  double max_dt() const override { return child(0).max_dt(); }
  void advance(double dt) override {
    child(0).advance(dt);
    ++steps_;
  }

 protected:
  std::vector<std::string> features() const override { return {"forwards"}; }
  void connect() override {}
  void save_own(StateRecord& state) const override { state.integers["steps"] = steps_; }
  void load_own(const StateRecord& state) override { steps_ = state.integers.at("steps"); }

 private:
  long long steps_ = 0;
};

std::unique_ptr<Coupler> collision(bool wrap_the_solid, const LoadedScene& scene) {
  std::vector<std::unique_ptr<Module>> children = collision_modules(scene);
  if (wrap_the_solid) children[1] = std::make_unique<Wrapper>(std::move(children[1]));
  auto fsi =
      make_fsi_coupler(scene.scene.couplers(0), std::move(children), {&scene.scene, "couplers[0]"});
  fsi->initialize();
  return fsi;
}

std::vector<double> solid_positions(Coupler& fsi) {
  FieldBuffer out;
  fsi.write(fsi.info().writes.back().name, out);  // the solid's particles, however nested
  return out.arrays.at("position").values;
}

TEST(FsiCoupler, ASolidInsideAnotherCouplerIsCoupledTheSameAndItsStateNests) {
  const LoadedScene scene = load_scene_text(kCollision, "collision.yaml");
  auto plain = collision(false, scene), nested = collision(true, scene);
  EXPECT_EQ(nested->info().writes.back().name, "wrapped.block.particles");
  for (int step = 0; step < 30; ++step) {
    plain->advance(plain->max_dt());
    nested->advance(nested->max_dt());
  }
  ASSERT_EQ(solid_positions(*plain), solid_positions(*nested));

  // Save two levels deep, through the checkpoint message, into a fresh tree; continue both.
  StateRecord state;
  nested->save(state);
  ASSERT_EQ(state.children.size(), 2u);
  EXPECT_EQ(state.children[1].name, "wrapped");
  ASSERT_EQ(state.children[1].children.size(), 1u);
  EXPECT_EQ(state.children[1].children[0].name, "block");
  // The wrapper counted the solid's sub-steps, as the FSI coupler did.
  EXPECT_EQ(state.children[1].integers.at("steps"), state.integers.at("solid_substeps"));
  EXPECT_GT(state.integers.at("solid_substeps"), 30);
  proto::ModuleState message;
  encode_state(state, message);
  auto restored = collision(true, scene);
  restored->load(decode_state(message));
  for (int step = 0; step < 30; ++step) {
    nested->advance(nested->max_dt());
    restored->advance(restored->max_dt());
  }
  EXPECT_EQ(solid_positions(*nested), solid_positions(*restored));
  EXPECT_NE(solid_positions(*nested), solid_positions(*plain));  // it moved on from there
}

}  // namespace
}  // namespace cosph
