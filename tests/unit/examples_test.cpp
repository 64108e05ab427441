// Every example scene is valid: it loads, and its modules build (cosph check).
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "cli.hpp"

namespace cosph {
namespace {

TEST(Examples, EveryExampleSceneChecksOut) {
  int count = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(COSPH_SOURCE_DIR) + "/examples")) {
    if (entry.path().extension() != ".yaml") continue;
    std::ostringstream out, err;
    EXPECT_EQ(run_cli({"check", entry.path().string()}, out, err), 0)
        << entry.path() << ": " << err.str();
    ++count;
  }
  EXPECT_GE(count, 7);
}

}  // namespace
}  // namespace cosph
