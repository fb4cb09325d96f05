#include "pegasus/optimizers/optimizer.hpp"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "pegasus/core/error.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// Integer-valued for exhaustive search, which enumerates only integers; real for the others, which refuse
// integer parameters.
ParameterSpec GainBiasBox(std::string_view method = "gradient") {
  const bool integer = method == "exhaustive";
  return ParameterSpec({{.name = "gain", .initial = 1.0, .lower = -3.0, .upper = 3.0, .integer = integer},
                        {.name = "bias", .initial = -2.0, .lower = -3.0, .upper = 3.0, .integer = integer}});
}

TEST(OptimizerDispatch, EveryMethodNameRunsThatMethodAndFindsTheMaximum) {
  ASSERT_EQ(OptimizerMethodNames().size(), 9u);
  for (const std::string_view name : OptimizerMethodNames()) {
    SCOPED_TRACE(name);
    // Maximal at (1, -1), a point of the integer grid so exhaustive search can hit it exactly.
    auto objective = ConcaveQuadratic(GainBiasBox(name), {1.0, -1.0}, {1.0, 2.0}, 3.0);
    OptimizerOptions options;
    options.method = std::string(name);
    options.nlopt.max_evaluations = 3000;
    options.hill_climbing.max_iterations = 3000;
    options.hill_climbing.min_step = 1e-6;
    options.ars.max_iterations = 400;
    options.ars.step_size = 0.05;
    Theta theta = {2.0, 2.0};
    OptimizerSummary summary;
    Solve(options, objective, &theta, &summary);
    EXPECT_EQ(summary.method, name);
    // ESCH only gets close in 3000 evaluations; ARS's step, scaled by the spread of the returns, shrinks with
    // the gradient but not to zero within 400 iterations.
    const double tolerance = name == "esch" || name == "ars" ? 0.1 : 1e-3;
    EXPECT_NEAR(theta[0], 1.0, tolerance);
    EXPECT_NEAR(theta[1], -1.0, tolerance);
    EXPECT_THAT(summary.BriefReport(), StartsWith(std::string(name) + ": "));
    EXPECT_EQ(summary.BriefReport().find('\n'), std::string::npos);
    EXPECT_THAT(summary.FullReport(), HasSubstr("bias"));
    EXPECT_THAT(summary.FullReport(), HasSubstr(std::string(TerminationTypeName(summary.termination_type))));
  }
}

TEST(OptimizerDispatch, IsValidNamesTheMethodOrThePrefixedFieldOfTheSelectedMethod) {
  std::string error;
  OptimizerOptions options;
  EXPECT_TRUE(options.IsValid(&error)) << error;

  options.method = "newton";
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("method: expected one of exhaustive, gradient, hill-climb, bobyqa"));

  options = {};
  EXPECT_EQ(options.method, "cmaes");  // the default (the optimizer suite's choice)
  options.gradient.max_step = -1.0;
  EXPECT_TRUE(options.IsValid(&error)) << error;  // not the selected method's
  options.method = "gradient";
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("gradient.max_step:"));
  options.method = "hill-climb";  // only the selected method's options are checked
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.hill_climbing.step_shrink = 2.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("hill_climbing.step_shrink:"));

  options = {};
  options.method = "exhaustive";
  options.exhaustive.block_size = 0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("exhaustive.block_size:"));

  options = {};
  options.method = "crs2";
  options.nlopt.population = -1;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("nlopt.population:"));

  auto objective = ConcaveQuadratic(GainBiasBox(), {1.0, -1.0}, {1.0, 2.0});
  Theta theta;
  OptimizerSummary summary;
  try {
    Solve(options, objective, &theta, &summary);
    ADD_FAILURE() << "Solve accepted invalid options";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("nlopt.population"));
  }
}

TEST(OptimizerDispatch, TheMethodOverridesTheNloptAlgorithm) {
  auto objective = ConcaveQuadratic(GainBiasBox(), {1.0, -1.0}, {1.0, 2.0});
  OptimizerOptions options;
  options.method = "sbplx";
  options.nlopt.algorithm = NloptAlgorithm::kCrs2;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.method, "sbplx");
}

TEST(OptimizerDispatch, SetCheckpointingReachesEveryMethodAndCheckpointsNameTheirMethod) {
  for (const std::string_view name : OptimizerMethodNames()) {
    SCOPED_TRACE(name);
    auto objective = ConcaveQuadratic(GainBiasBox(name), {1.0, -1.0}, {1.0, 2.0});
    OptimizerOptions options;
    options.method = std::string(name);
    options.exhaustive.block_size = 5;
    // Short runs: with a checkpoint every 2 iterations, checkpoint sizes add up quadratically.
    options.nlopt.max_evaluations = 100;
    options.hill_climbing.max_iterations = 100;
    options.ars.max_iterations = 10;
    std::vector<nlohmann::json> checkpoints;
    options.SetCheckpointing(2, [&](const nlohmann::json& c) { checkpoints.push_back(c); });
    Theta theta;
    OptimizerSummary summary;
    Solve(options, objective, &theta, &summary);
    ASSERT_FALSE(checkpoints.empty());
    EXPECT_EQ(CheckpointMethod(checkpoints.front()), name);
    EXPECT_EQ(checkpoints.front()["iterations"], 2);
  }
  EXPECT_THROW(CheckpointMethod(nlohmann::json{{"method", "gradient"}}), InputError);
}

