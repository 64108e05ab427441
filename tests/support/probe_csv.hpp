// Reading probe CSV files in tests: one column (0 = time) of a file written by the driver's
// probes, with "nan" (a dry sensor) read as NaN.
#pragma once

#include <cmath>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace cosph::test {

inline std::vector<double> csv_column(const std::string& file, int column) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  std::vector<double> values;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::string cell;
    for (int c = 0; c <= column; ++c) std::getline(row, cell, ',');
    values.push_back(cell == "nan" ? NAN : std::stod(cell));
  }
  return values;
}

}  // namespace cosph::test
