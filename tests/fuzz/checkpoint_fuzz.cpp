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
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "checkpoint.pb.h"
#include "fuzz_support.hpp"
#include "io/checkpoint_file.hpp"

namespace {

std::string scene_text() {
  std::ifstream in(COSPH_SOURCE_DIR "/tests/fuzz/checkpoint_scene.yaml");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
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
  static const std::string scene = scene_text();
  cosph::fuzz::run_two_steps(
      [&] {
        cosph::write_checkpoint(path, checkpoint);
        return cosph::load_scene_text(scene, "checkpoint_scene.yaml");
      },
      path);
  return 0;
}
