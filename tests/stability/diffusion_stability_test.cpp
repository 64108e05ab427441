// Stability suite (ctest -L stability): hard diffusion cases run to their end and stay sane, and
// the health monitor stops a run built to blow up with a message that says where.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "../support/reduced_run.hpp"
#include "cli.hpp"
#include "driver/health_monitor.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

// Diffusion ratio 100 along a direction at 30 degrees, on a lattice perturbed by up to 40% of the
// spacing, from a sharp initial square: the case where negative weights or a too-large step
// would show first.
const char* const kHardAnisotropic = R"yaml(
dimension: 2
end_time: 1.0e9
domain: {lower: [0, 0], upper: [1, 1]}
run: {health_interval: 50}
modules:
  - name: hard
    diffusion:
      body:
        spacing: 0.02
        perturbation: 0.4
        perturbation_seed: 7
        shape: {box: {lower: [0, 0], upper: [1, 1]}}
      anisotropy: {direction: [0.8660254037844387, 0.5], along: 1.0e-3, across: 1.0e-5}
      initial: "heaviside(0.1 - abs(x - 0.5)) * heaviside(0.1 - abs(y - 0.5))"
)yaml";

struct Stats {
  double min = INFINITY, max = -INFINITY, total = 0.0, energy = 0.0;
  bool finite = true;
};

Stats stats(Simulation& simulation) {
  BodyViews views;
  simulation.module(0).bodies(views);
  const ParticleSet<2>& p = *views.bodies2.at(0).particles;
  Stats s;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double c = p.scalar("concentration")[i], V = p.scalar("volume")[i];
    s.finite &= std::isfinite(c);
    s.min = std::min(s.min, c);
    s.max = std::max(s.max, c);
    s.total += V * c;
    s.energy += V * c * c;
  }
  return s;
}

TEST(DiffusionStability, RatioHundredOnPerturbedLatticeStaysBoundedForTenThousandSteps) {
  RunOptions options;
  options.bench = true;
  options.progress = false;
  Simulation simulation(load_scene_text(kHardAnisotropic, "hard.yaml"), builtin_modules(), options);
  simulation.initialize();
  const double dt = simulation.module(0).max_dt();
  options.end_time = 10000.5 * dt;  // 10^4 steps (the last one partial)
  Simulation run(load_scene_text(kHardAnisotropic, "hard.yaml"), builtin_modules(),
                 test::with_step_cap(options));
  run.initialize();
  const Stats before = stats(run);
  const RunSummary summary = run.run();  // the health monitor checks every 50 steps
  const Stats after = stats(run);
  EXPECT_TRUE(after.finite);
  // Bounds stated, true after any number of steps: values within the initial range [0, 1]
  // (discrete maximum principle), total amount conserved to 1e-12 relative, the L2 energy
  // decreased.
  EXPECT_GE(after.min, 0.0);
  EXPECT_LE(after.max, 1.0);
  EXPECT_NEAR(after.total, before.total, 1e-12 * before.total);
  EXPECT_LT(after.energy, before.energy);
  COSPH_SKIP_CHECKS_IF_REDUCED();
  EXPECT_EQ(summary.steps, 10001u);
  std::cout << "after 10^4 steps: c in [" << after.min << ", " << after.max << "]\n";
  // It diffused, by as much as measured (peak 0.169481), bounded 2% either side: a diffusion
  // operator 10% too strong lowers the peak of a spreading blob by 5% (quasi-1D, peak ~
  // 1/sqrt(D t)) to 9% (2D, peak ~ 1/(D t)).
  EXPECT_LT(after.max, 1.02 * 0.169481);
  EXPECT_GT(after.max, 0.98 * 0.169481);
}

TEST(DiffusionStability, HealthMonitorStopsABlowUpNamingModuleQuantityParticleAndStep) {
  // Five times the stable step: explicit Euler amplifies the shortest modes until the maximum
  // principle is violated.
  RunOptions options;
  options.bench = true;
  options.progress = false;
  Simulation probe(load_scene_text(kHardAnisotropic, "blowup.yaml"), builtin_modules(), options);
  probe.initialize();
  const double unstable = 5.0 * probe.module(0).max_dt();
  std::ostringstream set;
  set.precision(17);
  set << "modules[0].diffusion.time_step=" << unstable;
  Simulation simulation(load_scene_text(kHardAnisotropic, "blowup.yaml", {set.str()}),
                        builtin_modules(), options);
  simulation.initialize();
  try {
    simulation.run();
    FAIL() << "the run should have been stopped";
  } catch (const HealthError& e) {
    const std::string msg = e.what();
    std::cout << msg << "\n";
    EXPECT_NE(msg.find("health check failed at step 50 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("module 'hard'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("concentration = "), std::string::npos) << msg;
    EXPECT_NE(msg.find("at particle "), std::string::npos) << msg;
    EXPECT_NE(msg.find("position ("), std::string::npos) << msg;
    EXPECT_NE(msg.find("maximum principle"), std::string::npos) << msg;
  }
}

TEST(DiffusionStability, NonFiniteInitialValuesAreCaughtBeforeTheFirstStep) {
  RunOptions options;
  options.bench = true;
  options.progress = false;
  Simulation simulation(
      load_scene_text(kHardAnisotropic, "nan.yaml", {"modules[0].diffusion.initial=sqrt(x - 0.5)"}),
      builtin_modules(), options);
  simulation.initialize();
  try {
    simulation.run();
    FAIL() << "NaN initial values should stop the run";
  } catch (const HealthError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("at step 0 "), std::string::npos) << msg;
    EXPECT_NE(msg.find("concentration = "), std::string::npos) << msg;
    EXPECT_NE(msg.find("nan at particle"), std::string::npos) << msg;
    EXPECT_NE(msg.find("a finite value"), std::string::npos) << msg;
  }
}

TEST(DiffusionStability, CommandLineReportsHealthFailureAndHealthOffSkipsIt) {
  const std::string file = testing::TempDir() + "blowup_cli.yaml";
  {
    std::ofstream out(file);
    out << kHardAnisotropic;
  }
  std::ostringstream out, err;
  const std::vector<std::string> base = {
      "run",        file,   "--bench", "--quiet",
      "--end-time", "2000", "--set",   "modules[0].diffusion.time_step=100"};
  EXPECT_EQ(run_cli(base, out, err), 1);
  EXPECT_NE(err.str().find("health check failed"), std::string::npos) << err.str();
  std::vector<std::string> off = base;
  off.insert(off.end(), {"--health", "off"});
  std::ostringstream out2, err2;
  EXPECT_EQ(run_cli(off, out2, err2), 0) << err2.str();
}

}  // namespace
}  // namespace cosph
