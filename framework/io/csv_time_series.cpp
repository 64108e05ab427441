#include "io/csv_time_series.hpp"

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "core/error.hpp"
#include "io/text_format.hpp"

namespace cosph {

namespace {

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';  // a quote inside a quoted field is doubled
    quoted += c;
  }
  return quoted + "\"";
}

}  // namespace

CsvTimeSeries::CsvTimeSeries(std::string path, std::vector<std::string> columns)
    : CsvTimeSeries(std::move(path), std::move(columns), std::string()) {}

CsvTimeSeries::CsvTimeSeries(std::string path, std::vector<std::string> columns,
                             const std::string& kept_rows)
    : path_(std::move(path)), columns_(std::move(columns)), out_(path_, std::ios::trunc) {
  if (!out_)
    throw RuntimeError("cannot open CSV file '" + path_ + "' for writing: " + std::strerror(errno));
  out_ << header_of(columns_) << '\n' << kept_rows << std::flush;
  check_stream();
}

CsvTimeSeries CsvTimeSeries::resume(std::string path, std::vector<std::string> columns,
                                    double time) {
  std::string kept;
  std::ifstream in(path);
  std::string line;
  if (in && std::getline(in, line) && line == header_of(columns)) {
    // Rows are "time,..." in round-trip form: the first field reads back exactly.
    while (std::getline(in, line)) {
      const double t = std::strtod(line.c_str(), nullptr);
      if (!(t <= time)) break;  // times increase: everything after was sampled past `time`
      kept += line + '\n';
    }
  }
  in.close();
  return CsvTimeSeries(std::move(path), std::move(columns), kept);
}

std::string CsvTimeSeries::header_of(const std::vector<std::string>& columns) {
  std::string h = "time";
  for (const auto& c : columns) h += ',' + csv_field(c);
  return h;
}

void CsvTimeSeries::append(double time, const std::vector<double>& values) {
  if (values.size() != columns_.size())
    throw std::invalid_argument("CSV file '" + path_ + "' has " + std::to_string(columns_.size()) +
                                " columns, got " + std::to_string(values.size()) + " values");
  // Built whole and flushed at once, so a reader polling the file does not see half rows.
  std::string row = format_double(time);
  for (double v : values) row += ',' + format_double(v);
  row += '\n';
  out_ << row << std::flush;
  check_stream();
}

void CsvTimeSeries::check_stream() const {
  if (!out_) throw RuntimeError("cannot write CSV file '" + path_ + "' (write failed, disk full?)");
}

}  // namespace cosph