TEST(OptimizerDispatch, OnlyExhaustiveSearchTakesIntegerParameters) {
  for (const std::string_view name : OptimizerMethodNames()) {
    if (name == "exhaustive") continue;
    SCOPED_TRACE(name);
    auto objective = ConcaveQuadratic(GainBiasBox("exhaustive"), {1.0, -1.0}, {1.0, 2.0});
    OptimizerOptions options;
    options.method = std::string(name);
    Theta theta;
    OptimizerSummary summary;
    try {
      Solve(options, objective, &theta, &summary);
      ADD_FAILURE() << "a real-valued search over integer parameters";
    } catch (const InputError& e) {
      EXPECT_EQ(
          std::string(e.what()),
          fmt::format("optimizer method {}: searches real numbers, but parameter 'gain' is an integer (a "
                      "table entry); expected exhaustive",
                      name));
    }
  }
}

// Records the fields a VisitFields lists, and whether each is set by a config (integer, real) or only by a
// program (internal).
struct FieldNames {
  std::vector<std::string> config, program;
  template <class M>
  void integer(const char* name, M, const char* help, double, double = 0) {
    config.emplace_back(name);
    EXPECT_NE(std::string_view(help), "") << name;
  }
  template <class M>
  void real(const char* name, M, const char* help, double, double, bool = false) {
    config.emplace_back(name);
    EXPECT_NE(std::string_view(help), "") << name;
  }
  template <class M>
  void internal(const char* name, M, const char*) {
    program.emplace_back(name);
  }
};

TEST(OptimizerMethods, TheListDescribesEveryMethodOnceAndConsistently) {
  std::set<std::string_view> sections, types, names;
  std::set<std::uint32_t> domains;
  std::size_t method_names = 0;
  ForEachOptimizerMethod([&](auto member) {
    using Options = OptimizerMethodOptions<decltype(member)>;
    const OptimizerMethodInfo& info = Options::kMethod;
    SCOPED_TRACE(info.section);
    EXPECT_TRUE(sections.insert(info.section).second);
    EXPECT_TRUE(types.insert(info.type_name).second);
    EXPECT_FALSE(info.description.empty());
    ASSERT_FALSE(info.method_names.front().empty());
    for (std::string_view name : info.method_names) {
      if (name.empty()) continue;
      ++method_names;
      EXPECT_TRUE(names.insert(name).second) << name;
      EXPECT_TRUE(info.runs(name));
    }
    for (std::string_view name : info.need_finite_bounds) {
      if (name.empty()) continue;
      EXPECT_TRUE(info.runs(name)) << name;
    }
    // A method has a seed exactly when it names the domains the training layer derives it from.
    constexpr bool has_seed = requires(Options o) { o.seed; };
    EXPECT_EQ(info.seed_domain != 0, has_seed);
    if (has_seed) {
      EXPECT_TRUE(domains.insert(info.seed_domain).second);
      EXPECT_TRUE(domains.insert(info.refine_seed_domain).second);
    }
    // Fields: each named once; a seed is the library's to set, never a config's.
    FieldNames fields;
    Options::VisitFields(fields);
    std::set<std::string> all(fields.config.begin(), fields.config.end());
    all.insert(fields.program.begin(), fields.program.end());
    EXPECT_EQ(all.size(), fields.config.size() + fields.program.size());
    EXPECT_FALSE(fields.config.empty());
    EXPECT_EQ(all.count("seed"), has_seed ? 1u : 0u);
    EXPECT_EQ(std::count(fields.config.begin(), fields.config.end(), "seed"), 0);
  });
  // The names the dispatcher accepts are the list's, in its order.
  EXPECT_EQ(method_names, names.size());
  EXPECT_EQ(std::vector<std::string_view>(OptimizerMethodNames().begin(), OptimizerMethodNames().end()),
            (std::vector<std::string_view>{"exhaustive", "gradient", "hill-climb", "bobyqa", "sbplx", "crs2",
                                           "esch", "cmaes", "ars"}));
}

TEST(OptimizerMethods, SetSeedsAndIterationLimitFollowTheList) {
  OptimizerOptions options;
  options.SetSeeds(77);
  EXPECT_EQ(options.hill_climbing.seed, 77u);
  EXPECT_EQ(options.nlopt.seed, 77u);
  EXPECT_EQ(options.cmaes.seed, 77u);
  EXPECT_EQ(options.ars.seed, 77u);
  options.gradient.max_iterations = 11;
  options.hill_climbing.max_iterations = 12;
  options.cmaes.max_iterations = 13;
  options.ars.max_iterations = 14;
  options.nlopt.max_evaluations = 15;
  options.exhaustive.max_policies = 100;
  options.exhaustive.block_size = 30;
  const std::vector<std::pair<std::string, std::int64_t>> expected = {
      {"gradient", 11}, {"hill-climb", 12}, {"cmaes", 13},    {"ars", 14},
      {"bobyqa", 15},   {"esch", 15},       {"exhaustive", 4}};
  for (const auto& [method, limit] : expected) {
    options.method = method;
    EXPECT_EQ(options.IterationLimit(), limit) << method;
  }
  // Blocks of policies, without overflow at the largest class.
  options.method = "exhaustive";
  options.exhaustive.max_policies = std::numeric_limits<std::int64_t>::max();
  options.exhaustive.block_size = 4096;
  EXPECT_EQ(options.IterationLimit(), std::numeric_limits<std::int64_t>::max() / 4096 + 1);
  options.method = "newton";
  EXPECT_EQ(options.IterationLimit(), 0);
}

}  // namespace
}  // namespace pegasus
