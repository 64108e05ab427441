// Fuzz target: CSV inputs of a scene (point clouds in 2D and 3D, fibre fields), all read by
// read_csv_columns. Any file either reads or is refused with a RuntimeError naming the file and
// line; anything else is a bug. Seeds: tests/fuzz/seeds/ and bench/reference/*.csv.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "core/error.hpp"
#include "geometry/csv_table.hpp"
#include "geometry/point_cloud_csv.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string path = (std::filesystem::temp_directory_path() /
                                   ("cosph_csv_fuzz_" + std::to_string(getpid()) + ".csv"))
                                      .string();
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  auto guarded = [](auto&& read) {
    try {
      read();
    } catch (const cosph::RuntimeError& e) {
      if (std::string(e.what()).find(path) == std::string::npos) {
        std::cerr << "a CSV error that does not name the file: " << e.what() << "\n";
        std::abort();
      }
    }
  };
  guarded([] { (void)cosph::read_point_cloud_csv<2>(path); });
  guarded([] { (void)cosph::read_point_cloud_csv<3>(path); });
  guarded([] {
    (void)cosph::read_csv_columns(path, {"x", "y", "z", "fx", "fy", "fz"}, {"sx", "sy", "sz"},
                                  "fibre");
  });
  return 0;
}
