#include "pegasus/optimizers/gradient_ascent.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "pegasus/core/error.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;

// Three parameters whose useful changes differ by four orders of magnitude (ThreeScaleSpec).
TEST(GradientAscent, FindsTheMaximumOfABoundedConcaveQuadratic) {
  const Theta peak = {0.003, -2.5, 370.0};
  auto objective = ConcaveQuadratic(ThreeScaleSpec(), peak, {0.01, 1.0, 100.0}, 4.0);
  Theta theta;
  OptimizerSummary summary;
  Solve(GradientAscentOptions{}, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kConvergence) << summary.FullReport();
  const Theta scale = objective.parameters().scales();
  // function_tolerance = 1e-12 stops once U-hat is within about 1e-12 * |U-hat| of the top, i.e. within
  // sqrt(4e-12) = 2e-6 scaled units of the peak.
  for (std::size_t i = 0; i < peak.size(); ++i) EXPECT_NEAR(theta[i], peak[i], 1e-5 * scale[i]) << i;
  EXPECT_NEAR(summary.best_value, 4.0, 1e-10);
  EXPECT_EQ(summary.best_theta, theta);
  EXPECT_DOUBLE_EQ(summary.initial_value, objective.evaluate(Theta{0.0, 0.0, 0.0}));
}

TEST(GradientAscent, StopsOnTheBoundWhenTheOptimumLiesBeyondIt) {
  ParameterSpec spec(
      {{.name = "a", .lower = -1.0, .upper = 1.0}, {.name = "b", .lower = -1.0, .upper = 1.0}});
  auto objective = ConcaveQuadratic(spec, {0.5, 3.0}, {1.0, 1.0});
  Theta theta;
  OptimizerSummary summary;
  Solve(GradientAscentOptions{}, objective, &theta, &summary);
  EXPECT_EQ(theta[1], 1.0);
  EXPECT_NEAR(theta[0], 0.5, 1e-6);
  EXPECT_NEAR(summary.best_value, -4.0, 1e-10);
}

TEST(GradientAscent, AcceptedValuesNeverDecreaseEvenOnADiscontinuousObjective) {
  // A quadratic with small cliffs: the kind of discontinuity §5.3 (footnote 13) warns about.
  ParameterSpec spec({{.name = "a", .initial = -2.0, .lower = -5.0, .upper = 5.0},
                      {.name = "b", .initial = 2.0, .lower = -5.0, .upper = 5.0}});
  FunctionObjective objective(spec, [](std::span<const double> t) {
    return -(t[0] - 1.0) * (t[0] - 1.0) - 3.0 * t[1] * t[1] + 0.05 * std::floor(7.0 * std::sin(3.0 * t[0]));
  });
  GradientAscentOptions options;
  options.max_iterations = 200;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_FALSE(summary.history.empty());
  double previous = summary.initial_value;
  for (const auto& record : summary.history) {
    EXPECT_GE(record.value, previous) << "iteration " << record.iteration;
    previous = record.value;
  }
  EXPECT_EQ(objective.evaluate(theta), summary.best_value);
}

TEST(GradientAscent, EvaluatesEachGradientInOneBatchOfTwoNThetas) {
  auto quadratic = ConcaveQuadratic(ThreeScaleSpec(), {0.003, -2.5, 370.0}, {0.01, 1.0, 100.0});
  CountingObjective counting(quadratic);
  GradientAscentOptions options;
  options.max_iterations = 20;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, counting, &theta, &summary);
  ASSERT_FALSE(counting.batch_sizes.empty());
  for (const std::size_t size : counting.batch_sizes) EXPECT_EQ(size, 6u);
  // One batch per completed iteration, plus one for an iteration that ended the run.
  EXPECT_GE(static_cast<std::int64_t>(counting.batch_sizes.size()), summary.iterations);
  EXPECT_LE(static_cast<std::int64_t>(counting.batch_sizes.size()), summary.iterations + 1);
  EXPECT_EQ(counting.thetas_evaluated, summary.evaluations);
}

TEST(GradientAscent, NeverStepsFartherThanMaxStepInScaledUnits) {
  auto objective = ConcaveQuadratic(ThreeScaleSpec(), {0.5, 7.0, -800.0}, {0.01, 1.0, 100.0});
  const Theta scale = objective.parameters().scales();
  GradientAscentOptions options;
  options.max_step = 0.25;
  options.initial_step = 0.25;
  options.max_iterations = 100;
  options.checkpoint_every = 1;
  std::vector<Theta> iterates = {objective.parameters().initial()};
  options.on_checkpoint = [&](const nlohmann::json& checkpoint) {
    iterates.push_back(VectorFromJson(checkpoint["state"]["theta"], "theta"));
  };
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_GT(iterates.size(), 10u);
  for (std::size_t k = 1; k < iterates.size(); ++k) {
    double squared = 0.0;
    for (std::size_t i = 0; i < scale.size(); ++i) {
      const double d = (iterates[k][i] - iterates[k - 1][i]) / scale[i];
      squared += d * d;
    }
    EXPECT_LE(std::sqrt(squared), 0.25 * (1.0 + 1e-12)) << "step " << k;
  }
}

