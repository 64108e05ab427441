#include "cli.hpp"

#include <cmath>
#include <iostream>

#include "core/error.hpp"
#include "driver/simulation.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace cosph {

namespace {

const char* const kUsage = R"(cosph - co-simulation of SPH physics modules

usage:
  cosph run SCENE.yaml [options]     run a scene to its end time
  cosph check SCENE.yaml [--set ...] validate a scene (and build its particles) without running
  cosph help                         this text

options of run:
  --set key.path=value   override a scene value (repeatable), e.g.
                         --set modules[0].diffusion.body.spacing=0.005
  --threads N            number of threads (default: run.threads, else all cores)
  --output DIR           output directory (default: output.directory, relative to the scene)
  --restart FILE         continue from a checkpoint file
  --bench                write no files; print steps and particle-steps per second
  --end-time T           stop at T instead of the scene's end_time
  --steps N              stop after N steps (a smoke run: output, probes and summary as at the end)
  --health on|off        health monitor (default on, every run.health_interval steps): stops a
                         run whose values turn non-finite or leave their physical bounds
  --quiet                no progress line
)";

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Arguments {
  std::string command, scene;
  std::vector<std::string> overrides;
  RunOptions options;
};

Arguments parse(const std::vector<std::string>& args) {
  Arguments a;
  if (args.empty()) throw UsageError("no command given");
  a.command = args[0];
  for (std::size_t k = 1; k < args.size(); ++k) {
    const std::string& s = args[k];
    auto value = [&]() -> std::string {
      if (k + 1 >= args.size()) throw UsageError(s + " needs a value");
      return args[++k];
    };
    auto number = [&](const std::string& text, const std::string& option) {
      try {
        std::size_t used = 0;
        const double v = std::stod(text, &used);
        if (used != text.size()) throw std::invalid_argument("");
        return v;
      } catch (const std::exception&) {
        throw UsageError(option + " expects a number, got '" + text + "'");
      }
    };
    if (s == "--set") {
      a.overrides.push_back(value());
    } else if (s.rfind("--set=", 0) == 0) {
      a.overrides.push_back(s.substr(6));
    } else if (s == "--threads") {
      const double n = number(value(), "--threads");
      if (n < 1 || n != std::floor(n)) throw UsageError("--threads expects a positive integer");
      a.options.threads = static_cast<int>(n);
    } else if (s == "--output") {
      a.options.output_directory = value();
    } else if (s == "--restart") {
      a.options.restart_file = value();
    } else if (s == "--bench") {
      a.options.bench = true;
    } else if (s == "--health") {
      const std::string v = value();
      if (v != "on" && v != "off") throw UsageError("--health expects on or off, got '" + v + "'");
      a.options.health = v == "on";
    } else if (s == "--quiet") {
      a.options.progress = false;
    } else if (s == "--end-time") {
      a.options.end_time = number(value(), "--end-time");
      if (!(a.options.end_time > 0)) throw UsageError("--end-time must be positive");
    } else if (s == "--steps") {
      const double n = number(value(), "--steps");
      if (n < 1 || n != std::floor(n)) throw UsageError("--steps expects a positive integer");
      a.options.max_steps = static_cast<unsigned long long>(n);
    } else if (!s.empty() && s[0] == '-') {
      throw UsageError("unknown option '" + s + "'");
    } else if (a.scene.empty()) {
      a.scene = s;
    } else {
      throw UsageError("unexpected argument '" + s + "'");
    }
  }
  return a;
}

}  // namespace

int run_cli(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  Arguments a;
  try {
    a = parse(args);
    if (a.command == "help" || a.command == "--help" || a.command == "-h") {
      out << kUsage;
      return 0;
    }
    if (a.command != "run" && a.command != "check")
      throw UsageError("unknown command '" + a.command + "'");
    if (a.scene.empty()) throw UsageError(a.command + " needs a scene file");
  } catch (const UsageError& e) {
    err << "cosph: " << e.what() << "\n\n" << kUsage;
    return 2;
  }

  try {
    LoadedScene scene = load_scene_file(a.scene, a.overrides);
    if (a.command == "check") {
      RunOptions options = a.options;
      options.bench = true;
      Simulation simulation(std::move(scene), builtin_modules(), options);
      simulation.initialize();
      std::size_t particles = 0;
      for (std::size_t k = 0; k < simulation.module_count(); ++k)
        particles += simulation.module(k).particle_count();
      out << a.scene << ": ok (" << simulation.module_count() << " module(s), " << particles
          << " particles)\n";
      return 0;
    }
    Simulation simulation(std::move(scene), builtin_modules(), a.options);
    simulation.initialize();
    const RunSummary summary = simulation.run();
    out << "steps " << summary.steps << "  particles " << summary.particles << "  wall "
        << summary.wall_seconds << " s  particle-steps/s " << summary.particle_steps_per_second
        << "  peak memory " << summary.peak_memory_bytes / 1048576.0 << " MiB\n";
    for (const auto& m : summary.modules) {
      out << "module " << m.name << " (" << m.type << "):";
      for (const auto& f : m.features) out << " [" << f << "]";
      out << "  advance " << m.advance_seconds << " s\n";
    }
    for (const auto& c : summary.couplers) {
      out << "coupler " << c.name << " (" << c.type << "):";
      for (const auto& f : c.features) out << " [" << f << "]";
      out << "  own " << c.own_seconds << " s of " << c.advance_seconds << " s\n";
    }
    if (!a.options.bench) {
      out << "output: " << summary.output_directory << "/ (summary.json";
      for (const auto& o : summary.outputs) {
        if (o == "vtp") out << ", *.pvd + *.vtp";
        if (o == "checkpoint") out << ", *.ckpt";
        if (o.rfind("probe:", 0) == 0) out << ", " << o.substr(6) << ".csv";
      }
      out << ")\n";
    }
    return 0;
  } catch (const SceneError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const ConfigError& e) {
    err << a.scene << ": " << e.key_path() << ": " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "cosph: error: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace cosph
