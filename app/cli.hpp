// The `cosph` command line: `run`, `check`, `help`. Parsing and dispatch live here (testable);
// main() only forwards argv. Exit codes: 0 success, 1 run-time failure, 2 bad scene or usage.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace cosph {

int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

}  // namespace cosph
