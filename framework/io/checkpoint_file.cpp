#include "io/checkpoint_file.hpp"

#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace cosph {

namespace {
const char* const kMagic = "cosph-checkpoint";
}

std::uint64_t fnv1a64(const std::string& bytes) {
  std::uint64_t hash = 1469598103934665603ull;
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

void write_checkpoint(const std::string& path, const proto::Checkpoint& checkpoint) {
  proto::CheckpointFile file;
  file.set_magic(kMagic);
  std::string payload;
  if (!checkpoint.SerializeToString(&payload))
    throw RuntimeError(path + ": cannot serialise checkpoint");
  file.set_checksum(fnv1a64(payload));
  file.set_payload(std::move(payload));
  write_file_atomically(path, [&](std::ostream& out) {
    if (!file.SerializeToOstream(&out)) throw RuntimeError(path + ": cannot write checkpoint");
  });
}

proto::Checkpoint read_checkpoint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw RuntimeError(path + ": cannot open checkpoint file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  proto::CheckpointFile file;
  if (!file.ParseFromString(buffer.str()) || file.magic() != kMagic)
    throw RuntimeError(path + ": not a cosph checkpoint file (or it is damaged)");
  if (fnv1a64(file.payload()) != file.checksum())
    throw RuntimeError(path + ": checkpoint is damaged (checksum mismatch)");
  proto::Checkpoint checkpoint;
  if (!checkpoint.ParseFromString(file.payload()))
    throw RuntimeError(path + ": checkpoint payload cannot be parsed");
  if (checkpoint.format_version() != kCheckpointFormatVersion)
    throw RuntimeError(path + ": checkpoint format version " +
                       std::to_string(checkpoint.format_version()) +
                       " is not supported (this build reads version " +
                       std::to_string(kCheckpointFormatVersion) + ")");
  return checkpoint;
}

}  // namespace cosph
