#include "driver/simulation.hpp"

#include <sys/resource.h>
#include <tbb/global_control.h>
#include <tbb/info.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <set>
#include <sstream>

#include "core/error.hpp"
#include "driver/health_monitor.hpp"
#include "driver/probe_set.hpp"
#include "driver/state_codec.hpp"
#include "io/checkpoint_file.hpp"
#include "io/pvd_collection.hpp"
#include "io/vtp_writer.hpp"

namespace cosph {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Events on a fixed grid of simulated times k * interval, tracked by index so that a restarted
// run meets exactly the same event times (and therefore takes exactly the same steps).
struct Schedule {
  double interval = 0.0;  // 0: never
  unsigned long long next = 0;
  bool active() const { return interval > 0.0; }
  double time() const { return static_cast<double>(next) * interval; }
};

std::string json_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    out += c;
  }
  return out;
}

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";  // JSON has no NaN or infinity
  if (!std::isfinite(v)) return "null";
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

// The process's peak resident memory (Linux reports ru_maxrss in kiB).
double peak_resident_bytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0.0;
  return double(usage.ru_maxrss) * 1024.0;
}

std::string fingerprint(const proto::Scene& scene) {
  std::string bytes = std::to_string(scene.dimension());
  for (const auto& m : scene.modules()) bytes += m.SerializeAsString();
  for (const auto& c : scene.couplers()) bytes += c.SerializeAsString();
  if (scene.has_domain()) bytes += scene.domain().SerializeAsString();
  std::ostringstream s;
  s << std::hex << fnv1a64(bytes);
  return s.str();
}

std::string probe_schedule_key(const std::string& probe) { return "probe_next:" + probe; }

}  // namespace

std::string RunSummary::to_json() const {
  std::ostringstream j;
  j << "{\n";
  j << "  \"scene\": \"" << json_escape(scene) << "\",\n";
  j << "  \"dimension\": " << dimension << ",\n";
  j << "  \"threads\": " << threads << ",\n";
  j << "  \"start_time\": " << json_number(start_time) << ",\n";
  j << "  \"end_time\": " << json_number(end_time) << ",\n";
  j << "  \"steps\": " << steps << ",\n";
  j << "  \"wall_seconds\": " << json_number(wall_seconds) << ",\n";
  j << "  \"cpu_seconds\": " << json_number(cpu_seconds) << ",\n";
  j << "  \"output_seconds\": " << json_number(output_seconds) << ",\n";
  j << "  \"peak_memory_bytes\": " << json_number(peak_memory_bytes) << ",\n";
  j << "  \"particles\": " << particles << ",\n";
  j << "  \"particle_steps_per_second\": " << json_number(particle_steps_per_second) << ",\n";
  j << "  \"output_directory\": \"" << json_escape(output_directory) << "\",\n";
  j << "  \"modules\": [";
  for (std::size_t k = 0; k < modules.size(); ++k) {
    const auto& m = modules[k];
    j << (k ? "," : "") << "\n    {\"name\": \"" << json_escape(m.name) << "\", \"type\": \""
      << json_escape(m.type) << "\", \"particles\": " << m.particles
      << ", \"advance_seconds\": " << json_number(m.advance_seconds) << ", \"features\": [";
    for (std::size_t f = 0; f < m.features.size(); ++f)
      j << (f ? ", " : "") << "\"" << json_escape(m.features[f]) << "\"";
    j << "]";
    if (!m.statistics.empty()) {
      j << ", \"statistics\": {";
      bool first = true;
      for (const auto& [key, value] : m.statistics) {
        j << (first ? "" : ", ") << "\"" << json_escape(key) << "\": " << json_number(value);
        first = false;
      }
      j << "}";
    }
    j << "}";
  }
  j << "\n  ],\n  \"couplers\": [";
  for (std::size_t k = 0; k < couplers.size(); ++k) {
    const auto& c = couplers[k];
    j << (k ? "," : "") << "\n    {\"name\": \"" << json_escape(c.name) << "\", \"type\": \""
      << json_escape(c.type) << "\", \"advance_seconds\": " << json_number(c.advance_seconds)
      << ", \"own_seconds\": " << json_number(c.own_seconds) << ", \"children\": [";
    for (std::size_t f = 0; f < c.children.size(); ++f)
      j << (f ? ", " : "") << "\"" << json_escape(c.children[f]) << "\"";
    j << "], \"features\": [";
    for (std::size_t f = 0; f < c.features.size(); ++f)
      j << (f ? ", " : "") << "\"" << json_escape(c.features[f]) << "\"";
    j << "]}";
  }
  j << "\n  ],\n  \"outputs\": [";
  for (std::size_t k = 0; k < outputs.size(); ++k)
    j << (k ? ", " : "") << "\"" << json_escape(outputs[k]) << "\"";
  j << "],\n  \"probes\": {";
  bool first = true;
  for (const auto& [name, columns] : probes) {
    j << (first ? "" : ",") << "\n    \"" << json_escape(name) << "\": {";
    bool first_column = true;
    for (const auto& [column, value] : columns) {
      j << (first_column ? "" : ", ") << "\"" << json_escape(column)
        << "\": " << json_number(value);
      first_column = false;
    }
    j << "}";
    first = false;
  }
  j << "\n  }\n}\n";
  return j.str();
}

