#include "pegasus/optimizers/exhaustive_search.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "pegasus/core/error.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;

ParameterSpec SmallClass() {
  return ParameterSpec({{.name = "a", .initial = 0, .lower = 0, .upper = 3, .integer = true},
                        {.name = "b", .initial = 0, .lower = 0, .upper = 4, .integer = true},
                        {.name = "c", .initial = 0, .lower = -2, .upper = 2, .integer = true}});
}

TEST(ExhaustiveSearch, FindsTheArgmaxOfAFiniteClass) {
  FunctionObjective objective(SmallClass(), [](std::span<const double> t) {
    return std::sin(1.3 * t[0] + 0.7 * t[1] * t[2]) + 0.1 * std::cos(t[1] - t[2]);
  });
  Theta theta;
  OptimizerSummary summary;
  Solve(ExhaustiveSearchOptions{}, objective, &theta, &summary);
  // Brute force in plain nested loops.
  double best = -std::numeric_limits<double>::infinity();
  Theta argmax;
  for (int a = 0; a <= 3; ++a)
    for (int b = 0; b <= 4; ++b)
      for (int c = -2; c <= 2; ++c) {
        const Theta t = {double(a), double(b), double(c)};
        if (objective.evaluate(t) > best) {
          best = objective.evaluate(t);
          argmax = t;
        }
      }
  EXPECT_EQ(theta, argmax);
  EXPECT_EQ(summary.best_value, best);
  EXPECT_EQ(summary.evaluations, 4 * 5 * 5);
  EXPECT_EQ(summary.termination_type, TerminationType::kSearchComplete);
}

TEST(ExhaustiveSearch, BreaksTiesTowardTheLowestEnumerationIndex) {
  // Maximal at (1, *, 0) and (3, *, 0) for every b: the lowest index is (1, 0, 0).
  FunctionObjective objective(SmallClass(), [](std::span<const double> t) {
    return (t[0] == 1.0 || t[0] == 3.0) && t[2] == 0.0 ? 1.0 : 0.0;
  });
  ExhaustiveSearchOptions options;
  options.block_size = 7;  // ties straddle blocks
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(theta, (Theta{1.0, 0.0, 0.0}));

  FunctionObjective flat(SmallClass(), [](std::span<const double>) { return 2.5; });
  Solve(options, flat, &theta, &summary);
  EXPECT_EQ(theta, (Theta{0.0, 0.0, -2.0}));
}

TEST(ExhaustiveSearch, EnumeratesWithTheLastParameterFastestAndKeepsEveryValue) {
  // U = the policy's own mixed-radix number, so all_values must count 0, 1, 2, ...
  FunctionObjective objective(
      SmallClass(), [](std::span<const double> t) { return t[0] * 25.0 + t[1] * 5.0 + (t[2] + 2.0); });
  ExhaustiveSearchOptions options;
  options.keep_all_values = true;
  options.block_size = 9;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_EQ(summary.all_values.size(), 100u);
  for (std::size_t k = 0; k < 100; ++k) {
    EXPECT_EQ(summary.all_values[k], static_cast<double>(k));
    Theta decoded;
    ExhaustiveSearchTheta(objective.parameters(), static_cast<std::int64_t>(k), &decoded);
    EXPECT_EQ(objective.evaluate(decoded), static_cast<double>(k));
  }
  EXPECT_EQ(ExhaustiveSearchSize(objective.parameters(), 1000), 100);
}

TEST(ExhaustiveSearch, EvaluatesInBlocksThroughEvaluateBatch) {
  FunctionObjective inner(SmallClass(), [](std::span<const double> t) { return t[0] - t[1]; });
  CountingObjective counting(inner);
  ExhaustiveSearchOptions options;
  options.block_size = 32;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, counting, &theta, &summary);
  EXPECT_EQ(counting.batch_sizes, (std::vector<std::size_t>{32, 32, 32, 4}));
  EXPECT_EQ(counting.evaluate_calls, 0);
  EXPECT_EQ(summary.iterations, 4);
}

TEST(ExhaustiveSearch, TakesTheIntegersInsideNonIntegralBounds) {
  ParameterSpec spec({{.name = "a", .initial = 1.0, .lower = 0.5, .upper = 3.2, .integer = true}});
  EXPECT_EQ(ExhaustiveSearchSize(spec, 100), 3);
  Theta theta;
  ExhaustiveSearchTheta(spec, 0, &theta);
  EXPECT_EQ(theta, Theta{1.0});
  ExhaustiveSearchTheta(spec, 2, &theta);
  EXPECT_EQ(theta, Theta{3.0});
}

TEST(ExhaustiveSearch, RefusesNonIntegerUnboundedOrTooLargeClasses) {
  auto refuses = [](ParameterSpec spec, const std::string& expected, std::int64_t max_policies = 10'000'000) {
    FunctionObjective objective(std::move(spec), [](std::span<const double>) { return 0.0; });
    ExhaustiveSearchOptions options;
    options.max_policies = max_policies;
    Theta theta;
    OptimizerSummary summary;
    try {
      Solve(options, objective, &theta, &summary);
      ADD_FAILURE() << "accepted a class that should fail with " << expected;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(expected));
    }
  };
  refuses(ParameterSpec({{.name = "w", .lower = 0, .upper = 3}}),
          "parameter w: exhaustive search needs integer");
  refuses(ParameterSpec({{.name = "k", .initial = 0, .lower = 0, .integer = true}}),
          "parameter k: exhaustive search needs finite bounds");
  // A class with an integer parameter but no integer in its bounds cannot be made: its initial value must be
  // one.
  EXPECT_THROW(ParameterSpec({{.name = "k", .initial = 0.5, .lower = 0.2, .upper = 0.8, .integer = true}}),
               InputError);
  refuses(SmallClass(), "max_policies = 99", 99);
  // 4^8 policies fit the default; 64^8 = 2^48 do not (and must not overflow while counting).
  std::vector<Parameter> table;
  for (int i = 0; i < 8; ++i)
    table.push_back({.name = "o" + std::to_string(i), .lower = 0, .upper = 63, .integer = true});
  refuses(ParameterSpec(table), "more than max_policies");
}

TEST(ExhaustiveSearchOptions, IsValidRejectsEachBadFieldByName) {
  const std::vector<std::pair<std::string, std::function<void(ExhaustiveSearchOptions&)>>> cases = {
      {"max_policies", [](auto& o) { o.max_policies = 0; }},
      {"block_size", [](auto& o) { o.block_size = 0; }},
      {"checkpoint_every", [](auto& o) { o.checkpoint_every = -1; }},
      {"on_checkpoint", [](auto& o) { o.checkpoint_every = 1; }},
      {"resume_from",
       [](auto& o) {
         o.resume_from = nlohmann::json{{"format", kCheckpointFormat}};
       }},
  };
  std::string error;
  EXPECT_TRUE(ExhaustiveSearchOptions{}.IsValid(&error)) << error;
  FunctionObjective objective(SmallClass(), [](std::span<const double>) { return 0.0; });
  for (const auto& [field, mutate] : cases) {
    ExhaustiveSearchOptions options;
    mutate(options);
    EXPECT_FALSE(options.IsValid(&error)) << field;
    EXPECT_THAT(error, ::testing::StartsWith(field + ":"));
    Theta theta;
    OptimizerSummary summary;
    EXPECT_THROW(Solve(options, objective, &theta, &summary), InputError) << field;
  }
}

}  // namespace
}  // namespace pegasus
