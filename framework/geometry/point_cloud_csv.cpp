#include "geometry/point_cloud_csv.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string_view>
#include <vector>

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

}  // namespace

template <int D>
ParticleCloud<D> read_point_cloud_csv(const std::string& path) {
  const auto fail = [&](std::size_t line, const std::string& message) -> RuntimeError {
    return RuntimeError(path + ":" + (line ? std::to_string(line) + ":" : std::string()) + " " +
                        message);
  };
  std::ifstream in(path);
  if (!in) throw fail(0, "cannot open point-cloud file for reading");

  constexpr int kRequired = D + 1;
  const std::array<const char*, 4> names =
      D == 2 ? std::array<const char*, 4>{"x", "y", "volume", ""}
             : std::array<const char*, 4>{"x", "y", "z", "volume"};
  std::array<std::size_t, kRequired> column{};
  std::size_t field_count = 0;
  bool have_header = false;

  ParticleCloud<D> cloud;
  std::string text;
  std::size_t line = 0;
  while (std::getline(in, text)) {
    ++line;
    std::string_view view(text);
    const std::string_view stripped = trim(view);
    if (stripped.empty() || stripped.front() == '#') continue;
    const auto fields = split(view);

    if (!have_header) {
      have_header = true;
      field_count = fields.size();
      for (int r = 0; r < kRequired; ++r) {
        std::size_t hits = 0;
        for (std::size_t c = 0; c < fields.size(); ++c)
          if (column_name(fields[c]) == names[r]) {
            column[r] = c;
            ++hits;
          }
        if (hits > 1) throw fail(line, std::string("column '") + names[r] + "' appears twice");
        if (hits == 0)
          throw fail(line, std::string("missing column '") + names[r] + "' in header '" +
                               std::string(stripped) + "' (required: x, y" + (D == 3 ? ", z" : "") +
                               ", volume)");
      }
      continue;
    }

    if (fields.size() != field_count)
      throw fail(line, "expected " + std::to_string(field_count) +
                           " comma-separated fields (as "
                           "in the header), found " +
                           std::to_string(fields.size()));
    std::array<double, kRequired> value{};
    for (int r = 0; r < kRequired; ++r)
      if (!parse_double(fields[column[r]], value[r]))
        throw fail(line, std::string("column '") + names[r] + "': '" +
                             std::string(fields[column[r]]) + "' is not a finite number");
    if (!(value[D] > 0.0))
      throw fail(line, "volume must be positive, got " + std::string(fields[column[D]]));
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = value[a];
    cloud.positions.push_back(x);
    cloud.volumes.push_back(value[D]);
  }
  if (in.bad()) throw fail(line, "read error");
  if (!have_header) throw fail(0, "no header line (expected column names x, y, ..., volume)");
  if (cloud.positions.empty()) throw fail(0, "no particles (only a header)");
  return cloud;
}

template ParticleCloud<2> read_point_cloud_csv<2>(const std::string&);
template ParticleCloud<3> read_point_cloud_csv<3>(const std::string&);

}  // namespace cosph
