// Numeric CSV tables with named columns (point clouds, fibre fields): the one reader behind every
// CSV input of a scene, so that all of them accept the same format and fail with the same
// file:line messages.
#pragma once

#include <string>
#include <vector>

namespace cosph {

struct CsvColumns {
  // values[k][row]: the k-th requested column (empty when an optional column is absent).
  std::vector<std::vector<double>> values;
  std::vector<std::size_t> lines;  // file line of each row, for messages
  std::size_t rows() const { return lines.size(); }
};

// Format: comma-separated; blank lines and lines starting with '#' are skipped; the first other
// line is the header (names trimmed, case-insensitive, optionally in double quotes). Returns the
// `required` columns and then the `optional` ones, in that order. Every data line has as many
// fields as the header; requested fields must be finite numbers. `what` names the file's role in
// messages ("point-cloud", "fibre"). Throws RuntimeError "<path>:<line>: message" if the file
// cannot be read, has no header or no data line, lacks a required column or repeats one, or has a
// malformed line.
CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& required,
                            const std::vector<std::string>& optional, const std::string& what);

}  // namespace cosph
