// ParticleSet: named structure-of-arrays fields with metadata, stable storage, permutation.
#include "core/particles.hpp"

#include <gtest/gtest.h>

namespace cosph {
namespace {

TEST(ParticleSet, FieldsAreZeroInitialisedAndKeepTheirFlags) {
  ParticleSet<3> p("body");
  p.resize(4);
  auto& x = p.add_vector("position", {.output = true});
  auto& m = p.add_scalar("mass", {.checkpoint = true});
  auto& F = p.add_matrix("deformation_gradient", {.output = true, .checkpoint = true});
  EXPECT_EQ(p.size(), 4u);
  EXPECT_EQ(p.field_count(), 3u);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(x[i], Vec<3>::Zero());
    EXPECT_EQ(m[i], 0.0);
    EXPECT_EQ(F[i], Mat<3>::Zero());
  }
  EXPECT_TRUE(p.info("position").flags.output);
  EXPECT_FALSE(p.info("position").flags.checkpoint);
  EXPECT_TRUE(p.info("mass").flags.checkpoint);
  EXPECT_EQ(p.info("deformation_gradient").kind, FieldKind::Matrix);
  EXPECT_EQ(p.raw("deformation_gradient").size(), 4u * 9u);
}

TEST(ParticleSet, ReferencesStayValidWhenMoreFieldsAreRegistered) {
  ParticleSet<2> p;
  p.resize(100);
  auto& first = p.add_scalar("a");
  first[7] = 3.5;
  for (int k = 0; k < 50; ++k) p.add_vector("v" + std::to_string(k));
  EXPECT_EQ(first[7], 3.5);
  EXPECT_EQ(&first, &p.scalar("a"));
}

TEST(ParticleSet, RegisteringAgainMergesFlagsAndAnotherKindIsAnError) {
  ParticleSet<2> p;
  p.add_scalar("c", {.output = true});
  p.add_scalar("c", {.exchange = true});
  EXPECT_TRUE(p.info("c").flags.output);
  EXPECT_TRUE(p.info("c").flags.exchange);
  EXPECT_THROW(p.add_vector("c"), std::logic_error);
  EXPECT_THROW(p.vector("c"), std::logic_error);
  EXPECT_THROW(p.scalar("missing"), std::out_of_range);
}

TEST(ParticleSet, RawViewIsContiguousComponentsPerParticle) {
  ParticleSet<2> p;
  p.resize(3);
  auto& v = p.add_vector("velocity");
  v[1] = Vec<2>(4.0, 5.0);
  auto raw = p.raw("velocity");
  ASSERT_EQ(raw.size(), 6u);
  EXPECT_EQ(raw[2], 4.0);
  EXPECT_EQ(raw[3], 5.0);
}

TEST(ParticleSet, PermuteReordersEveryFieldConsistently) {
  ParticleSet<2> p;
  p.resize(4);
  auto& id = p.add_scalar("id");
  auto& x = p.add_vector("position");
  auto& M = p.add_matrix("B");
  for (std::size_t i = 0; i < 4; ++i) {
    id[i] = double(i);
    x[i] = Vec<2>(double(i), -double(i));
    M[i] = double(i) * Mat<2>::Identity();
  }
  p.permute({2, 0, 3, 1});
  const double expected[] = {2, 0, 3, 1};
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(id[i], expected[i]);
    EXPECT_EQ(x[i], Vec<2>(expected[i], -expected[i]));
    EXPECT_EQ(M[i], expected[i] * Mat<2>::Identity());
  }
  EXPECT_THROW(p.permute({0, 1}), std::logic_error);
}

TEST(ParticleSet, ResizeKeepsValuesAndZeroesNewEntries) {
  ParticleSet<3> p;
  p.resize(2);
  auto& x = p.add_vector("position");
  x[1] = Vec<3>(1, 2, 3);
  p.resize(5);
  EXPECT_EQ(x[1], Vec<3>(1, 2, 3));
  EXPECT_EQ(x[4], Vec<3>::Zero());
}

}  // namespace
}  // namespace cosph
