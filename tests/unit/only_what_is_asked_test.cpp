// A scene pays only for what it asks: what the scene does not name is neither listed in the run
// summary nor allocated (no fields registered, no files written).
#include <gtest/gtest.h>

#include <filesystem>

#include "driver/simulation.hpp"
#include "module_catalogue.hpp"

namespace cosph {
namespace {

namespace fs = std::filesystem;

const char* const kMinimal = R"yaml(
dimension: 2
end_time: 0.5
modules:
  - name: plain
    diffusion:
      body:
        spacing: 0.05
        shape: {box: {lower: [0, 0], upper: [1, 1]}}
      diffusivity: 1.0e-3
      kernel_correction: false
      initial: "x"
output: {vtp: false}
checkpoint: {at_end: false}
)yaml";

RunSummary run(const std::string& text, const std::vector<std::string>& overrides,
               const fs::path& out, std::vector<std::string>* fields) {
  RunOptions options;
  options.progress = false;
  options.output_directory = out.string();
  Simulation simulation(load_scene_text(text, "scene.yaml", overrides), builtin_modules(), options);
  simulation.initialize();
  const RunSummary summary = simulation.run();
  BodyViews views;
  simulation.module(0).bodies(views);
  *fields = views.bodies2.at(0).particles->field_names();
  return summary;
}

TEST(OnlyWhatIsAsked, MinimalSceneListsAndAllocatesNothingOptional) {
  const fs::path out = fs::temp_directory_path() / "cosph_only_minimal";
  fs::remove_all(out);
  std::vector<std::string> fields;
  const RunSummary s = run(kMinimal, {}, out, &fields);
  ASSERT_EQ(s.modules.size(), 1u);
  EXPECT_EQ(s.modules[0].features,
            (std::vector<std::string>{"isotropic diffusion", "kernel wendland_c2"}));
  EXPECT_TRUE(s.outputs.empty());
  EXPECT_TRUE(s.probes.empty());
  EXPECT_EQ(fields, (std::vector<std::string>{"position", "volume", "concentration"}));
  // Only the run summary is written: no VTP, PVD, probe or checkpoint file.
  std::vector<std::string> files;
  for (const auto& f : fs::directory_iterator(out)) files.push_back(f.path().filename().string());
  EXPECT_EQ(files, (std::vector<std::string>{"summary.json"}));
}

TEST(OnlyWhatIsAsked, WhatTheSceneNamesIsListed) {
  const fs::path out = fs::temp_directory_path() / "cosph_only_full";
  fs::remove_all(out);
  std::vector<std::string> fields;
  const RunSummary s = run(
      kMinimal,
      {"modules[0].diffusion.kernel_correction=true", "output.vtp=true", "checkpoint.at_end=true",
       "modules[0].diffusion.fixed_values=[{region: {name: left, shape: {box: {lower: [0, 0], "
       "upper: [0.1, 1]}}}, "
       "value: '0'}]",
       "probes=[{name: centre, points: {at: [[0.5, 0.5]], fields: [concentration]}}]"},
      out, &fields);
  EXPECT_EQ(s.modules[0].features,
            (std::vector<std::string>{"isotropic diffusion", "kernel wendland_c2",
                                      "kernel correction", "fixed values"}));
  EXPECT_EQ(s.outputs, (std::vector<std::string>{"vtp", "probe:centre", "checkpoint"}));
  EXPECT_EQ(s.probes.count("centre"), 1u);
  EXPECT_TRUE(fs::exists(out / "plain.pvd"));
  EXPECT_TRUE(fs::exists(out / "centre.csv"));
  EXPECT_TRUE(fs::exists(out / "checkpoint_final.ckpt"));
}

}  // namespace
}  // namespace cosph
