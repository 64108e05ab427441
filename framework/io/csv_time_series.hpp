// A time series of named values written as CSV, one row per sample, readable while the run goes
// on (every row is flushed).
#pragma once

#include <fstream>
#include <string>
#include <vector>

namespace cosph {

class CsvTimeSeries {
 public:
  // Creates (truncates) `path` and writes the header "time,<columns...>". Column names containing
  // a comma, a double quote or a line break are quoted as in RFC 4180. Throws cosph::RuntimeError
  // naming the path if the file cannot be opened.
  CsvTimeSeries(std::string path, std::vector<std::string> columns);

  // Continues the series of a run restarted at `time`: where `path` holds this header, its rows
  // up to `time` stay (later ones belong to the part of the run that is done again) and new
  // rows follow them; otherwise (no file, another header) the file starts as above.
  static CsvTimeSeries resume(std::string path, std::vector<std::string> columns, double time);

  // Writes one row "time,values..." with each number in its shortest exact (round-trip) form and
  // flushes it. values.size() must equal columns().size() (std::invalid_argument otherwise).
  // Throws cosph::RuntimeError naming the path if the write fails.
  void append(double time, const std::vector<double>& values);

  const std::string& path() const { return path_; }
  const std::vector<std::string>& columns() const { return columns_; }

 private:
  CsvTimeSeries(std::string path, std::vector<std::string> columns, const std::string& kept_rows);
  static std::string header_of(const std::vector<std::string>& columns);
  void check_stream() const;

  std::string path_;
  std::vector<std::string> columns_;
  std::ofstream out_;
};

}  // namespace cosph
