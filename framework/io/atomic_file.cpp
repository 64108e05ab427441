#include "io/atomic_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <system_error>

#include "core/error.hpp"

namespace cosph {

void write_file_atomically(const std::string& path,
                           const std::function<void(std::ostream&)>& write) {
  // Same directory as the target, so that the rename stays within one file system and is atomic.
  const std::string temporary = path + ".tmp";
  auto discard = [&] {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
  };
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) throw RuntimeError("cannot write file '" + path + "': " + std::strerror(errno));
    try {
      write(out);
    } catch (...) {
      out.close();
      discard();
      throw;
    }
    out.close();  // flushes; a full disk shows up here rather than in write()
    if (!out) {
      discard();
      throw RuntimeError("cannot write file '" + path + "' (write failed, disk full?)");
    }
  }
  std::error_code error;
  std::filesystem::rename(temporary, path, error);
  if (error) {
    discard();
    throw RuntimeError("cannot write file '" + path + "': " + error.message());
  }
}

}  // namespace cosph
