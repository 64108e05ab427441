// Fuzz target: checkpoint contents. The input is a checkpoint payload (proto::Checkpoint, the
// bytes inside the file's checksum, so that mutations reach the decoder and every module's load
// instead of stopping at the checksum); it is written as a checkpoint of a small scene with
// several modules and a coupler, and the scene is restarted from it for two steps. Every input
// either restarts or is refused with a RuntimeError naming the problem; anything else is a bug.
// A file given whole (starting with its header) is unwrapped first, so real checkpoints seed it:
// `cosph run tests/fuzz/checkpoint_scene.yaml --steps 3` writes one.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <string>

#include "checkpoint.pb.h"
#include "core/error.hpp"
#include "driver/simulation.hpp"
#include "io/checkpoint_file.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace {

std::string scene_text() {
  std::ifstream in(COSPH_SOURCE_DIR "/tests/fuzz/checkpoint_scene.yaml");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void require_message(const std::exception& e) {
  if (std::string(e.what()).empty()) {
    std::cerr << "a cosph error without a message\n";
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string bytes(reinterpret_cast<const char*>(data), size);
  cosph::proto::CheckpointFile file;
  if (bytes.rfind("\n\x10"
                  "cosph-checkpoint",
                  0) == 0 &&
      file.ParseFromString(bytes))
    bytes = file.payload();
  cosph::proto::Checkpoint checkpoint;
  if (!checkpoint.ParseFromString(bytes)) return 0;
  static const std::string path = (std::filesystem::temp_directory_path() /
                                   ("cosph_checkpoint_fuzz_" + std::to_string(getpid()) + ".ckpt"))
                                      .string();
  try {
    cosph::write_checkpoint(path, checkpoint);
    cosph::RunOptions options;
    options.bench = true;
    options.progress = false;
    options.threads = 1;
    options.max_steps = 2;
    options.restart_file = path;
    static const std::string scene = scene_text();
    cosph::Simulation simulation(cosph::load_scene_text(scene, "checkpoint_scene.yaml"),
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
