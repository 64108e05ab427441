// The driver: restart continues bit-identically, thread count does not change results, damaged
// checkpoints are refused, and the command line maps errors to exit codes with clear messages.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "cli.hpp"
#include "core/error.hpp"
#include "driver/simulation.hpp"
#include "io/checkpoint_file.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

namespace fs = std::filesystem;

const char* const kScene = R"yaml(name: driver_test
dimension: 2
end_time: 2.0
domain: {lower: [0, 0], upper: [1, 1]}
modules:
  - name: blob
    diffusion:
      body:
        spacing: 0.025
        shape:
          difference:
            base: {box: {lower: [0, 0], upper: [1, 1]}}
            subtract: {ellipsoid: {center: [0.7, 0.3], radius: 0.15}}
      anisotropy: {direction: [1, 2], along: 2.0e-3, across: 2.0e-4}
      initial: "exp(-((x - 0.4)^2 + (y - 0.6)^2) / 0.01)"
      fixed_values:
        - region: {name: left, shape: {box: {lower: [0, 0], upper: [0.05, 1]}}}
          value: "0.5 * sin(t)"
output: {interval: 0.5}
checkpoint: {interval: 1.0}
probes:
  - name: point
    points: {at: [[0.5, 0.5]], fields: [concentration]}
  - name: total
    reduce: {quantity: integral, field: concentration}
)yaml";

fs::path temp_dir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("cosph_driver_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string write_scene(const fs::path& dir, const std::string& text) {
  const fs::path file = dir / "scene.yaml";
  std::ofstream(file) << text;
  return file.string();
}

std::string file_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<double> final_field(const std::string& scene, RunOptions options) {
  options.progress = false;
  Simulation simulation(load_scene_file(scene), builtin_modules(), options);
  simulation.initialize();
  simulation.run();
  BodyViews views;
  simulation.module(0).bodies(views);
  return views.bodies2.at(0).particles->scalar("concentration");
}

TEST(Driver, RestartFromCheckpointIsBitIdenticalToUninterruptedRun) {
  const fs::path dir = temp_dir("restart");
  const std::string scene = write_scene(dir, kScene);
  RunOptions full;
  full.output_directory = (dir / "full").string();
  const std::vector<double> uninterrupted = final_field(scene, full);
  const fs::path checkpoint = dir / "full" / "checkpoint_000001.ckpt";  // written at t = 1
  ASSERT_TRUE(fs::exists(checkpoint));

  RunOptions restart;
  restart.output_directory = (dir / "restart").string();
  restart.restart_file = checkpoint.string();
  const std::vector<double> continued = final_field(scene, restart);
  ASSERT_EQ(continued.size(), uninterrupted.size());
  for (std::size_t i = 0; i < continued.size(); ++i)
    ASSERT_EQ(continued[i], uninterrupted[i]) << "particle " << i;
  // The test has teeth: the state at t = 1 differs from the final one.
  RunOptions half;
  half.bench = true;
  half.end_time = 1.0;
  EXPECT_NE(final_field(scene, half), uninterrupted);
}

TEST(Driver, OneAndTwoThreadsGiveBitIdenticalResults) {
  const fs::path dir = temp_dir("threads");
  const std::string scene = write_scene(dir, kScene);
  RunOptions one, two;
  one.bench = two.bench = true;
  one.threads = 1;
  two.threads = 2;
  EXPECT_EQ(final_field(scene, one), final_field(scene, two));
}

