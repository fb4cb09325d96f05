#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {
namespace {

ScenarioOptions options(ScenarioVariant variant, int m = 8) {
  return {.seed = 11, .count = m, .horizon = 20, .noise_dim = 3, .initial_noise_dim = 2, .variant = variant};
}

std::vector<double> all_numbers(const ScenarioSet& set) {
  std::vector<double> out;
  std::vector<double> buffer(static_cast<std::size_t>(std::max(set.noise_dim(), set.initial_noise_dim())));
  for (int i = 0; i < set.size(); ++i) {
    set.initial_noise(i, std::span<double>(buffer.data(), static_cast<std::size_t>(set.initial_noise_dim())));
    out.insert(out.end(), buffer.begin(), buffer.begin() + set.initial_noise_dim());
    for (int t = 0; t < set.horizon(); ++t) {
      set.step_noise(i, t, std::span<double>(buffer.data(), static_cast<std::size_t>(set.noise_dim())));
      out.insert(out.end(), buffer.begin(), buffer.begin() + set.noise_dim());
    }
  }
  return out;
}

TEST(ScenarioSet, SameSeedGivesIdenticalNumbersAndAnotherSeedDifferent) {
  for (auto v : {ScenarioVariant::kPlain, ScenarioVariant::kAntithetic, ScenarioVariant::kStratified,
                 ScenarioVariant::kSobol}) {
    auto a = all_numbers(ScenarioSet(options(v)));
    auto b = all_numbers(ScenarioSet(options(v)));
    auto other = options(v);
    other.seed = 12;
    EXPECT_EQ(a, b) << to_string(v);
    EXPECT_NE(a, all_numbers(ScenarioSet(other))) << to_string(v);
    for (double u : a) {
      ASSERT_GT(u, 0.0);
      ASSERT_LT(u, 1.0);
    }
  }
}

TEST(ScenarioSet, ScenarioNumbersDoNotDependOnHowManyScenariosExist) {
  // Random access: scenario 3's noise is the same whether the set has 4 or 40 scenarios (plain variant).
  ScenarioSet small(options(ScenarioVariant::kPlain, 4)), large(options(ScenarioVariant::kPlain, 40));
  std::vector<double> a(3), b(3);
  for (int t = 0; t < 20; ++t) {
    small.step_noise(3, t, a);
    large.step_noise(3, t, b);
    EXPECT_EQ(a, b);
  }
}

TEST(ScenarioSet, AntitheticPairsMirrorEveryUniform) {
  ScenarioSet set(options(ScenarioVariant::kAntithetic));
  std::vector<double> a(3), b(3);
  for (int pair = 0; pair < 4; ++pair)
    for (int t = 0; t < 20; ++t) {
      set.step_noise(2 * pair, t, a);
      set.step_noise(2 * pair + 1, t, b);
      for (int j = 0; j < 3; ++j)
        EXPECT_DOUBLE_EQ(a[static_cast<std::size_t>(j)] + b[static_cast<std::size_t>(j)], 1.0);
    }
}

TEST(ScenarioSet, StratifiedInitialNoisePutsOneScenarioInEachStratum) {
  const int m = 16;
  ScenarioSet set(options(ScenarioVariant::kStratified, m));
  for (int dim = 0; dim < 2; ++dim) {
    std::vector<int> hits(m, 0);
    std::vector<double> p0(2);
    for (int i = 0; i < m; ++i) {
      set.initial_noise(i, p0);
      ++hits[static_cast<std::size_t>(p0[static_cast<std::size_t>(dim)] * m)];
    }
    for (int h : hits) EXPECT_EQ(h, 1);
  }
}

TEST(ScenarioSet, SobolPointsCoverTheCubeMoreEvenlyThanRandomPoints) {
  // With m = 64 points, every one of the 8 equal bins of a coordinate holds exactly 8 Sobol points
  // (a digital shift preserves this (t, m, s)-net property); random points miss that by a wide margin.
  const int m = 64;
  auto count_deviation = [&](ScenarioVariant v) {
    ScenarioSet set(options(v, m));
    int worst = 0;
    std::vector<double> p(3);
    for (int t = 0; t < 5; ++t)
      for (int j = 0; j < 3; ++j) {
        std::vector<int> bins(8, 0);
        for (int i = 0; i < m; ++i) {
          set.step_noise(i, t, p);
          ++bins[static_cast<std::size_t>(p[static_cast<std::size_t>(j)] * 8)];
        }
        for (int b : bins) worst = std::max(worst, std::abs(b - 8));
      }
    return worst;
  };
  EXPECT_EQ(count_deviation(ScenarioVariant::kSobol), 0);
  EXPECT_GT(count_deviation(ScenarioVariant::kPlain), 2);
}

TEST(ScenarioSet, RejectsBadSizesAndUnknownVariants) {
  auto bad = options(ScenarioVariant::kPlain);
  bad.count = 0;
  EXPECT_THROW(ScenarioSet{bad}, InputError);
  bad = options(ScenarioVariant::kPlain);
  bad.horizon = 0;
  EXPECT_THROW(ScenarioSet{bad}, InputError);
  bad = options(ScenarioVariant::kSobol);
  bad.horizon = 5000;
  EXPECT_THROW(ScenarioSet{bad}, InputError);
  EXPECT_THROW(parse_scenario_variant("lhs"), InputError);
  EXPECT_EQ(parse_scenario_variant("sobol"), ScenarioVariant::kSobol);
}

}  // namespace
}  // namespace pegasus
