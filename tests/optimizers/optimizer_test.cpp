#include "pegasus/optimizers/optimizer.hpp"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pegasus/core/error.hpp"
#include "pegasus/optimizers/test_problems.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

// Integer-valued for exhaustive search, which enumerates only integers; real for the others, which refuse
// integer parameters.
ParameterSpec Box(std::string_view method = "gradient") {
  const bool integer = method == "exhaustive";
  return ParameterSpec({{.name = "gain", .initial = 1.0, .lower = -3.0, .upper = 3.0, .integer = integer},
                        {.name = "bias", .initial = -2.0, .lower = -3.0, .upper = 3.0, .integer = integer}});
}

TEST(OptimizerDispatch, EveryMethodNameRunsThatMethodAndFindsTheMaximum) {
  ASSERT_EQ(OptimizerMethodNames().size(), 9u);
  for (const std::string_view name : OptimizerMethodNames()) {
    SCOPED_TRACE(name);
    // Maximal at (1, -1), a point of the integer grid so exhaustive search can hit it exactly.
    auto objective = ConcaveQuadratic(Box(name), {1.0, -1.0}, {1.0, 2.0}, 3.0);
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
  options.gradient.max_step = -1.0;
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

  auto objective = ConcaveQuadratic(Box(), {1.0, -1.0}, {1.0, 2.0});
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
  auto objective = ConcaveQuadratic(Box(), {1.0, -1.0}, {1.0, 2.0});
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
    auto objective = ConcaveQuadratic(Box(name), {1.0, -1.0}, {1.0, 2.0});
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
    auto objective = ConcaveQuadratic(Box("exhaustive"), {1.0, -1.0}, {1.0, 2.0});
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

}  // namespace
}  // namespace pegasus
