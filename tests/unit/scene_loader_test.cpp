// Scene files: every kind of bad input stops with a message naming the file, the line and the
// key path; overrides are checked like the file itself.
#include "scene/scene_loader.hpp"

#include <gtest/gtest.h>

namespace cosph {
namespace {

const char* const kValid = R"(name: test
dimension: 2
end_time: 1.0
modules:
  - name: heat
    diffusion:
      body:
        spacing: 0.05
        shape:
          box: {lower: [0, 0], upper: [1, 1]}
      diffusivity: 1.0e-3
probes:
  - name: centre
    points: {at: [[0.5, 0.5]], fields: [concentration]}
)";

// The message of the SceneError that loading `text` throws ("" if none).
std::string error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    load_scene_text(text, "scene.yaml", overrides);
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) << "message: " << (haystack)

TEST(SceneLoader, ValidSceneLoadsWithDefaults) {
  const LoadedScene s = load_scene_text(kValid, "scene.yaml");
  EXPECT_EQ(s.scene.dimension(), 2);
  ASSERT_EQ(s.scene.modules_size(), 1);
  const auto& d = s.scene.modules(0).diffusion();
  EXPECT_DOUBLE_EQ(d.body().spacing(), 0.05);
  EXPECT_DOUBLE_EQ(d.body().kernel().smoothing_length_ratio(), 1.3);  // schema default
  EXPECT_TRUE(d.kernel_correction());
  EXPECT_EQ(s.scene.probes(0).points().at(0).coordinates_size(), 2);
}

TEST(SceneLoader, UnknownKeyNamesFileLineAndPathAndListsValidKeys) {
  const std::string msg = error_of(replace(kValid, "      diffusivity:", "      difusivity:"));
  EXPECT_CONTAINS(msg, "scene.yaml:11:");
  EXPECT_CONTAINS(msg, "modules[0].diffusion.difusivity");
  EXPECT_CONTAINS(msg, "unknown key 'difusivity'");
  EXPECT_CONTAINS(msg, "diffusivity");
}

TEST(SceneLoader, WrongTypeIsAnError) {
  const std::string msg = error_of(replace(kValid, "spacing: 0.05", "spacing: fine"));
  EXPECT_CONTAINS(msg, "scene.yaml:8:");
  EXPECT_CONTAINS(msg, "modules[0].diffusion.body.spacing");
  EXPECT_CONTAINS(msg, "expected a number, got 'fine'");
  EXPECT_CONTAINS(error_of(replace(kValid, "dimension: 2", "dimension: 2.5")),
                  "expected an integer");
  EXPECT_CONTAINS(error_of(replace(kValid, "end_time: 1.0", "end_time: [1]")),
                  "expected a number, got a list");
  EXPECT_CONTAINS(error_of(replace(kValid, "box: {lower: [0, 0], upper: [1, 1]}", "box: 3")),
                  "expected a mapping of keys");
}

// Found by scene_fuzz: a flow mapping with a missing key ("{name: c,{box: ...}}") makes a mapping
// a key; yaml-cpp's conversion of it to a name threw TypedBadConversion out of the loader.
TEST(SceneLoader, MappingAsAKeyIsAnError) {
  const std::string msg = error_of(replace(kValid, "{at: [[0.5, 0.5]], fields: [concentration]}",
                                           "{at: [[0.5, 0.5]],{fields: [concentration]}}"));
  EXPECT_CONTAINS(msg, "scene.yaml:14:");
  EXPECT_CONTAINS(msg, "probes[0].points");
  EXPECT_CONTAINS(msg, "expected a key name");
  EXPECT_CONTAINS(msg, "got a mapping");
}

TEST(SceneLoader, MissingRequiredValueIsAnError) {
  const std::string msg = error_of(replace(kValid, "end_time: 1.0\n", ""));
  EXPECT_CONTAINS(msg, "end_time");
  EXPECT_CONTAINS(msg, "required");
  const std::string spacing = error_of(replace(kValid, "        spacing: 0.05\n", ""));
  EXPECT_CONTAINS(spacing, "scene.yaml:7:");  // the body's line
  EXPECT_CONTAINS(spacing, "modules[0].diffusion.body.spacing");
  EXPECT_CONTAINS(error_of(replace(kValid, "end_time: 1.0", "end_time:")), "missing value");
}