TEST(GradientAscent, GivesBitIdenticalResultsWhenRunTwice) {
  ParameterSpec spec({{.name = "x", .initial = -1.2, .lower = -5.0, .upper = 5.0},
                      {.name = "y", .initial = 1.0, .lower = -5.0, .upper = 5.0}});
  auto objective = NegatedRosenbrock(spec);
  GradientAscentOptions options;
  options.max_iterations = 300;
  Theta first, second;
  OptimizerSummary a, b;
  Solve(options, objective, &first, &a);
  Solve(options, objective, &second, &b);
  std::string difference;
  EXPECT_TRUE(SameOutcome(a, b, &difference)) << difference;
  EXPECT_EQ(first, second);
}

TEST(GradientAscent, StopsAtMaxIterationsAndNeverPassesMaxEvaluations) {
  ParameterSpec spec({{.name = "x", .initial = -1.2, .lower = -5.0, .upper = 5.0},
                      {.name = "y", .initial = 1.0, .lower = -5.0, .upper = 5.0}});
  auto objective = NegatedRosenbrock(spec);
  GradientAscentOptions options;
  options.max_iterations = 7;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kMaxIterations);
  EXPECT_EQ(summary.iterations, 7);

  options.max_iterations = 1000;
  options.max_evaluations = 50;
  theta.clear();
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kMaxEvaluations);
  EXPECT_LE(summary.evaluations, 50);
}

TEST(GradientAscent, StartsFromTheGivenThetaClampedIntoTheBounds) {
  ParameterSpec spec(
      {{.name = "a", .lower = -1.0, .upper = 1.0}, {.name = "b", .lower = -1.0, .upper = 1.0}});
  auto objective = ConcaveQuadratic(spec, {0.0, 0.0}, {1.0, 1.0});
  GradientAscentOptions options;
  options.max_iterations = 0;
  Theta theta = {5.0, -0.5};
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(theta, (Theta{1.0, -0.5}));
  EXPECT_EQ(summary.initial_value, -1.25);
  EXPECT_EQ(summary.evaluations, 1);

  Theta wrong_size = {0.0};
  EXPECT_THROW(Solve(options, objective, &wrong_size, &summary), InputError);
}

TEST(GradientAscentOptions, IsValidRejectsEachBadFieldByName) {
  const std::vector<std::pair<std::string, std::function<void(GradientAscentOptions&)>>> cases = {
      {"max_iterations", [](auto& o) { o.max_iterations = -1; }},
      {"max_evaluations", [](auto& o) { o.max_evaluations = 0; }},
      {"relative_step", [](auto& o) { o.relative_step = 0.0; }},
      {"relative_step", [](auto& o) { o.relative_step = std::nan(""); }},
      {"max_step", [](auto& o) { o.max_step = -1.0; }},
      {"initial_step", [](auto& o) { o.initial_step = 2.0; }},
      {"initial_step", [](auto& o) { o.initial_step = 0.0; }},
      {"min_step", [](auto& o) { o.min_step = -1e-3; }},
      {"min_step", [](auto& o) { o.min_step = 0.5; }},
      {"step_growth", [](auto& o) { o.step_growth = 0.5; }},
      {"max_backtracks", [](auto& o) { o.max_backtracks = -1; }},
      {"function_tolerance", [](auto& o) { o.function_tolerance = -1.0; }},
      {"checkpoint_every", [](auto& o) { o.checkpoint_every = -1; }},
      {"on_checkpoint", [](auto& o) { o.checkpoint_every = 5; }},
      {"resume_from",
       [](auto& o) {
         o.resume_from = nlohmann::json{{"format", "something else"}};
       }},
      {"resume_from",
       [](auto& o) {
         o.resume_from = nlohmann::json{{"format", kCheckpointFormat}, {"method", "hill-climb"}};
       }},
  };
  std::string error;
  EXPECT_TRUE(GradientAscentOptions{}.IsValid(&error)) << error;
  ParameterSpec spec({{.name = "a"}});
  auto objective = ConcaveQuadratic(spec, {0.0}, {1.0});
  for (const auto& [field, mutate] : cases) {
    GradientAscentOptions options;
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
