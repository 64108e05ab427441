// Throughput of the diffusion building blocks at several particle counts (particles per second):
// the kernel-correction matrix, the pair-weight precomputation and one explicit diffusion step.
// Numbers go to docs/PERFORMANCE.md; nothing here asserts a time.
#include <benchmark/benchmark.h>

#include <random>

#include "bench_lattice.hpp"
#include "kernels/kernel_correction.hpp"
#include "neighbour/cell_linked_list.hpp"
#include "operators/diffusion_operator.hpp"

namespace {

using namespace cosph;

template <int D>
struct Cloud {
  std::vector<Vec<D>> x;
  std::vector<double> V;
  Kernel kernel{KernelType::WendlandC2, D, 1.3 * 0.01};
  Domain<D> domain;
  NeighbourList neighbours;

  explicit Cloud(std::size_t target) {
    const double dp = 0.01;
    x = bench::jittered_lattice<D>(target, dp, 0.2);
    V.assign(x.size(), std::pow(dp, D));
    neighbours = build_inner_list<D>(x, kernel.support_radius(), domain);
  }
};

template <int D>
void BM_CorrectionMatrix(benchmark::State& state) {
  Cloud<D> c(static_cast<std::size_t>(state.range(0)));
  std::vector<Mat<D>> B;
  for (auto _ : state) {
    compute_correction_matrices<D>(c.x, c.V, c.neighbours, c.kernel, c.domain, B);
    benchmark::DoNotOptimize(B.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(c.x.size()));
}

template <int D>
void BM_DiffusionWeights(benchmark::State& state) {
  Cloud<D> c(static_cast<std::size_t>(state.range(0)));
  Mat<D> tensor = 1e-4 * Mat<D>::Identity();
  tensor(0, 0) = 1e-3;
  const std::vector<Mat<D>> tensors(c.x.size(), tensor);
  for (auto _ : state) {
    auto w = diffusion_pair_weights<D>(c.x, c.V, c.neighbours, c.kernel, c.domain, tensors, true);
    benchmark::DoNotOptimize(w.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(c.x.size()));
}

template <int D>
void BM_DiffusionStep(benchmark::State& state) {
  Cloud<D> c(static_cast<std::size_t>(state.range(0)));
  const std::vector<Mat<D>> tensors(c.x.size(), 1e-4 * Mat<D>::Identity());
  const auto w =
      diffusion_pair_weights<D>(c.x, c.V, c.neighbours, c.kernel, c.domain, tensors, false);
  std::vector<double> value(c.x.size()), rate;
  for (std::size_t i = 0; i < value.size(); ++i) value[i] = c.x[i][0];
  for (auto _ : state) {
    apply_diffusion(c.neighbours, w, value, rate);
    for (std::size_t i = 0; i < value.size(); ++i) value[i] += 1e-3 * rate[i];
    benchmark::DoNotOptimize(value.data());
  }
  state.counters["pairs_per_particle"] = double(c.neighbours.pair_count()) / double(c.x.size());
  state.SetItemsProcessed(state.iterations() * static_cast<long>(c.x.size()));
}

}  // namespace

BENCHMARK(BM_CorrectionMatrix<2>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CorrectionMatrix<3>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_DiffusionWeights<2>)
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
