#include "pegasus/optimizers/hill_climbing.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "pegasus/core/error.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;

TEST(HillClimbing, FindsTheMaximumOfABoundedConcaveQuadratic) {
  const Theta peak = {0.003, -2.5, 370.0};
  auto objective = ConcaveQuadratic(ThreeScaleSpec(), peak, {0.01, 1.0, 100.0}, 4.0);
  HillClimbingOptions options;
  options.max_iterations = 5000;
  options.min_step = 1e-6;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kConvergence) << summary.FullReport();
  const Theta scale = objective.parameters().scales();
  for (std::size_t i = 0; i < peak.size(); ++i) EXPECT_NEAR(theta[i], peak[i], 1e-4 * scale[i]) << i;
  EXPECT_NEAR(summary.best_value, 4.0, 1e-7);
}

TEST(HillClimbing, StopsOnTheBoundWhenTheOptimumLiesBeyondIt) {
  ParameterSpec spec(
      {{.name = "a", .lower = -1.0, .upper = 1.0}, {.name = "b", .lower = -1.0, .upper = 1.0}});
  auto objective = ConcaveQuadratic(spec, {0.5, 3.0}, {1.0, 1.0});
  HillClimbingOptions options;
  options.max_iterations = 5000;
  options.min_step = 1e-6;
  options.proposals_per_iteration = 4;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  // Clipping to the bound puts proposals exactly on it.
  EXPECT_EQ(theta[1], 1.0);
  EXPECT_NEAR(theta[0], 0.5, 1e-4);
}

TEST(HillClimbing, AcceptedValuesNeverDecrease) {
  ParameterSpec spec({{.name = "x", .initial = -1.2, .lower = -5.0, .upper = 5.0},
                      {.name = "y", .initial = 1.0, .lower = -5.0, .upper = 5.0}});
  auto objective = NegatedRosenbrock(spec);
  HillClimbingOptions options;
  options.max_iterations = 2000;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_EQ(summary.history.size(), 2000u);
  double previous = summary.initial_value;
  int increases = 0;
  for (const auto& record : summary.history) {
    EXPECT_GE(record.value, previous) << "iteration " << record.iteration;
    increases += record.value > previous;
    previous = record.value;
  }
  EXPECT_GT(increases, 100);
  EXPECT_GT(summary.best_value, -0.01);  // from -24.2 at the start, along the curved valley
}

TEST(HillClimbing, EvaluatesTheProposalsOfAnIterationInOneBatch) {
  auto quadratic = ConcaveQuadratic(ThreeScaleSpec(), {0.003, -2.5, 370.0}, {0.01, 1.0, 100.0});
  CountingObjective counting(quadratic);
  HillClimbingOptions options;
  options.proposals_per_iteration = 5;
  options.max_iterations = 40;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, counting, &theta, &summary);
  EXPECT_EQ(counting.batch_sizes, std::vector<std::size_t>(40, 5));
  EXPECT_EQ(counting.evaluate_calls, 1);  // the starting theta
  EXPECT_EQ(summary.evaluations, 1 + 40 * 5);
}

TEST(HillClimbing, GivesBitIdenticalResultsWhenRunTwiceAndOtherResultsForAnotherSeed) {
  ParameterSpec spec({{.name = "x", .initial = -1.2, .lower = -5.0, .upper = 5.0},
                      {.name = "y", .initial = 1.0, .lower = -5.0, .upper = 5.0}});
  auto objective = NegatedRosenbrock(spec);
  HillClimbingOptions options;
  options.max_iterations = 300;
  options.proposals_per_iteration = 3;
  Theta first, second, third;
  OptimizerSummary a, b, c;
  Solve(options, objective, &first, &a);
  Solve(options, objective, &second, &b);
  std::string difference;
  EXPECT_TRUE(SameOutcome(a, b, &difference)) << difference;
  options.seed = 99;
  Solve(options, objective, &third, &c);
  EXPECT_FALSE(SameOutcome(a, c));
}

