// Errors are values with context. A ConfigError names the scene key path it is about; the scene
// loader adds the file and line, and the command-line front end is the only place that prints
// them and chooses an exit code.
#pragma once

#include <stdexcept>
#include <string>

namespace cosph {

// Something the user wrote is wrong: unknown key, wrong type, non-physical value. Exit code 2.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(std::string key_path, const std::string& message)
      : std::runtime_error(message), key_path_(std::move(key_path)) {}
  const std::string& key_path() const { return key_path_; }

 private:
  std::string key_path_;
};

// A run went wrong in a way the user must know about (singular correction matrix, unreadable
// file, damaged checkpoint). Exit code 1.
class RuntimeError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace cosph
