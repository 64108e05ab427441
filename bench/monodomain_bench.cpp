// Monodomain building blocks, measured separately (node-steps per second): the reaction half
// steps (Aliev-Panfilov, QSS) and the diffusion step, in 2D and 3D from 1e4 to 1e6 particles.
// Numbers go to docs/PERFORMANCE.md; nothing asserts a time.
#include <benchmark/benchmark.h>

#include <random>

#include "bench_lattice.hpp"
#include "core/parallel.hpp"
#include "monodomain/ionic_model.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "operators/diffusion_operator.hpp"

namespace {

using namespace cosph;

template <int D>
struct Tissue {
  std::vector<Vec<D>> x;
  std::vector<double> V, w, volume;
  NeighbourList neighbours;
  ExplicitDiffusion<D> diffusion;

  explicit Tissue(std::size_t target) {
    const double dp = 0.01;
    x = bench::jittered_lattice<D>(target, dp, 0.0);
    volume.assign(x.size(), std::pow(dp, D));
    std::mt19937 rng(2);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (std::size_t i = 0; i < x.size(); ++i) {
      V.push_back(u(rng));
      w.push_back(0.5 * u(rng));
    }
    const Kernel kernel(KernelType::WendlandC2, D, 1.3 * dp);
    const Domain<D> domain;
    neighbours = build_inner_list<D>(x, kernel.support_radius(), domain);
    diffusion.setup(x, volume, neighbours, kernel, domain,
                    std::vector<Mat<D>>(x.size(), Mat<D>::Identity()), false, 0.5);
  }
};

template <int D>
void BM_ReactionStep(benchmark::State& state) {
  Tissue<D> t(static_cast<std::size_t>(state.range(0)));
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

template <int D>
void BM_DiffusionStep(benchmark::State& state) {
  Tissue<D> t(static_cast<std::size_t>(state.range(0)));
  const double dt = t.diffusion.stable_dt();
  for (auto _ : state) {
    t.diffusion.step(t.V, dt);
    benchmark::DoNotOptimize(t.V.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(t.V.size()));
}

}  // namespace

BENCHMARK(BM_ReactionStep<2>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_ReactionStep<3>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_DiffusionStep<2>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_DiffusionStep<3>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