TEST(HillClimbing, StopsAtMaxIterationsAndNeverPassesMaxEvaluations) {
  ParameterSpec spec({{.name = "x", .initial = -1.2}, {.name = "y", .initial = 1.0}});
  auto objective = NegatedRosenbrock(spec);
  HillClimbingOptions options;
  options.max_iterations = 11;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kMaxIterations);
  EXPECT_EQ(summary.iterations, 11);

  options.max_iterations = 1000;
  options.proposals_per_iteration = 4;
  options.max_evaluations = 30;
  theta.clear();
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kMaxEvaluations);
  EXPECT_EQ(summary.evaluations, 29);  // 1 + 7 * 4; an eighth batch would pass 30
}

TEST(FillStandardNormals, GivesMeanZeroUnitVarianceAndConsumesTwoUniformsPerPair) {
  UniformStream uniforms(7, 1);
  std::vector<double> normals(3);
  FillStandardNormals(uniforms, normals);
  EXPECT_EQ(uniforms.position(), 4u);  // ceil(3 / 2) pairs

  std::vector<double> many(200000);
  FillStandardNormals(uniforms, many);
  double sum = 0.0, squares = 0.0, fourth = 0.0;
  for (const double z : many) {
    sum += z;
    squares += z * z;
    fourth += z * z * z * z;
  }
  const double n = static_cast<double>(many.size());
  EXPECT_NEAR(sum / n, 0.0, 0.01);
  EXPECT_NEAR(squares / n, 1.0, 0.01);
  EXPECT_NEAR(fourth / n, 3.0, 0.06);  // the normal's kurtosis
}

TEST(HillClimbingOptions, IsValidRejectsEachBadFieldByName) {
  const std::vector<std::pair<std::string, std::function<void(HillClimbingOptions&)>>> cases = {
      {"max_iterations", [](auto& o) { o.max_iterations = -1; }},
      {"max_evaluations", [](auto& o) { o.max_evaluations = 0; }},
      {"proposals_per_iteration", [](auto& o) { o.proposals_per_iteration = 0; }},
      {"max_step", [](auto& o) { o.max_step = 0.0; }},
      {"max_step", [](auto& o) { o.max_step = INFINITY; }},
      {"initial_step", [](auto& o) { o.initial_step = 5.0; }},
      {"min_step", [](auto& o) { o.min_step = -1.0; }},
      {"min_step", [](auto& o) { o.min_step = 0.2; }},
      {"step_growth", [](auto& o) { o.step_growth = 0.9; }},
      {"step_shrink", [](auto& o) { o.step_shrink = 0.0; }},
      {"step_shrink", [](auto& o) { o.step_shrink = 1.5; }},
      {"checkpoint_every", [](auto& o) { o.checkpoint_every = -2; }},
      {"on_checkpoint", [](auto& o) { o.checkpoint_every = 1; }},
      {"resume_from", [](auto& o) { o.resume_from = nlohmann::json::array(); }},
      {"resume_from",
       [](auto& o) {
         o.resume_from = nlohmann::json{{"format", kCheckpointFormat}, {"method", "gradient"}};
       }},
  };
  std::string error;
  EXPECT_TRUE(HillClimbingOptions{}.IsValid(&error)) << error;
  ParameterSpec spec({{.name = "a"}});
  auto objective = ConcaveQuadratic(spec, {0.0}, {1.0});
  for (const auto& [field, mutate] : cases) {
    HillClimbingOptions options;
    mutate(options);
    EXPECT_FALSE(options.IsValid(&error)) << field;
    EXPECT_THAT(error, ::testing::StartsWith(field + ":"));
    Theta theta;
    OptimizerSummary summary;
    try {
      Solve(options, objective, &theta, &summary);
      ADD_FAILURE() << "Solve accepted a bad " << field;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(field));
    }
  }
}

}  // namespace
}  // namespace pegasus
