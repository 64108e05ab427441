#include "geometry/csv_table.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>

#include "core/error.hpp"

namespace cosph {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return fields;
}

std::string column_name(std::string_view field) {
  if (field.size() >= 2 && field.front() == '"' && field.back() == '"')
    field = trim(field.substr(1, field.size() - 2));
  std::string name(field);
  for (char& c : name) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return name;
}

// The whole field must be the number: "1.5abc" is an error, not 1.5.
bool parse_double(std::string_view field, double& value) {
  if (!field.empty() && field.front() == '+') field.remove_prefix(1);
  if (field.empty()) return false;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), value);
  return ec == std::errc() && end == field.data() + field.size() && std::isfinite(value);
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

}  // namespace

CsvColumns read_csv_columns(const std::string& path, const std::vector<std::string>& required,
                            const std::vector<std::string>& optional, const std::string& what) {
  const auto fail = [&](std::size_t line, const std::string& message) -> RuntimeError {
    return RuntimeError(path + ":" + (line ? std::to_string(line) + ":" : std::string()) + " " +
                        message);
  };
  std::ifstream in(path);
  if (!in) throw fail(0, "cannot open " + what + " file for reading");

  std::vector<std::string> names = required;
  names.insert(names.end(), optional.begin(), optional.end());
  constexpr std::size_t kAbsent = static_cast<std::size_t>(-1);
  std::vector<std::size_t> column(names.size(), kAbsent);
  std::size_t field_count = 0;
  bool have_header = false;

  CsvColumns table;
  table.values.resize(names.size());
  std::string text;
  std::size_t line = 0;
  while (std::getline(in, text)) {
    ++line;
    const std::string_view view(text);
    const std::string_view stripped = trim(view);
    if (stripped.empty() || stripped.front() == '#') continue;
    const auto fields = split(view);

    if (!have_header) {
      have_header = true;
      field_count = fields.size();
      for (std::size_t r = 0; r < names.size(); ++r) {
        std::size_t hits = 0;
        for (std::size_t c = 0; c < fields.size(); ++c)
          if (column_name(fields[c]) == names[r]) {
            column[r] = c;
            ++hits;
          }
        if (hits > 1) throw fail(line, "column '" + names[r] + "' appears twice");
        if (hits == 0 && r < required.size())
          throw fail(line, "missing column '" + names[r] + "' in header '" + std::string(stripped) +
                               "' (required: " + joined(required) + ")");
      }
      continue;
    }

    if (fields.size() != field_count)
      throw fail(line, "expected " + std::to_string(field_count) +
                           " comma-separated fields (as in the header), found " +
                           std::to_string(fields.size()));
    for (std::size_t r = 0; r < names.size(); ++r) {
      if (column[r] == kAbsent) continue;
      double value = 0.0;
      if (!parse_double(fields[column[r]], value))
        throw fail(line, "column '" + names[r] + "': '" + std::string(fields[column[r]]) +
                             "' is not a finite number");
      table.values[r].push_back(value);
    }
    table.lines.push_back(line);
  }
  if (in.bad()) throw fail(line, "read error");
  if (!have_header)
    throw fail(0, "no header line (expected column names " + joined(required) + ")");
  if (table.rows() == 0) throw fail(0, "no data (only a header)");
  return table;
}

}  // namespace cosph
