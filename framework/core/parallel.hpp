// Thin wrappers over oneTBB that keep results independent of the number of threads: loops write
// only their own index, and reductions combine fixed-size blocks in a fixed order.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cstddef>

namespace cosph {

// Indices per task. Pair loops (tens of neighbours per index) split at kPairGrain; streaming
// updates (a few flops per index: x += dt v) at kStreamGrain, below which a fork and join costs
// more than the loop: a body of a few hundred particles sub-stepped thousands of times per fluid
// step (FSI) ran slower on 2 threads than on 1 when every loop forked.
inline constexpr std::size_t kPairGrain = 256;
inline constexpr std::size_t kStreamGrain = 8192;

// Pairs a task of a pair loop should hold to pay for its fork and join (about 10 us of work;
// oneTBB halves a range while it is longer than the grain, so a task holds half to all of it).
// A solid of a few hundred particles (8,000 pairs) sub-stepped half a million times in an FSI run
// is faster on the calling thread alone: the 416-particle hydrostatic plate's whole run took 13%
// less wall time with its pair loops unsplit.
inline constexpr std::size_t kPairsPerTask = 16384;

// The grain of a pair loop over n indices with `pairs` pairs in all: kPairsPerTask pairs' worth of
// indices, never finer than kPairGrain; a loop of fewer pairs is not split.
inline std::size_t pair_loop_grain(std::size_t n, std::size_t pairs) {
  if (pairs == 0) return kPairGrain;
  return std::max(kPairGrain, (kPairsPerTask * n + pairs - 1) / pairs);
}

// Calls body(i) for i in [0, n). body must write only data owned by i (gather, no atomics).
// Loops no longer than one grain run on the calling thread.
template <typename Body>
void parallel_for_each_index(std::size_t n, const Body& body, std::size_t grain = kPairGrain) {
  if (n <= grain) {
    for (std::size_t i = 0; i < n; ++i) body(i);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, grain),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                    });
}

// The same for streaming updates.
template <typename Body>
void parallel_stream(std::size_t n, const Body& body) {
  parallel_for_each_index(n, body, kStreamGrain);
}

// Deterministic sum of value(i) over [0, n): the block boundaries and the combination order do
// not depend on the thread count, so the result is bit-identical with 1 or many threads.
template <typename T, typename Value>
T deterministic_sum(std::size_t n, T zero, const Value& value) {
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, n, 1024), zero,
      [&](const tbb::blocked_range<std::size_t>& r, T acc) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) acc += value(i);
        return acc;
      },
      [](T a, const T& b) { return T(a + b); });
}

}  // namespace cosph
