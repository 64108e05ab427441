#include "driver/probe_set.hpp"

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "core/error.hpp"
#include "core/parallel.hpp"
#include "driver/scene_geometry.hpp"
#include "io/csv_time_series.hpp"
#include "io/probes.hpp"
#include "io/reductions.hpp"
#include "io/wall_sensor.hpp"

namespace cosph {

namespace {

template <int D>
const BodyView<D>* find_body(const BodyViews& views, const std::string& body) {
  const auto& list = [&]() -> const std::vector<BodyView<D>>& {
    if constexpr (D == 2)
      return views.bodies2;
    else
      return views.bodies3;
  }();
  for (const auto& v : list)
    if (body.empty() || v.particles->name() == body) return &v;
  return nullptr;
}

}  // namespace

struct ProbeSet::Probe {
  std::string name;
  double interval = 0.0;
  std::vector<std::string> columns;
  std::vector<double> last;
  std::vector<std::vector<double>> points;  // sampling points of point and line probes
  std::unique_ptr<CsvTimeSeries> csv;
  virtual ~Probe() = default;
  virtual std::vector<double> evaluate() const = 0;
};

namespace {

template <int D>
struct PointProbeEntry : ProbeSet::Probe {
  const BodyView<D>* body;
  PointProbe<D> probe;
  PointProbeEntry(const BodyView<D>* b, PointProbe<D> p) : body(b), probe(std::move(p)) {}
  std::vector<double> evaluate() const override {
    return probe.sample(*body->particles, "volume", body->kernel, body->domain);
  }
};

template <int D>
struct ReductionEntry : ProbeSet::Probe {
  const BodyView<D>* body;
  proto::Reduction spec;
  std::vector<double> evaluate() const override {
    const auto& p = *body->particles;
    const std::string& q = spec.quantity();
    if (q == "kinetic_energy") return {total_kinetic_energy<D>(p)};
    if (q == "extent") return {extent<D>(p, spec.axis())};
    if (q == "front") return {front<D>(p, spec.axis())};
    if (q == "surface_height")
      return {surface_height<D>(p, body->kernel, to_vec<D>(spec.at()), spec.axis())};
    if (q == "integral") return {integral<D>(p, spec.field())};
    if (q == "total") {
      if (spec.has_within()) return total_within(p);
      if (p.info(spec.field()).kind == FieldKind::Scalar) return {total_scalar<D>(p, spec.field())};
      const Vec<D> v = total_vector<D>(p, spec.field());
      return std::vector<double>(v.data(), v.data() + D);
    }
    const auto& f = p.scalar(spec.field());
    double m = q == "minimum" ? INFINITY : -INFINITY;
    for (double v : f) m = q == "minimum" ? std::min(m, v) : std::max(m, v);
    return {m};
  }
  // The total over the particles inside the `within` box, summed in index order.
  std::vector<double> total_within(const ParticleSet<D>& p) const {
    const Vec<D> lower = to_vec<D>(spec.within().lower()), upper = to_vec<D>(spec.within().upper());
    const auto& x = p.vector("position");
    auto inside = [&](std::size_t i) {
      for (int a = 0; a < D; ++a)
        if (x[i][a] < lower[a] || x[i][a] > upper[a]) return false;
      return true;
    };
    if (p.info(spec.field()).kind == FieldKind::Scalar) {
      const auto& f = p.scalar(spec.field());
      return {
          deterministic_sum(p.size(), 0.0, [&](std::size_t i) { return inside(i) ? f[i] : 0.0; })};
    }
    const auto& f = p.vector(spec.field());
    const Vec<D> v = deterministic_sum(p.size(), Vec<D>(Vec<D>::Zero()), [&](std::size_t i) {
      return inside(i) ? f[i] : Vec<D>(Vec<D>::Zero());
    });
    return std::vector<double>(v.data(), v.data() + D);
  }
};

// Throws a ConfigError naming key_of(k) for the first point outside the body's domain (a domain
// with lower == upper is unbounded).
template <int D, typename Key>
void require_inside_domain(const std::vector<Vec<D>>& points, const Domain<D>& domain,
                           const Key& key_of, const std::string& what) {
  if (domain.upper == domain.lower) return;
  for (std::size_t k = 0; k < points.size(); ++k)
    for (int a = 0; a < D; ++a)
      if (points[k][a] < domain.lower[a] || points[k][a] > domain.upper[a])
        throw ConfigError(key_of(k), what + " lies outside the domain");
}

template <int D>
struct WallSensorEntry : ProbeSet::Probe {
  const BodyView<D>* body;
  WallSensor<D> sensor;
  WallSensorEntry(const BodyView<D>* b, WallSensor<D> s) : body(b), sensor(std::move(s)) {}
  std::vector<double> evaluate() const override {
    const ParticleSet<D>& wall = *body->particles;
    return sensor.sample(cache.of(sensor, wall, body->kernel.support_radius(), body->domain),
                         wall.vector("force"));
  }
  mutable CoverageCache<D> cache;  // evaluate() is const; the cache only saves work
};

template <int D>
std::unique_ptr<ProbeSet::Probe> make_sensor(const proto::WallSensor& spec, const BodyView<D>* body,
                                             const std::string& path) {
  const ParticleSet<D>& particles = *body->particles;
  if (!particles.has("force") || particles.info("force").kind != FieldKind::Vector ||
      !particles.has("volume"))
    throw ConfigError(path + ".body", "a wall sensor reads the fluid's force on a wall body ('" +
                                          particles.name() +
                                          "' has no vector 'force' and scalar 'volume': a fluid's "
                                          "walls with the 'wall_force' output have them)");
  const Vec<D> normal = to_vec<D>(spec.normal());
  if (!(normal.norm() > 0.0)) throw ConfigError(path + ".sensor.normal", "the normal is zero");
  std::vector<Vec<D>> centres;
  for (const auto& p : spec.at()) centres.push_back(to_vec<D>(p.coordinates()));
  require_inside_domain<D>(
      centres, body->domain,
      [&](std::size_t k) { return path + ".sensor.at[" + std::to_string(k) + "]"; }, "sensor");
  std::unique_ptr<WallSensorEntry<D>> entry;
  try {
    entry =
        std::make_unique<WallSensorEntry<D>>(body, WallSensor<D>(centres, normal, spec.diameter()));
  } catch (const std::invalid_argument& e) {
    throw ConfigError(path + ".sensor", e.what());
  }
  // The setup check fills the entry's cache: a static wall's coverage is computed this once.
  const typename WallSensor<D>::Coverage* checked = nullptr;
  try {
    checked =
        &entry->cache.of(entry->sensor, particles, body->kernel.support_radius(), body->domain);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(path + ".sensor", e.what());
  }
  const auto& coverage = *checked;
  for (std::size_t k = 0; k < coverage.weights.size(); ++k)
    if (coverage.weights[k].empty())
      throw ConfigError(path + ".sensor.at[" + std::to_string(k) + "]",
                        "no wall particle of '" + particles.name() +
                            "' lies behind this sensor's face (within the kernel's support along "
                            "minus the normal): is it on the wall's surface, and does 'normal' "
                            "point out of the wall into the fluid?");
  for (std::size_t k = 0; k < centres.size(); ++k) {
    std::string column = "pressure@p";  // appended: GCC 12's false -Wrestrict (bug 105329)
    entry->columns.push_back(column.append(std::to_string(k)));
    entry->points.emplace_back(centres[k].data(), centres[k].data() + D);
  }
  return entry;
}

template <int D>
std::unique_ptr<ProbeSet::Probe> make_probe(const proto::ProbeSpec& spec, const BodyView<D>* body,
                                            const std::string& path) {
  const ParticleSet<D>& particles = *body->particles;
  auto check_field = [&](const std::string& field, const std::string& key) {
    std::string base = field;
    if (!particles.has(base)) {
      const auto dot = field.rfind('.');
      if (dot != std::string::npos) base = field.substr(0, dot);
    }
    if (!particles.has(base))
      throw ConfigError(key, "body '" + particles.name() + "' has no field '" + field + "'");
  };
  switch (spec.kind_case()) {
    case proto::ProbeSpec::kPoints:
    case proto::ProbeSpec::kLine: {
      std::vector<Vec<D>> points;
      const bool line = spec.has_line();
      const auto& fields = line ? spec.line().fields() : spec.points().fields();
      if (line) {
        const Vec<D> a = to_vec<D>(spec.line().from().coordinates());
        const Vec<D> b = to_vec<D>(spec.line().to().coordinates());
        const int n = spec.line().count();
        for (int k = 0; k < n; ++k) points.push_back(a + (b - a) * (double(k) / (n - 1)));
      } else {
        for (const auto& p : spec.points().at()) points.push_back(to_vec<D>(p.coordinates()));
      }
      require_inside_domain<D>(
          points, body->domain,
          [&](std::size_t k) {
            return path + (line ? ".line" : ".points.at[" + std::to_string(k) + "]");
          },
          "probe point");
      std::vector<std::string> names(fields.begin(), fields.end());
      for (std::size_t k = 0; k < names.size(); ++k)
        check_field(names[k],
                    path + (line ? ".line" : ".points") + ".fields[" + std::to_string(k) + "]");
      ProbeOptions options;
      options.interpolation =
          spec.interpolation() == "quadratic" ? ProbeOptions::Interpolation::quadratic
          : spec.interpolation() == "linear"  ? ProbeOptions::Interpolation::linear
                                              : ProbeOptions::Interpolation::shepard;
      if (spec.configuration() == "reference") {
        options.position_field = "reference_position";
        if (!particles.has(options.position_field))
          throw ConfigError(
              path + ".configuration",
              "body '" + particles.name() + "' does not move: it has no reference configuration");
      }
      auto entry =
          std::make_unique<PointProbeEntry<D>>(body, PointProbe<D>(points, names, {}, options));
      entry->columns = entry->probe.columns();
      for (const auto& p : points) entry->points.emplace_back(p.data(), p.data() + D);
      return entry;
    }
    case proto::ProbeSpec::kReduce: {
      auto entry = std::make_unique<ReductionEntry<D>>();
      entry->body = body;
      entry->spec = spec.reduce();
      const std::string& q = spec.reduce().quantity();
      if (q == "surface_height" && spec.reduce().at_size() == 0)
        throw ConfigError(path + ".reduce.at", "a surface height needs the gauge position 'at'");
      if (q != "kinetic_energy" && q != "extent" && q != "front" && q != "surface_height") {
        if (spec.reduce().field().empty())
          throw ConfigError(path + ".reduce", "'" + q + "' needs a field");
        check_field(spec.reduce().field(), path + ".reduce.field");
      }
      if (spec.reduce().has_within() && q != "total")
        throw ConfigError(path + ".reduce.within", "only a 'total' takes a box");
      if (spec.reduce().has_within())
        for (int a = 0; a < D; ++a)
          if (!(spec.reduce().within().lower(a) <= spec.reduce().within().upper(a)))
            throw ConfigError(path + ".reduce.within",
                              "the box needs lower <= upper along every axis");
      if ((q == "extent" || q == "front" || q == "surface_height") && spec.reduce().axis() >= D)
        throw ConfigError(path + ".reduce.axis", "axis must be below the dimension");
      if (q == "total" && particles.info(spec.reduce().field()).kind == FieldKind::Vector) {
        for (int a = 0; a < D; ++a)
          entry->columns.push_back(spec.reduce().field() + "." + "xyz"[a]);
      } else {
        entry->columns = {
            q == "extent"  ? "extent_" + std::string(1, "xyz"[spec.reduce().axis()])
            : q == "front" ? "front_" + std::string(1, "xyz"[spec.reduce().axis()])
            : q == "surface_height"
                ? std::string("surface_height")
                : q + (spec.reduce().field().empty() ? "" : "_" + spec.reduce().field())};
      }
      return entry;
    }
    case proto::ProbeSpec::kSensor:
      return make_sensor<D>(spec.sensor(), body, path);
    case proto::ProbeSpec::KIND_NOT_SET:
      break;
  }
  throw ConfigError(path, "a probe needs one of: points, line, reduce, sensor");
}

}  // namespace

ProbeSet::ProbeSet(const proto::Scene& scene,
                   const std::vector<std::pair<std::string, BodyViews>>& modules,
                   const std::string& directory) {
  for (int k = 0; k < scene.probes_size(); ++k) {
    const auto& spec = scene.probes(k);
    const std::string path = "probes[" + std::to_string(k) + "]";
    const BodyViews* views = nullptr;
    for (const auto& [name, v] : modules)
      if (spec.module().empty() || spec.module() == name) {
        views = &v;
        break;
      }
    if (!views) throw ConfigError(path + ".module", "no module named '" + spec.module() + "'");
    std::unique_ptr<Probe> probe;
    if (scene.dimension() == 2) {
      const auto* body = find_body<2>(*views, spec.body());
      if (!body) throw ConfigError(path + ".body", "no body named '" + spec.body() + "'");
      probe = make_probe<2>(spec, body, path);
    } else {
      const auto* body = find_body<3>(*views, spec.body());
      if (!body) throw ConfigError(path + ".body", "no body named '" + spec.body() + "'");
      probe = make_probe<3>(spec, body, path);
    }
    for (const auto& other : probes_)
      if (other->name == spec.name())
        throw ConfigError(path + ".name", "two probes named '" + spec.name() + "'");
    probe->name = spec.name();
    probe->interval = spec.interval();
    if (!directory.empty() && !probe->points.empty()) {
      // Sidecar with the sampling points, so that tools can place each column in space.
      std::ofstream out(std::filesystem::path(directory) / (spec.name() + ".points.csv"));
      out << "label,x,y" << (scene.dimension() == 3 ? ",z" : "") << "\n";
      out.precision(17);
      for (std::size_t k = 0; k < probe->points.size(); ++k) {
        out << "p" << k;
        for (double c : probe->points[k]) out << "," << c;
        out << "\n";
      }
    }
    probes_.push_back(std::move(probe));
  }
  directory_ = directory;
}

void ProbeSet::open_files(std::optional<double> resume_time) {
  if (directory_.empty()) return;
  for (auto& p : probes_) {
    std::string path = (std::filesystem::path(directory_) / (p->name + ".csv")).string();
    p->csv = std::make_unique<CsvTimeSeries>(
        resume_time ? CsvTimeSeries::resume(std::move(path), p->columns, *resume_time)
                    : CsvTimeSeries(std::move(path), p->columns));
  }
}

const std::string& ProbeSet::name(std::size_t k) const { return probes_[k]->name; }

ProbeSet::~ProbeSet() = default;

std::size_t ProbeSet::size() const { return probes_.size(); }
double ProbeSet::interval(std::size_t k) const { return probes_[k]->interval; }

void ProbeSet::sample(std::size_t k, double time) {
  Probe& p = *probes_[k];
  p.last = p.evaluate();
  if (p.csv) p.csv->append(time, p.last);
}

std::map<std::string, std::map<std::string, double>> ProbeSet::last_values() const {
  std::map<std::string, std::map<std::string, double>> out;
  for (const auto& p : probes_)
    for (std::size_t c = 0; c < p->columns.size() && c < p->last.size(); ++c)
      out[p->name][p->columns[c]] = p->last[c];
  return out;
}

}  // namespace cosph
