// Thin wrappers over oneTBB that keep results independent of the number of threads: loops write
// only their own index, and reductions combine fixed-size blocks in a fixed order.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <cstddef>

namespace cosph {

// Calls body(i) for i in [0, n). body must write only data owned by i (gather, no atomics).
template <typename Body>
void parallel_for_each_index(std::size_t n, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 256),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
                    });
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
