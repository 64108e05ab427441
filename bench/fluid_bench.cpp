// Throughput of the weakly-compressible fluid on the dam breaks of examples/fluid_dambreak_2d.yaml
// (Lobovsky's tank, H = 1) and examples/fluid_dambreak_3d.yaml at several resolutions: one
// advection step of the whole module (its acoustic sub-steps included), built from the scene as a
// user would. Separately, on the same particles, the neighbour search of one advection step
// (fluid-fluid and fluid-wall lists; static walls keep their cell list) and the cell sort done
// every 100 steps, so that performance.py can state their share of the step. Reports
// particle-steps per second and the heap memory per particle the module holds. Numbers go to
// docs/PERFORMANCE.md; nothing asserts a time.
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <string>

#include "driver/registry.hpp"
#include "module_catalogue.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "scene/scene_loader.hpp"

namespace {

using namespace cosph;

double heap_bytes() { return double(mallinfo2().uordblks) + double(mallinfo2().hblkhd); }

std::string scene_path(int dimension) {
  return std::string(COSPH_SOURCE_DIR) + "/examples/fluid_dambreak_" + std::to_string(dimension) +
         "d.yaml";
}

// The dam break at H / resolution, its module built and initialised.
struct DamBreak {
  LoadedScene scene;
  std::unique_ptr<Module> module;
  double memory = 0.0;
  DamBreak(int dimension, int resolution)
      : scene(load_scene_file(scene_path(dimension), {"modules[0].fluid.body.spacing=" +
                                                      std::to_string(1.0 / resolution)})) {
    const double before = heap_bytes();
    const ModuleContext context{&scene.scene, "modules[0]", COSPH_SOURCE_DIR "/examples"};
    module = builtin_modules().create("fluid", scene.scene.modules(0), context);
    module->initialize();
    memory = heap_bytes() - before;
  }
};

template <int D>
void BM_FluidDamBreakStep(benchmark::State& state) {
  DamBreak dam(D, static_cast<int>(state.range(0)));
  for (auto _ : state) dam.module->advance(dam.module->max_dt());
  const auto particles = static_cast<long>(dam.module->particle_count());
  state.SetItemsProcessed(state.iterations() * particles);
  state.counters["particles"] = double(particles);
  state.counters["bytes_per_particle"] = dam.memory / double(particles);
}

template <int D>
const BodyView<D>& body(const BodyViews& views, std::size_t k) {
  if constexpr (D == 2)
    return views.bodies2.at(k);
  else
    return views.bodies3.at(k);
}

// The searches of one advection step on the dam break's initial particles.
template <int D>
void BM_FluidNeighbourSearch(benchmark::State& state) {
  DamBreak dam(D, static_cast<int>(state.range(0)));
  BodyViews views;
  dam.module->bodies(views);
  const auto& fluid = body<D>(views, 0);
  const auto& walls = body<D>(views, 1);
  const auto& x = fluid.particles->vector("position");
  const double cutoff = fluid.kernel.support_radius();
  const CellLinkedList<D> wall_cells(walls.particles->vector("position"), cutoff, walls.domain);
  for (auto _ : state) {
    const NeighbourList inner = build_inner_list<D>(x, cutoff, fluid.domain);
    const NeighbourList contact = build_contact_list<D>(x, wall_cells, cutoff);
    benchmark::DoNotOptimize(inner.pair_count() + contact.pair_count());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(x.size()));
  state.counters["particles"] = double(dam.module->particle_count());
}

// One cell sort of the fluid (the order and the permutation of every field).
template <int D>
void BM_FluidCellSort(benchmark::State& state) {
  DamBreak dam(D, static_cast<int>(state.range(0)));
  BodyViews views;
  dam.module->bodies(views);
  const auto& fluid = body<D>(views, 0);
  ParticleSet<D> copy = *fluid.particles;
  const double cutoff = fluid.kernel.support_radius();
  for (auto _ : state) {
    const auto order = cell_sort_order<D>(copy.vector("position"), cutoff, fluid.domain);
    copy.permute(order);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(copy.size()));
  state.counters["particles"] = double(dam.module->particle_count());
}

}  // namespace

BENCHMARK(BM_FluidDamBreakStep<2>)
    ->Arg(20)
    ->Arg(40)
    ->Arg(80)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FluidNeighbourSearch<2>)
    ->Arg(20)
    ->Arg(40)
    ->Arg(80)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FluidCellSort<2>)
    ->Arg(20)
    ->Arg(40)
    ->Arg(80)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FluidDamBreakStep<3>)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FluidNeighbourSearch<3>)
    ->Arg(10)
    ->Arg(20)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_FluidCellSort<3>)->Arg(10)->Arg(20)->Unit(benchmark::kMillisecond)->UseRealTime();

BENCHMARK_MAIN();
