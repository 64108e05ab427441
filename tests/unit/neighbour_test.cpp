// Cell-linked-list neighbour search against brute force, and the cell sort.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "core/error.hpp"
#include "neighbour/cell_linked_list.hpp"

namespace cosph {
namespace {

template <int D>
std::vector<Vec<D>> random_cloud(std::size_t n, const Vec<D>& lo, const Vec<D>& hi, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Vec<D>> x(n);
  for (auto& p : x)
    for (int a = 0; a < D; ++a) p[a] = lo[a] + u(rng) * (hi[a] - lo[a]);
  return x;
}

template <int D>
void expect_same_sets(const NeighbourList& a, const NeighbourList& b) {
  ASSERT_EQ(a.particle_count(), b.particle_count());
  ASSERT_EQ(a.pair_count(), b.pair_count());
  for (std::size_t i = 0; i < a.particle_count(); ++i) {
    std::set<Index> sa(a.of(i).begin(), a.of(i).end()), sb(b.of(i).begin(), b.of(i).end());
    ASSERT_EQ(sa, sb) << "particle " << i;
    ASSERT_EQ(sa.size(), a.of(i).size()) << "duplicate neighbour of particle " << i;
  }
}

template <int D>
void check_inner(bool periodic) {
  Domain<D> domain;
  domain.lower = Vec<D>::Zero();
  domain.upper = Vec<D>::Constant(1.0);
  domain.upper[0] = 1.7;
  if (periodic) domain.periodic.fill(true);
  const std::size_t n = D == 2 ? 3000 : 4000;
  auto x = random_cloud<D>(n, domain.lower, domain.upper, 7 + D);
  const double cutoff = D == 2 ? 0.06 : 0.12;
  auto cells = build_inner_list<D>(x, cutoff, domain);
  auto brute = brute_force_list<D>(x, x, cutoff, domain, true);
  expect_same_sets<D>(cells, brute);
  EXPECT_GT(cells.pair_count(), n * 5);  // the test is not vacuous
}

TEST(NeighbourSearch, InnerListEqualsBruteForce2D) { check_inner<2>(false); }
TEST(NeighbourSearch, InnerListEqualsBruteForce3D) { check_inner<3>(false); }
TEST(NeighbourSearch, PeriodicInnerListEqualsBruteForce2D) { check_inner<2>(true); }
TEST(NeighbourSearch, PeriodicInnerListEqualsBruteForce3D) { check_inner<3>(true); }

TEST(NeighbourSearch, MixedPeriodicAxesEqualBruteForce) {
  Domain<2> domain;
  domain.lower = Vec<2>(-0.5, 0.0);
  domain.upper = Vec<2>(0.5, 2.0);
  domain.periodic = {true, false};
  auto x = random_cloud<2>(2500, domain.lower, domain.upper, 3);
  expect_same_sets<2>(build_inner_list<2>(x, 0.07, domain),
                      brute_force_list<2>(x, x, 0.07, domain, true));
}

TEST(NeighbourSearch, ContactListEqualsBruteForceWithLargerCutoff) {
  Domain<3> domain;
  auto a = random_cloud<3>(1500, Vec<3>::Zero(), Vec<3>::Constant(1.0), 11);
  auto b = random_cloud<3>(2500, Vec<3>(0.5, 0.2, -0.3), Vec<3>(1.6, 0.9, 0.8), 12);
  const double h_fluid = 0.05, h_solid = 0.025;  // the larger smoothing length governs
  const double cutoff = 2.0 * std::max(h_fluid, h_solid);
  expect_same_sets<3>(build_contact_list<3>(a, b, cutoff, domain),
                      brute_force_list<3>(a, b, cutoff, domain, false));
}

TEST(NeighbourSearch, ListIsIdenticalWhateverTheInputClustering) {
  // Sparse cloud in a big box: the cell list widens its cells but stays exact.
  Domain<2> domain;
  auto x = random_cloud<2>(400, Vec<2>::Zero(), Vec<2>::Constant(1000.0), 5);
  x.push_back(Vec<2>(0.01, 0.01));
  x.push_back(Vec<2>(0.02, 0.01));
  expect_same_sets<2>(build_inner_list<2>(x, 60.0, domain),
                      brute_force_list<2>(x, x, 60.0, domain, true));
}

TEST(NeighbourSearch, PeriodicAxisShorterThanThreeCutoffsIsRejected) {
  Domain<2> domain;
  domain.upper = Vec<2>(0.25, 1.0);
  domain.periodic = {true, false};
  auto x = random_cloud<2>(50, domain.lower, domain.upper, 1);
  // A ConfigError naming the scene key: a std::invalid_argument escaped scene_fuzz's run of a
  // Taylor-Green scene with a coarse spacing.
  try {
    build_inner_list<2>(x, 0.1, domain);
    ADD_FAILURE() << "a period of 0.25 with a cut-off of 0.1 was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key_path(), "domain.periodic");
    EXPECT_NE(std::string(e.what()).find("shorter than three cut-off radii"), std::string::npos);
  }
}

// Regression (found by the checkpoint fuzz target under UBSan): a NaN first position made the
// grid's bounds NaN and its cell count an undefined conversion. Non-finite positions (a run
// blowing up before the health monitor's next check) now have no neighbours and leave the list
// of the finite ones as brute force gives it.
TEST(NeighbourSearch, NonFinitePositionsDoNotBreakTheGrid) {
  Domain<2> domain;
  domain.upper = Vec<2>(1.0, 1.0);
  auto x = random_cloud<2>(500, domain.lower, domain.upper, 3);
  x[0] = Vec<2>(std::nan(""), 0.5);
  x[1] = Vec<2>(INFINITY, -INFINITY);
  const auto cells = build_inner_list<2>(x, 0.08, domain);
  EXPECT_EQ(cells.of(0).size(), 0u);
  EXPECT_EQ(cells.of(1).size(), 0u);
  const std::vector<Vec<2>> finite(x.begin() + 2, x.end());
  const auto brute = brute_force_list<2>(finite, finite, 0.08, domain, true);
  for (std::size_t i = 2; i < x.size(); ++i) {
    std::set<Index> got, want;
    for (Index j : cells.of(i)) got.insert(j - 2);
    for (Index j : brute.of(i - 2)) want.insert(j);
    ASSERT_EQ(got, want) << "particle " << i;
  }
  EXPECT_GT(brute.pair_count(), 500u);
}

TEST(NeighbourSearch, CellSortGroupsParticlesByCellAndIsAPermutation) {
  Domain<3> domain;
  auto x = random_cloud<3>(5000, Vec<3>::Zero(), Vec<3>::Constant(1.0), 9);
  const double cell = 0.1;
  auto order = cell_sort_order<3>(x, cell, domain);
  std::vector<Index> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 0; i < sorted.size(); ++i) ASSERT_EQ(sorted[i], i);
  // Consecutive particles in the new order are close: mean step much shorter than random.
  double step = 0.0;
  for (std::size_t k = 1; k < order.size(); ++k) step += (x[order[k]] - x[order[k - 1]]).norm();
  step /= order.size() - 1;
  EXPECT_LT(step, 0.2);  // random order gives about 0.66 in a unit cube
}

}  // namespace
}  // namespace cosph
