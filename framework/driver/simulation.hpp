// The driver: builds the scene's modules, advances them to the end time, writes output, probes
// and checkpoints on a fixed schedule of simulated times, reports progress, and returns a run
// summary. It knows modules only through the Module contract.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "driver/module.hpp"
#include "driver/module_tree.hpp"
#include "driver/registry.hpp"
#include "scene/scene_loader.hpp"

namespace cosph {

struct RunOptions {
  int threads = 0;                   // 0: the scene's run.threads, else all cores
  std::string restart_file;          // continue from this checkpoint
  std::string output_directory;      // overrides output.directory
  bool bench = false;                // no files at all: steps and throughput only
  bool progress = true;              // progress line on stderr
  double end_time = -1.0;            // < 0: the scene's end_time (tests stop early with it)
  unsigned long long max_steps = 0;  // > 0: stop after this many steps (smoke runs), as at the end
  bool health = true;                // run the health monitor (every run.health_interval steps)
};

struct ModuleTiming {
  std::string name;
  std::string type;
  std::size_t particles = 0;
  std::vector<std::string> features;
  double advance_seconds = 0.0;
  std::map<std::string, double> statistics;
};

// A coupler's time: its whole step, and its own share (exchange and mapping: the step less its
// children's advance times).
struct CouplerTiming {
  std::string name;
  std::string type;
  std::vector<std::string> children;
  std::vector<std::string> features;
  double advance_seconds = 0.0;
  double own_seconds = 0.0;
};

struct RunSummary {
  std::string scene;
  int dimension = 0;
  int threads = 0;
  double start_time = 0.0;
  double end_time = 0.0;
  unsigned long long steps = 0;
  double wall_seconds = 0.0;
  double cpu_seconds = 0.0;
  double output_seconds = 0.0;
  double peak_memory_bytes = 0.0;  // the process's peak resident set (getrusage ru_maxrss)
  std::size_t particles = 0;
  double particle_steps_per_second = 0.0;
  std::vector<ModuleTiming> modules;
  std::vector<CouplerTiming> couplers;
  std::vector<std::string> outputs;  // what was written: "vtp", "probe:<name>", "checkpoint"
  std::string output_directory;
  std::map<std::string, std::map<std::string, double>> probes;

  std::string to_json() const;
};

class Simulation {
 public:
  Simulation(LoadedScene scene, const ModuleRegistry& registry, RunOptions options);
  ~Simulation();

  // Builds and initialises the modules; ConfigErrors are rethrown as SceneErrors with file/line.
  void initialize();
  RunSummary run();

  // For tests: the scene's modules in scene order (coupled or not), and its couplers.
  Module& module(std::size_t k) { return *tree_.modules[k]; }
  std::size_t module_count() const { return tree_.modules.size(); }
  Module& coupler(std::size_t k) { return *tree_.couplers[k]; }
  std::size_t coupler_count() const { return tree_.couplers.size(); }
  const LoadedScene& scene() const { return scene_; }

 private:
  struct Impl;
  LoadedScene scene_;
  const ModuleRegistry& registry_;
  RunOptions options_;
  ModuleTree tree_;  // the roots the driver advances, over every module and coupler
  std::unique_ptr<Impl> impl_;
};

}  // namespace cosph
