// Checkpoint files: the complete state of a run as a binary protobuf message
// (proto/checkpoint.proto) wrapped with a magic string and an FNV-1a checksum of the payload,
// written atomically (temp file + rename). Reading refuses a damaged, truncated or foreign file
// with a clear error.
#pragma once

#include <string>

#include "checkpoint.pb.h"

namespace cosph {

constexpr unsigned kCheckpointFormatVersion = 1;

void write_checkpoint(const std::string& path, const proto::Checkpoint& checkpoint);
// Throws RuntimeError naming the path and the problem.
proto::Checkpoint read_checkpoint(const std::string& path);

std::uint64_t fnv1a64(const std::string& bytes);

}  // namespace cosph
