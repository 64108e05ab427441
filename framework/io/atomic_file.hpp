// Whole-file writes that never leave a half-written file behind: the content goes to a temporary
// file next to the target, which is renamed over it only once everything was written. A reader
// (ParaView refreshing a running simulation's output) therefore sees the old file or the new one.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace cosph {

// Calls write(stream) on a binary stream to "<path>.tmp" and renames it to `path`. Throws
// cosph::RuntimeError naming `path` if the file cannot be created, written or renamed; the
// temporary file is removed in that case. Exceptions thrown by `write` propagate unchanged
// (after removing the temporary file).
void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace cosph
