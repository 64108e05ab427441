// Monodomain reaction step (node-steps per second): both QSS half steps of Aliev-Panfilov, from
// 1e4 to 1e6 particles. The diffusion step it is paired with is measured on its own in
// diffusion_bench (BM_DiffusionStep): the two are benchmarked separately.
// Numbers go to docs/PERFORMANCE.md; nothing asserts a time.
#include <benchmark/benchmark.h>

#include <random>

#include "core/parallel.hpp"
#include "monodomain/ionic_model.hpp"

namespace {

using namespace cosph;

// Random states of `count` cells (the reaction step is local: no geometry needed).
struct Cells {
  std::vector<double> V, w;
  explicit Cells(std::size_t count) {
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < count; ++i) {
      V.push_back(u(rng));
      w.push_back(0.5 * u(rng));
    }
  }
};

void BM_ReactionStep(benchmark::State& state) {
  Cells t(static_cast<std::size_t>(state.range(0)));
  const AlievPanfilov model{proto::AlievPanfilovSpec()};
  const double half = 0.5 * 1e-4;
  for (auto _ : state) {
    parallel_for_each_index(t.V.size(), [&](std::size_t i) {
      react_before_diffusion(model, t.V[i], t.w[i], half);
      react_after_diffusion(model, t.V[i], t.w[i], half);
    });
    benchmark::DoNotOptimize(t.V.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(t.V.size()));
}

}  // namespace

// The reaction is local to each particle: its cost does not depend on the dimension.
BENCHMARK(BM_ReactionStep)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
