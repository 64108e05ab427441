// Neighbour-search throughput at growing particle counts: the cost per particle must stay flat
// (linear total cost). Reported as particles per second; no assertions here, docs/PERFORMANCE.md
// records the numbers.
#include <benchmark/benchmark.h>

#include <random>

#include "bench_lattice.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace {

template <int D>
std::vector<cosph::Vec<D>> lattice(std::size_t target, double dp) {
  return cosph::bench::jittered_lattice<D>(target, dp, 0.1);
}

template <int D>
void BM_InnerNeighbourList(benchmark::State& state) {
  const double dp = 0.01, cutoff = 2.6 * dp;  // Wendland C2 with h = 1.3 dp
  const auto x = lattice<D>(static_cast<std::size_t>(state.range(0)), dp);
  cosph::Domain<D> domain;
  std::size_t pairs = 0;
  for (auto _ : state) {
    auto list = cosph::build_inner_list<D>(x, cutoff, domain);
    pairs = list.pair_count();
    benchmark::DoNotOptimize(list.index.data());
  }
  state.counters["particles"] = double(x.size());
  state.counters["pairs_per_particle"] = double(pairs) / double(x.size());
  state.SetItemsProcessed(state.iterations() * static_cast<long>(x.size()));
}

template <int D>
void BM_CellSort(benchmark::State& state) {
  const double dp = 0.01;
  auto x = lattice<D>(static_cast<std::size_t>(state.range(0)), dp);
  std::shuffle(x.begin(), x.end(), std::mt19937(3));
  cosph::Domain<D> domain;
  for (auto _ : state) {
    auto order = cosph::cell_sort_order<D>(x, 2.6 * dp, domain);
    benchmark::DoNotOptimize(order.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(x.size()));
}

}  // namespace

BENCHMARK(BM_InnerNeighbourList<2>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_InnerNeighbourList<3>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_CellSort<3>)
    ->RangeMultiplier(10)
    ->Range(10000, 1000000)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

BENCHMARK_MAIN();