TEST(Driver, DamagedOrForeignCheckpointIsRefused) {
  const fs::path dir = temp_dir("damaged");
  const std::string scene = write_scene(dir, kScene);
  RunOptions full;
  full.output_directory = (dir / "out").string();
  final_field(scene, full);
  const fs::path good = dir / "out" / "checkpoint_final.ckpt";
  std::string bytes;
  {
    std::ifstream in(good, std::ios::binary);
    std::stringstream b;
    b << in.rdbuf();
    bytes = b.str();
  }
  auto refused = [&](const std::string& content, const std::string& scene_file,
                     const std::string& expect) {
    const fs::path bad = dir / "bad.ckpt";
    std::ofstream(bad, std::ios::binary) << content;
    RunOptions options;
    options.bench = true;
    options.restart_file = bad.string();
    try {
      final_field(scene_file, options);
      ADD_FAILURE() << "checkpoint accepted, expected: " << expect;
    } catch (const RuntimeError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  };
  std::string flipped = bytes;
  flipped[flipped.size() / 2] ^= 0x20;
  refused(flipped, scene, "");  // damaged payload: checksum or parse error
  refused(bytes.substr(0, bytes.size() / 3), scene, "");
  refused("hello", scene, "not a cosph checkpoint");
  // A checkpoint of another resolution does not match the scene.
  std::string other = kScene;
  other.replace(other.find("spacing: 0.025"), 14, "spacing: 0.05");
  refused(bytes, write_scene(temp_dir("damaged_other"), other), "another scene");
  // Intact files whose records do not fit the module: a missing key, an array of another size,
  // a schedule index that is no index. Each is named; none reads out of range.
  auto edited = [&](const std::function<void(proto::Checkpoint&)>& edit) {
    proto::Checkpoint c = read_checkpoint(good.string());
    edit(c);
    const fs::path file = dir / "edited.ckpt";
    write_checkpoint(file.string(), c);
    return file_text(file);
  };
  refused(edited([](proto::Checkpoint& c) {
            c.mutable_modules(0)->mutable_integers()->erase("steps");
          }),
          scene, "module 'blob': checkpoint does not match: it has no integer 'steps'");
  refused(edited([](proto::Checkpoint& c) {
            c.mutable_modules(0)->mutable_arrays(0)->mutable_values()->RemoveLast();
          }),
          scene, "module 'blob': checkpoint does not match: expected");
  refused(
      edited([](proto::Checkpoint& c) { (*c.mutable_driver_scalars())["output_index"] = -3.5; }),
      scene, "output_index = -3.5 is not a schedule index");
  refused(edited([](proto::Checkpoint& c) { c.set_time(std::nan("")); }), scene, "is not a time");
}

TEST(Driver, OutputFilesAreWritten) {
  const fs::path dir = temp_dir("files");
  const std::string scene = write_scene(dir, kScene);
  RunOptions options;
  options.output_directory = (dir / "out").string();
  final_field(scene, options);
  for (const char* f :
       {"blob.pvd", "blob_000000.vtp", "blob_000004.vtp", "point.csv", "total.csv", "summary.json"})
    EXPECT_TRUE(fs::exists(dir / "out" / f)) << f;
  std::ifstream csv(dir / "out" / "total.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("time,", 0), 0u) << header;
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_EQ(rows, 5);  // t = 0, 0.5, 1, 1.5, 2
}

// Probe schedules are kept by name: a restart whose scene lists the probes in another order
// (and adds one) samples each probe on its own grid, so that the files continue as if the run
// had not stopped; the new probe starts at its first sampling time after the restart. Before,
// schedules were stored by position and the swapped probes took each other's.
TEST(Driver, RestartWithReorderedProbesKeepsEachProbesSchedule) {
  const fs::path dir = temp_dir("reordered");
  std::string text = kScene;
  text.replace(text.find("  - name: point\n"), 16, "  - name: point\n    interval: 0.1\n");
  text.replace(text.find("  - name: total\n"), 16, "  - name: total\n    interval: 0.25\n");
  const std::string scene = write_scene(dir, text);
  RunOptions full;
  full.output_directory = (dir / "full").string();
  final_field(scene, full);

  RunOptions crashed;
  crashed.output_directory = (dir / "crashed").string();
  crashed.end_time = 1.3;  // stops after its checkpoint at t = 1
  final_field(scene, crashed);
  // The restarted scene: the two probes swapped, a third one added.
  const std::string point = "  - name: point\n    interval: 0.1\n";
  const std::size_t at = text.find(point);
  std::string reordered = text.substr(0, at);
  const std::string rest = text.substr(at + point.size());
  const std::size_t body_end = rest.find("  - name: total");
  reordered += rest.substr(body_end) + point + rest.substr(0, body_end) +
               "  - name: late\n    interval: 0.3\n    reduce: {quantity: maximum, field: "
               "concentration}\n";
  RunOptions restart;
  restart.output_directory = crashed.output_directory;
  restart.restart_file = (dir / "crashed" / "checkpoint_000001.ckpt").string();
  final_field(write_scene(temp_dir("reordered_scene"), reordered), restart);

  for (const char* f : {"point.csv", "total.csv"})
    EXPECT_EQ(file_text(dir / "crashed" / f), file_text(dir / "full" / f)) << f;
  std::ifstream late(dir / "crashed" / "late.csv");
  std::string header;
  std::getline(late, header);
  std::vector<double> times;
  for (std::string line; std::getline(late, line);) times.push_back(std::stod(line));
  const std::vector<double> expected = {1.2, 1.5, 1.8, 2.0};  // sampled at the step reaching them
  ASSERT_EQ(times.size(), expected.size());
  for (std::size_t k = 0; k < times.size(); ++k) EXPECT_NEAR(times[k], expected[k], 1e-9);
}

int cli(const std::vector<std::string>& args, std::string* err_text = nullptr) {
  std::ostringstream out, err;
  const int code = run_cli(args, out, err);
  if (err_text) *err_text = err.str();
  return code;
}

TEST(CommandLine, ExitCodesAndMessages) {
  const fs::path dir = temp_dir("cli");
  const std::string scene = write_scene(dir, kScene);
  EXPECT_EQ(cli({"help"}), 0);
  EXPECT_EQ(cli({"check", scene}), 0);
  std::string err;
  EXPECT_EQ(cli({"frobnicate"}, &err), 2);
  EXPECT_EQ(cli({"run", scene, "--threads", "zero"}, &err), 2);
  EXPECT_NE(err.find("--threads"), std::string::npos);
  // Bad scene value via --set: exit code 2 and the key path.
  EXPECT_EQ(cli({"check", scene, "--set", "modules[0].diffusion.body.spacing=0"}, &err), 2);
  EXPECT_NE(err.find("modules[0].diffusion.body.spacing: must be > 0"), std::string::npos) << err;
  // A body outside the domain: exit code 2, named by its key path and line.
  EXPECT_EQ(cli({"check", scene, "--set", "domain.upper=[0.5, 1]"}, &err), 2);
  EXPECT_NE(err.find("modules[0].diffusion.body"), std::string::npos) << err;
  EXPECT_NE(err.find("outside the domain"), std::string::npos) << err;
  // A probe outside the domain.
  EXPECT_EQ(cli({"check", scene, "--set", "probes[0].points.at=[[1.5, 0.5]]"}, &err), 2);
  EXPECT_NE(err.find("probes[0].points.at[0]: probe point lies outside the domain"),
            std::string::npos)
      << err;
  // A fixed-value region that holds no particle.
  EXPECT_EQ(cli({"check", scene, "--set",
                 "modules[0].diffusion.fixed_values[0].region.shape={box: {lower: [2, 2], upper: "
                 "[3, 3]}}"},
                &err),
            2);
  EXPECT_NE(err.find("fixed_values[0].region: the region contains no particle"), std::string::npos)
      << err;
  // Unreadable geometry: a missing point cloud file.
  std::string csv_scene = kScene;
  const auto at = csv_scene.find("        shape:");
  csv_scene = csv_scene.substr(0, at) + "        points_csv: missing.csv\n" +
              csv_scene.substr(csv_scene.find("      anisotropy"));
  EXPECT_EQ(cli({"check", write_scene(temp_dir("cli_csv"), csv_scene)}, &err), 2);
  EXPECT_NE(err.find("missing.csv"), std::string::npos) << err;
  EXPECT_NE(err.find("points_csv"), std::string::npos) << err;
  // A lattice placement on a point cloud, whose volumes are its own.
  EXPECT_EQ(cli({"check", write_scene(temp_dir("cli_csv"), csv_scene), "--set",
                 "modules[0].diffusion.body.placement=vertex"},
                &err),
            2);
  EXPECT_NE(err.find("modules[0].diffusion.body.placement: placement applies to a lattice"),
            std::string::npos)
      << err;
  // A bad expression names its key.
  EXPECT_EQ(cli({"check", scene, "--set", "modules[0].diffusion.initial=exp(-q)"}, &err), 2);
  EXPECT_NE(err.find("modules[0].diffusion.initial"), std::string::npos) << err;
  EXPECT_NE(err.find("unknown identifier 'q'"), std::string::npos) << err;
  // Missing restart file: run-time error, exit code 1.
  EXPECT_EQ(
      cli({"run", scene, "--bench", "--quiet", "--restart", (dir / "nope.ckpt").string()}, &err),
      1);
  EXPECT_NE(err.find("nope.ckpt: cannot open"), std::string::npos) << err;
  // A spacing far too fine for the geometry: stopped before the memory runs out, the body named.
  EXPECT_EQ(cli({"check", scene, "--set", "run.max_particles=1000"}, &err), 2);
  EXPECT_NE(err.find("modules[0].diffusion.body: 1488 particles, more than run.max_particles = "
                     "1000"),
            std::string::npos)
      << err;
  // --steps: a positive integer; the run stops after that many steps, before its end time.
  EXPECT_EQ(cli({"run", scene, "--steps", "0"}, &err), 2);
  EXPECT_NE(err.find("--steps expects a positive integer"), std::string::npos) << err;
  EXPECT_EQ(cli({"run", scene, "--steps", "2.5"}, &err), 2);
  RunOptions few;
  few.bench = true;
  few.progress = false;
  few.max_steps = 3;
  Simulation simulation(load_scene_file(scene), builtin_modules(), few);
  simulation.initialize();
  const RunSummary summary = simulation.run();
  EXPECT_EQ(summary.steps, 3u);
  EXPECT_GT(summary.end_time, 0.0);
  EXPECT_LT(summary.end_time, 0.5);
}

// An event interval below 1e-9 of the run is refused before anything is built, with its key: a
// fuzzed output interval of 5e-322 spun the event loop at t = 0 (found by scene_fuzz, a hang).
TEST(Driver, EventIntervalTooShortToResolveIsRefusedWithItsKey) {
  for (const std::string key : {"output.interval", "checkpoint.interval", "probes[1].interval"}) {
    RunOptions options;
    options.bench = true;
    options.progress = false;
    Simulation simulation(load_scene_text(kScene, "scene.yaml", {key + "=5e-322"}),
                          builtin_modules(), options);
    try {
      simulation.initialize();
      ADD_FAILURE() << key << " = 5e-322 was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key_path(), key);
      const std::string message = e.what();
      EXPECT_NE(message.find("shorter than 2e-09, 1e-9 of the run (end time 2"), std::string::npos)
          << message;
    }
  }
  // 2e-9 itself is accepted (the run is not started here: it would take 1e9 steps).
  RunOptions bench;
  bench.bench = true;
  Simulation fine(load_scene_text(kScene, "scene.yaml", {"output.interval=2e-9"}),
                  builtin_modules(), bench);
  EXPECT_NO_THROW(fine.initialize());
}

}  // namespace
}  // namespace cosph
