// Scene files: YAML translated into the schema message proto::Scene (proto/scene.proto). Every
// key is checked against the schema through protobuf reflection: unknown keys, wrong types,
// missing required values and values outside the bounds declared in the schema are errors that
// name the file, the line and the key path. `--set key.path=value` overrides are applied to the
// YAML tree before translation, so they are checked exactly like the file.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "scene.pb.h"

namespace cosph {

// Where each key path of the scene came from, for messages about the scene.
class SceneSource {
 public:
  SceneSource() = default;
  explicit SceneSource(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }
  // Directory of the scene file: relative paths in the scene are relative to it.
  std::string directory() const;
  void record(const std::string& key_path, int line, int column);
  void record_override(const std::string& key_path);
  // "file:line:col" for the key path, or for its closest recorded ancestor.
  std::string locate(const std::string& key_path) const;
  // "file:line:col: key.path: message" — the one format for every scene error.
  std::string format(const std::string& key_path, const std::string& message) const;
  std::string format(const ConfigError& error) const {
    return format(error.key_path(), error.what());
  }

 private:
  std::string file_;
  std::map<std::string, std::pair<int, int>> lines_;  // 1-based line and column
  std::map<std::string, bool> overridden_;
};

struct LoadedScene {
  proto::Scene scene;
  SceneSource source;
};

// A scene error already formatted with file, line and key path (what() is the full message).
class SceneError : public ConfigError {
 public:
  using ConfigError::ConfigError;
};

// Loads, overrides and validates. Throws SceneError.
LoadedScene load_scene_file(const std::string& path,
                            const std::vector<std::string>& overrides = {});
LoadedScene load_scene_text(const std::string& text, const std::string& name,
                            const std::vector<std::string>& overrides = {});

// Canonical text of the scene after overrides and defaults (for the run summary and checkpoints).
std::string scene_to_text(const proto::Scene& scene);

}  // namespace cosph