struct Simulation::Impl {
  std::unique_ptr<tbb::global_control> threads_control;
  int threads = 1;
  std::string directory;  // empty: no files
  std::vector<std::pair<std::string, BodyViews>> views;
  std::unique_ptr<ProbeSet> probes;
  std::vector<std::pair<std::unique_ptr<PvdCollection>, const void*>> pvds;
  Schedule output, checkpoint;
  std::optional<double> resume_time;  // a restarted run's start: its files continue from there
  std::vector<Schedule> probe_schedules;
  unsigned long long output_index = 0;
  double time = 0.0;
  unsigned long long steps = 0;
  double output_seconds = 0.0;
};

namespace {

// Event times are compared with a tolerance of 1e-12 of the run (at least 1e-12), so an interval
// must be well above it: one below 1e-9 of max(1, end_time) is refused before anything is built
// (a fuzzed output interval of 5e-322 spun the event loop through 1e309 grid points at t = 0).
// It is also a billion files: no scene means it.
void check_event_intervals(const proto::Scene& s, double end) {
  const double shortest = 1e-9 * std::max(1.0, end);
  auto check = [&](bool set, double interval, const std::string& key) {
    if (!set || interval >= shortest) return;
    std::ostringstream m;
    m << "interval " << interval << " is shorter than " << shortest
      << ", 1e-9 of the run (end time " << end
      << ", at least 1): the event grid cannot be resolved";
    throw ConfigError(key, m.str());
  };
  check(s.output().has_interval(), s.output().interval(), "output.interval");
  check(s.checkpoint().has_interval(), s.checkpoint().interval(), "checkpoint.interval");
  for (int k = 0; k < s.probes_size(); ++k)
    check(s.probes(k).has_interval(), s.probes(k).interval(),
          "probes[" + std::to_string(k) + "].interval");
}

}  // namespace

Simulation::Simulation(LoadedScene scene, const ModuleRegistry& registry, RunOptions options)
    : scene_(std::move(scene)),
      registry_(registry),
      options_(std::move(options)),
      impl_(std::make_unique<Impl>()) {}

Simulation::~Simulation() = default;

void Simulation::initialize() {
  const proto::Scene& s = scene_.scene;
  int threads = options_.threads > 0 ? options_.threads : s.run().threads();
  if (threads <= 0) threads = tbb::info::default_concurrency();
  impl_->threads = threads;
  impl_->threads_control =
      std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

  try {
    check_event_intervals(s, options_.end_time >= 0.0 ? options_.end_time : s.end_time());
    if (s.modules_size() > 1) {
      std::set<std::string> names;
      for (int k = 0; k < s.modules_size(); ++k)
        if (!names.insert(s.modules(k).name()).second)
          throw ConfigError("modules[" + std::to_string(k) + "].name",
                            "two modules named '" + s.modules(k).name() + "'");
    }
    std::vector<std::unique_ptr<Module>> modules;
    for (int k = 0; k < s.modules_size(); ++k) {
      const auto& spec = s.modules(k);
      ModuleContext context{&s, "modules[" + std::to_string(k) + "]", scene_.source.directory()};
      const std::string type = module_type(spec);
      if (type.empty())
        throw ConfigError(context.key_path, "a module needs its type, e.g. 'diffusion:'");
      if (spec.where() != "local")
        throw ConfigError(
            context.key_path + ".where",
            "only 'local' modules are available in this build (got '" + spec.where() + "')");
      auto module = registry_.create(type, spec, context);
      module->initialize();
      modules.push_back(std::move(module));
    }
    tree_ = assemble_module_tree(s, std::move(modules), registry_.couplers());
    for (const TimedModule* m : tree_.modules) {
      BodyViews v;
      m->bodies(v);
      impl_->views.emplace_back(m->info().name, v);
    }
    if (!options_.bench) {
      impl_->directory =
          options_.output_directory.empty() ? s.output().directory() : options_.output_directory;
      std::filesystem::create_directories(impl_->directory);
    }
    impl_->probes = std::make_unique<ProbeSet>(s, impl_->views, impl_->directory);
  } catch (const SceneError&) {
    throw;
  } catch (const ConfigError& e) {
    throw SceneError(e.key_path(), scene_.source.format(e));
  }
  impl_->output.interval = s.output().interval();
  impl_->checkpoint.interval = s.checkpoint().interval();
  for (std::size_t k = 0; k < impl_->probes->size(); ++k)
    impl_->probe_schedules.push_back({impl_->probes->interval(k), 0});
}

