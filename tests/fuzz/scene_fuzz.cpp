// Fuzz target: scene text and --set overrides. Any text either loads, builds and runs two steps, or
// stops with a cosph error (ConfigError, SceneError, RuntimeError) carrying a message: the promise
// that bad input gets a clear error. Anything else (another exception, a crash, a sanitizer report)
// is a bug. Bodies are capped at 20,000 particles so that one input cannot take the machine.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace {

void require_message(const std::exception& e) {
  if (std::string(e.what()).empty()) {
    std::cerr << "a cosph error without a message\n";
    std::abort();
  }
}

}  // namespace

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
  try {
    cosph::RunOptions options;
    options.bench = true;
    options.progress = false;
    options.threads = 1;
    options.max_steps = 2;
    cosph::Simulation simulation(cosph::load_scene_text(text, "fuzz.yaml", overrides),
                                 cosph::builtin_modules(), options);
    simulation.initialize();
    simulation.run();
  } catch (const cosph::ConfigError& e) {
    require_message(e);
  } catch (const cosph::RuntimeError& e) {
    require_message(e);
  }
  return 0;
}
