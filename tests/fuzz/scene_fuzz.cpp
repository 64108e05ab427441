// Fuzz target: scene text and --set overrides. Any text either loads, builds and runs two steps, or
// stops with a cosph error (ConfigError, SceneError, RuntimeError) carrying a message: the promise
// that bad input gets a clear error. Anything else (another exception, a crash, a sanitizer report)
// is a bug. Bodies are capped at 20,000 particles so that one input cannot take the machine.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 1 << 16) return 0;
  // Lines after a line "#--set" are --set overrides (key.path=value), so the override parser is
  // fuzzed with the YAML one.
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  if (const auto at = text.find("\n#--set\n"); at != std::string::npos) {
    std::istringstream lines(text.substr(at + 8));
    for (std::string line; std::getline(lines, line);) overrides.push_back(line);
    text.resize(at + 1);
  }
  overrides.push_back("run.max_particles=20000");
  cosph::fuzz::run_two_steps([&] { return cosph::load_scene_text(text, "fuzz.yaml", overrides); });
  return 0;
}
