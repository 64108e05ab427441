// The determinism promise, checked on any scene: one and two threads give bit-identical
// results, and a run restarted from its mid-run checkpoint ends bit for bit where the
// uninterrupted run ends, with its probe CSV files and ParaView collections continuing as if
// the run had never stopped. "Results" are everything a module exposes: every field of every
// body (state and derived) and every module's and coupler's checkpoint record.
#pragma once

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "simulation_setup.hpp"

namespace cosph::test {

// What a run leaves: "module/body/field" -> raw values, the state records flattened the same
// way, the text of every probe CSV and .pvd file, and the step count.
struct RunRecord {
  std::map<std::string, std::vector<double>> values;
  std::map<std::string, std::string> files;
  unsigned long long steps = 0;
};

inline void flatten(const StateRecord& r, const std::string& prefix, RunRecord& out) {
  for (const auto& [k, v] : r.arrays) out.values[prefix + k] = v;
  for (const auto& [k, v] : r.scalars) out.values[prefix + k] = {v};
  for (const auto& [k, v] : r.integers) out.values[prefix + k] = {static_cast<double>(v)};
  for (const auto& c : r.children) flatten(c, prefix + c.name + "/", out);
}

template <int D>
void add_bodies(const std::vector<BodyView<D>>& bodies, const std::string& module, RunRecord& out) {
  for (const auto& b : bodies)
    for (const auto& field : b.particles->field_names()) {
      const auto raw = b.particles->raw(field);
      out.values[module + "/" + b.particles->name() + "/" + field].assign(raw.begin(), raw.end());
    }
}

inline std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline RunRecord record_of(Simulation& simulation, const RunSummary& summary,
                           const std::filesystem::path& directory) {
  RunRecord out;
  out.steps = summary.steps;
  for (std::size_t k = 0; k < simulation.module_count(); ++k) {
    Module& m = simulation.module(k);
    BodyViews views;
    m.bodies(views);
    const std::string name = m.info().name;
    add_bodies(views.bodies2, name, out);
    add_bodies(views.bodies3, name, out);
    StateRecord state;
    m.save(state);
    flatten(state, "state:" + name + "/", out);
  }
  for (std::size_t k = 0; k < simulation.coupler_count(); ++k) {
    StateRecord state;
    simulation.coupler(k).save(state);
    flatten(state, "state:" + simulation.coupler(k).info().name + "/", out);
  }
  if (!directory.empty())
    for (const auto& entry : std::filesystem::directory_iterator(directory)) {
      const auto ext = entry.path().extension();
      const bool sidecar = entry.path().string().ends_with(".points.csv");
      if ((ext == ".csv" && !sidecar) || ext == ".pvd")
        out.files[entry.path().filename().string()] = file_text(entry.path());
    }
  return out;
}

// Bit for bit (NaN equals NaN of the same payload): the first difference is reported.
inline void expect_bit_identical(const RunRecord& a, const RunRecord& b, const std::string& what,
                                 bool compare_files = true) {
  ASSERT_EQ(a.values.size(), b.values.size()) << what << ": different sets of fields";
  for (const auto& [key, va] : a.values) {
    const auto it = b.values.find(key);
    ASSERT_TRUE(it != b.values.end()) << what << ": " << key << " missing";
    const auto& vb = it->second;
    ASSERT_EQ(va.size(), vb.size()) << what << ": " << key;
    for (std::size_t i = 0; i < va.size(); ++i)
      ASSERT_EQ(std::memcmp(&va[i], &vb[i], sizeof(double)), 0)
          << what << ": " << key << "[" << i << "] " << va[i] << " vs " << vb[i];
  }
  if (!compare_files) return;
  ASSERT_EQ(a.files.size(), b.files.size()) << what << ": different output files";
  for (const auto& [name, text] : a.files) {
    const auto it = b.files.find(name);
    ASSERT_TRUE(it != b.files.end()) << what << ": " << name << " missing";
    EXPECT_EQ(text, it->second) << what << ": " << name << " differs";
  }
}

struct DeterminismCase {
  std::string scene;                   // scene text
  std::vector<std::string> overrides;  // applied to every run
  double end_time = 0.0;               // the checkpoint is written at end_time / 2
  unsigned long long min_steps = 0;    // the run must be at least this long (past re-sorts...)
};

// Runs `c` uninterrupted on one thread, on two threads, restarted on two threads from the
// checkpoint at end_time / 2 into a fresh directory, and stopped at 3/4 of end_time then
// restarted from the same checkpoint into its own directory (a run that crashed after its
// checkpoint): the last must reproduce the uninterrupted run's probe CSVs and collections.
inline void check_determinism(const DeterminismCase& c, const std::string& name) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(testing::TempDir()) / ("cosph_determinism_" + name);
  fs::remove_all(dir);
  std::vector<std::string> overrides = c.overrides;
  std::ostringstream interval;
  interval.precision(17);
  interval << c.end_time / 2;
  overrides.push_back("checkpoint.interval=" + interval.str());
  auto run = [&](const std::string& sub, int threads, const std::string& restart, double end_time) {
    RunOptions options;
    options.threads = threads;
    options.output_directory = (dir / sub).string();
    options.restart_file = restart;
    options.end_time = end_time;
    auto simulation = make_simulation(c.scene, overrides, options);
    const RunSummary summary = simulation->run();
    return record_of(*simulation, summary, dir / sub);
  };
  const RunRecord full = run("full", 1, "", c.end_time);
  std::cout << name << ": " << full.steps << " steps, " << full.values.size() << " arrays, "
            << full.files.size() << " probe and collection files\n";
  EXPECT_GE(full.steps, c.min_steps) << name;
  const fs::path checkpoint = dir / "full" / "checkpoint_000001.ckpt";
  ASSERT_TRUE(fs::exists(checkpoint)) << name << ": no checkpoint at end_time / 2";

  expect_bit_identical(full, run("two", 2, "", c.end_time), name + ", 1 vs 2 threads");
  const RunRecord restarted = run("restart", 2, checkpoint.string(), c.end_time);
  EXPECT_GT(restarted.steps, 0u);
  EXPECT_LT(restarted.steps, full.steps);
  expect_bit_identical(full, restarted, name + ", restart", /*compare_files=*/false);

  // The crashed run: its state at 3/4 differs from the end (the comparisons compare something).
  const RunRecord crashed = run("crashed", 1, "", 0.75 * c.end_time);
  bool differs = false;
  for (const auto& [key, v] : crashed.values) differs = differs || v != full.values.at(key);
  EXPECT_TRUE(differs) << name << ": the state at 3/4 of the run is the final one";
  const fs::path crashed_checkpoint = dir / "crashed" / "checkpoint_000001.ckpt";
  ASSERT_TRUE(fs::exists(crashed_checkpoint));
  expect_bit_identical(full, run("crashed", 2, crashed_checkpoint.string(), c.end_time),
                       name + ", restart in the crashed run's directory");
}

}  // namespace cosph::test
