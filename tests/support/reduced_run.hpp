// Reduced runs for the sanitizer job. Its test preset sets COSPH_TEST_STEP_CAP = N: every
// validation and stability scene then stops after N steps, so that ASan and UBSan see each code
// path the full run takes (scene loading, particle generation, neighbour search, pair loops,
// coupling, sub-stepping, probes, the health monitor) at a cost CI can afford. The accuracy and
// end-state checks need the whole run, so a reduced test stops before them with GTEST_SKIP,
// which ctest reports as skipped, not passed. Unit tests see the variable too; only those that
// ask reduced_run() (two whole grid-sequenced solves, 251 s and 131 s under the sanitizers while
// the variable reached validation and stability tests alone) use it. Unset or 0 (the release
// job): full runs.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "driver/simulation.hpp"

namespace cosph::test {

inline unsigned long long step_cap() {
  const char* text = std::getenv("COSPH_TEST_STEP_CAP");
  if (text == nullptr || *text == '\0') return 0;
  char* end = nullptr;
  const unsigned long long cap = std::strtoull(text, &end, 10);
  if (*end != '\0' || text[0] == '-')
    throw std::invalid_argument("COSPH_TEST_STEP_CAP = '" + std::string(text) +
                                "': expected a whole number of steps");
  return cap;
}

inline bool reduced_run() { return step_cap() > 0; }

// The options a validation or stability run takes, with the sanitizer job's step cap applied.
inline RunOptions with_step_cap(RunOptions options) {
  options.max_steps = step_cap();
  return options;
}

}  // namespace cosph::test

// After the runs, before the checks that need them to have reached their end time.
#define COSPH_SKIP_CHECKS_IF_REDUCED()                                                            \
  do {                                                                                            \
    if (::cosph::test::reduced_run())                                                             \
      GTEST_SKIP() << "reduced run (COSPH_TEST_STEP_CAP = " << ::cosph::test::step_cap()          \
                   << " steps): the sanitizers saw its code paths; the checks need the full run"; \
  } while (false)
