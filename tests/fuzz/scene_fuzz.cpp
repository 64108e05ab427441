// Fuzz target: scene text and --set overrides. Any text either loads, builds and runs two steps, or
// stops with a cosph error (ConfigError, SceneError, RuntimeError) carrying a message: the promise
// that bad input gets a clear error. Anything else (another exception, a crash, a sanitizer report)
// is a bug. Bodies are capped at 20,000 particles so that one input cannot take the machine. A
// steady-state solid's step is a whole static solve, up to 127 bisected increments of
// max_iterations each (a mutated load or stiffness can ask for all of them): such scenes are
// capped at 300 particles and 10 iterations, which keeps the worst input within seconds under the
// sanitizers (the example scene itself runs in the smoke tests).
#include <algorithm>
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
  cosph::fuzz::run_two_steps([&] {
    cosph::LoadedScene loaded = cosph::load_scene_text(text, "fuzz.yaml", overrides);
    for (auto& module : *loaded.scene.mutable_modules()) {
      if (!module.has_solid() || !module.solid().has_steady_state()) continue;
      auto* steady = module.mutable_solid()->mutable_steady_state();
      steady->set_max_iterations(std::min(steady->max_iterations(), 10));
      loaded.scene.mutable_run()->set_max_particles(300);
    }
    return loaded;
  });
  return 0;
}