RunSummary Simulation::run() {
  Impl& I = *impl_;
  const proto::Scene& s = scene_.scene;
  const double end = options_.end_time >= 0.0 ? options_.end_time : s.end_time();
  const bool files = !I.directory.empty();
  const bool vtp = files && s.output().vtp();
  const std::string fp = fingerprint(s);

  // Derived output fields are computed once per output time, only when something is written.
  double prepared_time = -INFINITY;
  long long prepared_steps = -1;
  auto prepare_output = [&](double t) {
    if (t == prepared_time && static_cast<long long>(I.steps) == prepared_steps) return;
    for (auto& m : tree_.roots) m->prepare_output();
    prepared_time = t;
    prepared_steps = static_cast<long long>(I.steps);
  };
  auto write_output = [&](double t) {
    if (!vtp) return;
    const auto start = Clock::now();
    prepare_output(t);
    std::size_t body = 0;
    auto write_body = [&](const auto& view) {
      if (I.pvds.size() <= body) {
        const std::string pvd =
            (std::filesystem::path(I.directory) / (view.particles->name() + ".pvd")).string();
        I.pvds.emplace_back(I.resume_time ? PvdCollection::resume(pvd, *I.resume_time)
                                          : std::make_unique<PvdCollection>(pvd),
                            view.particles);
      }
      std::ostringstream file;
      file << view.particles->name() << "_" << std::setw(6) << std::setfill('0') << I.output_index
           << ".vtp";
      write_vtp((std::filesystem::path(I.directory) / file.str()).string(), *view.particles);
      I.pvds[body].first->add(t, file.str());
      ++body;
    };
    for (const auto& [name, v] : I.views) {
      for (const auto& b : v.bodies2) write_body(b);
      for (const auto& b : v.bodies3) write_body(b);
    }
    ++I.output_index;
    I.output_seconds += seconds_since(start);
  };
  auto sample_probe = [&](std::size_t k, double t) {
    const auto start = Clock::now();
    prepare_output(t);
    I.probes->sample(k, t);
    I.output_seconds += seconds_since(start);
  };
  auto save_checkpoint = [&](const std::string& file) {
    proto::Checkpoint c;
    c.set_format_version(kCheckpointFormatVersion);
    c.set_scene_fingerprint(fp);
    c.set_time(I.time);
    c.set_step(I.steps);
    c.set_next_output(I.output.next);
    (*c.mutable_driver_scalars())["next_checkpoint"] = static_cast<double>(I.checkpoint.next);
    (*c.mutable_driver_scalars())["output_index"] = static_cast<double>(I.output_index);
    // By name: a restart from this checkpoint may list the probes in another order, or others.
    for (std::size_t k = 0; k < I.probe_schedules.size(); ++k)
      (*c.mutable_driver_scalars())[probe_schedule_key(I.probes->name(k))] =
          static_cast<double>(I.probe_schedules[k].next);
    for (const auto& m : tree_.roots) {
      StateRecord state;
      const ModuleInfo info = m->info();
      state.name = info.name;
      state.type = info.type;
      m->save(state);
      encode_state(state, *c.add_modules());
    }
    const auto start = Clock::now();
    write_checkpoint((std::filesystem::path(I.directory) / file).string(), c);
    I.output_seconds += seconds_since(start);
  };

  // Where to start: t = 0, or a checkpoint.
  bool restarted = false;
  if (!options_.restart_file.empty()) {
    const proto::Checkpoint c = read_checkpoint(options_.restart_file);
    if (c.scene_fingerprint() != fp)
      throw RuntimeError(options_.restart_file +
                         ": checkpoint was written for another scene "
                         "(its modules, resolution or domain differ)");
    const auto& roots = tree_.roots;
    if (static_cast<std::size_t>(c.modules_size()) != roots.size())
      throw RuntimeError(options_.restart_file + ": checkpoint has " +
                         std::to_string(c.modules_size()) + " modules, the scene " +
                         std::to_string(roots.size()));
    for (std::size_t k = 0; k < roots.size(); ++k) {
      const auto& ms = c.modules(static_cast<int>(k));
      if (ms.name() != roots[k]->info().name || ms.type() != roots[k]->info().type)
        throw RuntimeError(options_.restart_file + ": checkpoint module '" + ms.name() + "' (" +
                           ms.type() + ") does not match the scene's '" + roots[k]->info().name +
                           "'");
      roots[k]->load(decode_state(ms));
    }
    if (!(std::isfinite(c.time()) && c.time() >= 0.0))
      throw RuntimeError(options_.restart_file + ": checkpoint time " + json_number(c.time()) +
                         " is not a time");
    I.time = c.time();
    I.steps = c.step();
    I.output.next = c.next_output();
    // Schedule indices are stored as doubles: whole, non-negative and exact, or refused.
    auto index = [&](const std::string& key, double value) {
      if (!(value >= 0.0 && value <= 9007199254740992.0 && value == std::floor(value)))
        throw RuntimeError(options_.restart_file + ": checkpoint's " + key + " = " +
                           json_number(value) + " is not a schedule index");
      return static_cast<unsigned long long>(value);
    };
    auto scalar = [&](const std::string& key) {
      auto it = c.driver_scalars().find(key);
      return index(key, it == c.driver_scalars().end() ? 0.0 : it->second);
    };
    I.checkpoint.next = scalar("next_checkpoint");
    I.output_index = scalar("output_index");
    for (std::size_t k = 0; k < I.probe_schedules.size(); ++k) {
      Schedule& ps = I.probe_schedules[k];
      const auto it = c.driver_scalars().find(probe_schedule_key(I.probes->name(k)));
      if (it != c.driver_scalars().end()) {
        ps.next = index(it->first, it->second);
      } else {
        // A probe the checkpointed run did not have starts at its first sampling time after
        // the restart (on the output grid when it has no interval of its own).
        const double interval = ps.active() ? ps.interval : I.output.interval;
        ps.next = interval > 0.0 ? static_cast<unsigned long long>(
                                       std::floor(I.time / interval * (1.0 + 1e-12) + 1e-12)) +
                                       1
                                 : 0;
      }
    }
    restarted = true;
  }
  if (files) I.probes->open_files(restarted ? std::optional<double>(I.time) : std::nullopt);
  I.resume_time = restarted ? std::optional<double>(I.time) : std::nullopt;

  const double start_time = I.time;
  const unsigned long long start_steps = I.steps;
  const double tolerance = 1e-12 * std::max(1.0, end);
  // Fires every event due at time t (events on the grid at or before t); the final call also
  // writes the last state and probe values unless they were just written at this time.
  double last_output_time = -INFINITY;
  std::vector<double> last_probe_time(I.probe_schedules.size(), -INFINITY);
  auto fire_due = [&](double t, bool final) {
    bool output_due = false;
    while (I.output.active() && I.output.time() <= t + tolerance) {
      output_due = true;
      ++I.output.next;
    }
    if (output_due || (final && last_output_time != t)) {
      write_output(t);
      last_output_time = t;
    }
    for (std::size_t k = 0; k < I.probe_schedules.size(); ++k) {
      // A probe without its own interval samples on the output grid; its index counts there.
      Schedule& ps = I.probe_schedules[k];
      const double interval = ps.active() ? ps.interval : I.output.interval;
      bool due = false;
      while (interval > 0.0 && static_cast<double>(ps.next) * interval <= t + tolerance) {
        due = true;
        ++ps.next;
      }
      if (due || (last_probe_time[k] != t && (final || (interval == 0.0 && t == start_time)))) {
        sample_probe(k, t);
        last_probe_time[k] = t;
      }
    }
    // Checkpoints are saved after the schedules moved past t, so that a restart from one does not
    // fire the same events again.
    bool checkpoint_due = false;
    while (files && I.checkpoint.active() && I.checkpoint.time() <= t + tolerance) {
      checkpoint_due = true;
      ++I.checkpoint.next;
    }
    if (checkpoint_due && t > start_time) {
      std::ostringstream name;
      name << "checkpoint_" << std::setw(6) << std::setfill('0') << I.checkpoint.next - 1
           << ".ckpt";
      save_checkpoint(name.str());
    }
  };

  const HealthMonitor health(options_.health ? s.run().health_interval() : 0, s.has_domain());
  const std::vector<const Module*> leaves(tree_.modules.begin(), tree_.modules.end());
  if (health.enabled()) health.check(leaves, I.steps, I.time);

  const auto wall_start = Clock::now();
  const std::clock_t cpu_start = std::clock();
  if (!restarted) {
    if (!I.output.active()) {
      write_output(I.time);
      last_output_time = I.time;
    }
    fire_due(I.time, false);
  }

  const bool tty = isatty(STDERR_FILENO);
  const double progress_interval = tty ? 0.5 : s.run().progress_interval();
  auto last_progress = Clock::now();
  auto progress = [&](bool final) {
    if (!options_.progress) return;
    if (!final && seconds_since(last_progress) < progress_interval) return;
    last_progress = Clock::now();
    const double wall = seconds_since(wall_start);
    const double done = (I.time - start_time) / std::max(end - start_time, 1e-300);
    const double eta = done > 0 ? wall * (1.0 - done) / done : 0.0;
    std::ostringstream line;
    line << "t = " << std::setprecision(6) << I.time << " / " << end << "  steps " << I.steps
         << "  wall " << std::fixed << std::setprecision(1) << wall << " s  ETA " << eta << " s";
    if (tty)
      std::cerr << "\r" << line.str() << "   " << (final ? "\n" : "") << std::flush;
    else
      std::cerr << line.str() << "\n";
  };

  while (I.time < end - tolerance &&
         (options_.max_steps == 0 || I.steps - start_steps < options_.max_steps)) {
    double target = end;
    if (I.output.active()) target = std::min(target, I.output.time());
    if (I.checkpoint.active() && files) target = std::min(target, I.checkpoint.time());
    // Probes do not constrain the step: they sample at the end of the first step that reaches
    // their sampling time (and record that time), so a fine probe interval costs no extra steps.
    double stable = INFINITY;
    for (const auto& m : tree_.roots) stable = std::min(stable, m->max_dt());
    const double remaining = target - I.time;
    if (!(stable > 0.0) || std::isnan(stable))
      throw RuntimeError("time step is " + json_number(stable) + " at t = " + json_number(I.time));
    // Equal steps up to the next event instead of full steps and a sliver at the end.
    const double steps_to_target = std::ceil(remaining / stable * (1.0 - 1e-12));
    const double dt = steps_to_target <= 1.0 ? remaining : remaining / steps_to_target;
    const bool reaches_target = steps_to_target <= 1.0;
    for (auto& m : tree_.roots) m->advance(dt);
    I.time = reaches_target ? target : I.time + dt;
    ++I.steps;
    if (health.due(I.steps)) health.check(leaves, I.steps, I.time);
    fire_due(I.time, false);
    progress(false);
  }
  if (health.enabled()) health.check(leaves, I.steps, I.time);
  fire_due(I.time, true);
  if (files && s.checkpoint().at_end()) save_checkpoint("checkpoint_final.ckpt");
  progress(true);

  RunSummary summary;
  summary.scene = scene_.source.file();
  summary.dimension = s.dimension();
  summary.threads = I.threads;
  summary.start_time = start_time;
  summary.end_time = I.time;
  summary.steps = I.steps - start_steps;
  summary.wall_seconds = seconds_since(wall_start);
  summary.cpu_seconds = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  summary.output_seconds = I.output_seconds;
  summary.peak_memory_bytes = peak_resident_bytes();
  summary.output_directory = I.directory;
  for (const TimedModule* m : tree_.modules) {
    const ModuleInfo info = m->info();
    summary.modules.push_back({info.name, info.type, m->particle_count(), info.active_features,
                               m->advance_seconds(), info.statistics});
    summary.particles += m->particle_count();
  }
  for (std::size_t c = 0; c < tree_.couplers.size(); ++c) {
    const TimedModule* m = tree_.couplers[c];
    const ModuleInfo info = m->info();
    CouplerTiming timing{info.name, info.type, info.children, info.active_features};
    timing.advance_seconds = timing.own_seconds = m->advance_seconds();
    for (const TimedModule* child : tree_.children[c])
      timing.own_seconds -= child->advance_seconds();
    summary.couplers.push_back(std::move(timing));
  }
  summary.particle_steps_per_second =
      summary.wall_seconds > 0
          ? double(summary.particles) * double(summary.steps) / summary.wall_seconds
          : 0.0;
  if (vtp) summary.outputs.push_back("vtp");
  for (const auto& p : s.probes()) summary.outputs.push_back("probe:" + p.name());
  if (files && (I.checkpoint.active() || s.checkpoint().at_end()))
    summary.outputs.push_back("checkpoint");
  summary.probes = I.probes->last_values();
  if (files) {
    std::ofstream out(std::filesystem::path(I.directory) / "summary.json");
    out << summary.to_json();
  }
  return summary;
}

}  // namespace cosph