TEST(SceneLoader, NonPhysicalNumbersAreErrors) {
  EXPECT_CONTAINS(error_of(replace(kValid, "end_time: 1.0", "end_time: -1")),
                  "must be > 0, got -1");
  EXPECT_CONTAINS(error_of(replace(kValid, "end_time: 1.0", "end_time: 0")), "must be > 0");
  EXPECT_CONTAINS(error_of(replace(kValid, "spacing: 0.05", "spacing: -0.05")),
                  "modules[0].diffusion.body.spacing: must be > 0");
  EXPECT_CONTAINS(error_of(replace(kValid, "diffusivity: 1.0e-3", "diffusivity: -2")),
                  "must be > 0");
  EXPECT_CONTAINS(error_of(replace(kValid, "dimension: 2", "dimension: 4")), "must be <= 3");
  EXPECT_CONTAINS(error_of(replace(kValid, "end_time: 1.0", "end_time: .nan")),
                  "expected a number");
}

TEST(SceneLoader, ListLengthMustMatchDimension) {
  const std::string msg = error_of(replace(kValid, "upper: [1, 1]", "upper: [1, 1, 1]"));
  EXPECT_CONTAINS(msg, "modules[0].diffusion.body.shape.box.upper");
  EXPECT_CONTAINS(msg, "expected 2 values");
}

TEST(SceneLoader, ExclusiveChoicesAreErrors) {
  const std::string text =
      replace(kValid, "    points: {at: [[0.5, 0.5]], fields: [concentration]}",
              "    points: {at: [[0.5, 0.5]], fields: [concentration]}\n"
              "    reduce: {quantity: integral, field: concentration}");
  EXPECT_CONTAINS(error_of(text), "exclude each other");
}

TEST(SceneLoader, ValueOutsideAllowedSetIsAnError) {
  const std::string text = replace(kValid, "        spacing: 0.05",
                                   "        spacing: 0.05\n        kernel: {type: gauss}");
  const std::string msg = error_of(text);
  EXPECT_CONTAINS(msg, "modules[0].diffusion.body.kernel.type");
  EXPECT_CONTAINS(msg, "'gauss' is not one of");
}

TEST(SceneLoader, YamlSyntaxErrorNamesLine) {
  const std::string msg = error_of("dimension: 2\nend_time: [1, 2\n");
  EXPECT_CONTAINS(msg, "scene.yaml:");
  EXPECT_CONTAINS(msg, "YAML syntax error");
}

TEST(SceneLoader, UnreadableFileIsAnError) {
  try {
    load_scene_file("/nonexistent/scene.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_CONTAINS(e.what(), "/nonexistent/scene.yaml: cannot open");
  }
}

TEST(SceneLoader, OverridesReplaceValuesByIndexOrName) {
  auto s = load_scene_text(kValid, "scene.yaml",
                           {"modules[0].diffusion.body.spacing=0.025", "end_time=3"});
  EXPECT_DOUBLE_EQ(s.scene.modules(0).diffusion().body().spacing(), 0.025);
  EXPECT_DOUBLE_EQ(s.scene.end_time(), 3.0);
  s = load_scene_text(kValid, "scene.yaml",
                      {"modules[heat].diffusion.kernel_correction=false", "output.interval=0.5"});
  EXPECT_FALSE(s.scene.modules(0).diffusion().kernel_correction());
  EXPECT_DOUBLE_EQ(s.scene.output().interval(), 0.5);
}

TEST(SceneLoader, BadOverridesAreCheckedLikeTheFile) {
  EXPECT_CONTAINS(error_of(kValid, {"modules[0].diffusion.body.spacing=-1"}),
                  "--set modules[0].diffusion.body.spacing");
  EXPECT_CONTAINS(error_of(kValid, {"modules[0].diffusion.body.spacing=-1"}), "must be > 0");
  EXPECT_CONTAINS(error_of(kValid, {"modules[0].diffusion.bogus=1"}), "unknown key 'bogus'");
  EXPECT_CONTAINS(error_of(kValid, {"modules[7].diffusion.diffusivity=1"}), "has no element [7]");
  EXPECT_CONTAINS(error_of(kValid, {"end_time"}), "expected key.path=value");
}

}  // namespace
}  // namespace cosph
