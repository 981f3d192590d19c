// Sweep planning: cases, shards, and combination lists.
#include <gtest/gtest.h>

#include <set>

#include "common/error.h"
#include "tools/sweep/sweep_plan.h"

namespace chorus::sweep {
namespace {

TEST(SweepPlan, CasesCoverScenesTimesSortedSpp) {
  const auto cases = planCases({"a/room.gltf", "b/glass.glb", "c/room.gltf"}, {16, 4, 16});
  ASSERT_EQ(cases.size(), 6u);
  EXPECT_EQ(cases[0].scene, "a-room");
  EXPECT_EQ(cases[0].spp, 4);
  EXPECT_EQ(cases[1].spp, 16);
  EXPECT_EQ(cases[2].scene, "glass");
  EXPECT_EQ(cases[4].scene, "c-room");
  EXPECT_EQ(cases[5].fileStem(), "c-room_spp16");
}

TEST(SweepPlan, ShardsPartitionTheCases) {
  const auto cases = planCases({"x.gltf", "y.gltf", "z.gltf"}, {4, 8, 16, 32});
  std::multiset<std::string> seen;
  for (int i = 0; i < 5; ++i)
    for (const auto& c : casesOfShard(cases, parseShard(std::to_string(i) + "/5")))
      seen.insert(c.fileStem());
  EXPECT_EQ(seen.size(), cases.size());
  for (const auto& c : cases) EXPECT_EQ(seen.count(c.fileStem()), 1u);
  EXPECT_THROW(parseShard("5/5"), Error);
  EXPECT_THROW(parseShard("1"), Error);
  EXPECT_THROW(parseShard("-1/3"), Error);
  EXPECT_THROW(parseShard("a/b"), Error);
}

TEST(SweepPlan, AllCombinationsAreEverySubsetOfSizeTwoOrMore) {
  const auto combos = planCombinations({"a", "b", "c", "d"}, "all");
  // C(4,2) + C(4,3) + C(4,4) = 6 + 4 + 1
  ASSERT_EQ(combos.size(), 11u);
  EXPECT_EQ(combos.front(), "a+b");
  EXPECT_EQ(combos[1], "a+c");
  EXPECT_EQ(combos[5], "c+d");
  EXPECT_EQ(combos[6], "a+b+c");
  EXPECT_EQ(combos.back(), "a+b+c+d");
  EXPECT_EQ(std::set<std::string>(combos.begin(), combos.end()).size(), combos.size());
}

TEST(SweepPlan, ListedCombinationsAreCanonicalisedAndChecked) {
  const std::vector<std::string> methods = {"nfor", "nlm", "atrous"};
  EXPECT_EQ(planCombinations(methods, "atrous+nfor,nfor+nlm+atrous"),
            (std::vector<std::string>{"nfor+atrous", "nfor+nlm+atrous"}));
  EXPECT_THROW(planCombinations(methods, "nfor+sbf"), Error);
  EXPECT_THROW(planCombinations(methods, "nfor"), Error);
  EXPECT_THROW(planCombinations(methods, "nfor+nfor"), Error);
  EXPECT_TRUE(planCombinations(methods, "none").empty());
}

TEST(SweepPlan, IntLists) {
  EXPECT_EQ(parseIntList("4,8,16", "--spp"), (std::vector<int>{4, 8, 16}));
  EXPECT_THROW(parseIntList("4,,8", "--spp"), Error);
  EXPECT_THROW(parseIntList("4,-8", "--spp"), Error);
  EXPECT_THROW(parseIntList("x", "--spp"), Error);
}

TEST(SweepEta, LinearInSppOnceTwoSppAreKnown) {
  // Case time 1 s + 0.5 s per spp: the fit recovers it exactly.
  const std::vector<FinishedCase> finished = {{4, 3.0}, {16, 9.0}, {4, 3.0}};
  EXPECT_NEAR(estimateRemainingSeconds(finished, {64, 256}), (1 + 32) + (1 + 128), 1e-9);
  // One spp so far: the mean case time per remaining case.
  EXPECT_NEAR(estimateRemainingSeconds({{4, 2.0}, {4, 4.0}}, {8, 16}), 6.0, 1e-12);
  // Time falling with spp (noise) is not extrapolated below zero: slope 0, the mean.
  EXPECT_NEAR(estimateRemainingSeconds({{4, 5.0}, {8, 3.0}}, {1024}), 4.0, 1e-12);
  EXPECT_EQ(estimateRemainingSeconds({}, {4}), 0.0);
  EXPECT_EQ(estimateRemainingSeconds({{4, 1.0}}, {}), 0.0);
}

}  // namespace
}  // namespace chorus::sweep
