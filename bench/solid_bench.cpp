// Throughput of one 3D total-Lagrangian solid step (position Verlet, neo-Hookean, no optional
// forces) at 1e4, 1e5 and 1e6 particles: the whole module's advance, built from a scene as a user
// would. Reports particle-steps per second and the heap memory per particle the module holds.
// Numbers go to docs/PERFORMANCE.md; nothing asserts a time.
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <cmath>
#include <string>

#include "driver/registry.hpp"
#include "module_catalogue.hpp"
#include "scene/scene_loader.hpp"

namespace {

using namespace cosph;

// Heap bytes in use (glibc's allocator statistics): the difference around building the module
// is what its particles, pairs and work arrays hold, independent of pages the allocator keeps.
double heap_bytes() { return double(mallinfo2().uordblks) + double(mallinfo2().hblkhd); }

// A cube of about `target` particles (spacing 0.01), neo-Hookean, swinging with a shear velocity.
std::string cube_scene(std::size_t target) {
  const int n = static_cast<int>(std::round(std::cbrt(double(target))));
  const double side = 0.01 * n;
  return "dimension: 3\nend_time: 1\nmodules:\n  - name: cube\n    solid:\n      body:\n"
         "        spacing: 0.01\n        shape: {box: {lower: [0, 0, 0], upper: [" +
         std::to_string(side) + ", " + std::to_string(side) + ", " + std::to_string(side) +
         "]}}\n      material: {density: 1000, neo_hookean: {young: 1.0e6, poisson: 0.3}}\n"
         "      initial_velocity: [\"0.1 * z\", \"0\", \"0\"]\n";
}

void BM_SolidStep3D(benchmark::State& state) {
  const auto scene =
      load_scene_text(cube_scene(static_cast<std::size_t>(state.range(0))), "solid_bench.yaml");
  const double before = heap_bytes();
  const ModuleContext context{&scene.scene, "modules[0]", "."};
  auto module = builtin_modules().create("solid", scene.scene.modules(0), context);
  module->initialize();
  const double memory = heap_bytes() - before;
  const double dt = module->max_dt();
  for (auto _ : state) module->advance(dt);
  const auto particles = static_cast<long>(module->particle_count());
  state.SetItemsProcessed(state.iterations() * particles);
  state.counters["particles"] = double(particles);
  state.counters["bytes_per_particle"] = memory / double(particles);
}

}  // namespace

BENCHMARK(BM_SolidStep3D)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
