#include "geometry/point_cloud_csv.hpp"

#include "core/error.hpp"
#include "geometry/csv_table.hpp"

namespace cosph {

template <int D>
ParticleCloud<D> read_point_cloud_csv(const std::string& path) {
  const std::vector<std::string> names = D == 2 ? std::vector<std::string>{"x", "y", "volume"}
                                                : std::vector<std::string>{"x", "y", "z", "volume"};
  const CsvColumns table = read_csv_columns(path, names, {}, "point-cloud");
  ParticleCloud<D> cloud;
  for (std::size_t row = 0; row < table.rows(); ++row) {
    const double volume = table.values[D][row];
    if (!(volume > 0.0))
      throw RuntimeError(path + ":" + std::to_string(table.lines[row]) +
                         ": volume must be positive, got " + std::to_string(volume));
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = table.values[a][row];
    cloud.positions.push_back(x);
    cloud.volumes.push_back(volume);
  }
  return cloud;
}

template ParticleCloud<2> read_point_cloud_csv<2>(const std::string&);
template ParticleCloud<3> read_point_cloud_csv<3>(const std::string&);

}  // namespace cosph
