#include "pegasus/optimizers/nlopt_optimizer.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <stdexcept>

#include "pegasus/core/error.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;

constexpr NloptAlgorithm kLocal[] = {NloptAlgorithm::kBobyqa, NloptAlgorithm::kSbplx};
constexpr NloptAlgorithm kGlobal[] = {NloptAlgorithm::kCrs2, NloptAlgorithm::kEsch};
constexpr NloptAlgorithm kAll[] = {NloptAlgorithm::kBobyqa, NloptAlgorithm::kSbplx, NloptAlgorithm::kCrs2,
                                   NloptAlgorithm::kEsch};

NloptOptions With(NloptAlgorithm algorithm) {
  NloptOptions options;
  options.algorithm = algorithm;
  return options;
}

TEST(NloptLocalMethods, FindTheMaximumOfRosenbrock) {
  for (const auto algorithm : kLocal) {
    SCOPED_TRACE(NloptAlgorithmName(algorithm));
    auto objective = NegatedRosenbrock(RosenbrockSpec());
    Theta theta;
    OptimizerSummary summary;
    Solve(With(algorithm), objective, &theta, &summary);
    EXPECT_EQ(summary.termination_type, TerminationType::kConvergence) << summary.FullReport();
    EXPECT_NEAR(theta[0], 1.0, 1e-4);
    EXPECT_NEAR(theta[1], 1.0, 2e-4);
    EXPECT_GT(summary.best_value, -1e-8);
    EXPECT_EQ(summary.initial_value, objective.evaluate(Theta{-1.2, 1.0}));
    EXPECT_EQ(summary.iterations, summary.evaluations);
  }
}

TEST(NloptLocalMethods, FindTheMaximumOfABoundedConcaveQuadraticWithDifferentScales) {
  ParameterSpec spec({{.name = "small", .lower = -1.0, .upper = 1.0, .scale = 0.01},
                      {.name = "unit", .lower = -10.0, .upper = 10.0, .scale = 1.0},
                      {.name = "large", .lower = -1000.0, .upper = 1000.0, .scale = 100.0}});
  const Theta peak = {0.003, -2.5, 370.0};
  for (const auto algorithm : kLocal) {
    SCOPED_TRACE(NloptAlgorithmName(algorithm));
    auto objective = ConcaveQuadratic(spec, peak, {0.01, 1.0, 100.0}, 4.0);
    Theta theta;
    OptimizerSummary summary;
    Solve(With(algorithm), objective, &theta, &summary);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(theta[i], peak[i], 1e-5 * spec[i].scale) << i;
  }
}

TEST(NloptMethods, StopOnTheBoundWhenTheOptimumLiesBeyondIt) {
  ParameterSpec spec(
      {{.name = "a", .lower = -1.0, .upper = 1.0}, {.name = "b", .lower = -1.0, .upper = 1.0}});
  for (const auto algorithm : kAll) {
    SCOPED_TRACE(NloptAlgorithmName(algorithm));
    auto objective = ConcaveQuadratic(spec, {0.5, 3.0}, {1.0, 1.0});
    NloptOptions options = With(algorithm);
    options.max_evaluations = 4000;
    Theta theta;
    OptimizerSummary summary;
    Solve(options, objective, &theta, &summary);
    // ESCH, an evolutionary strategy, has no local convergence phase and gets only close.
    const double tolerance = algorithm == NloptAlgorithm::kEsch ? 2e-2 : 1e-3;
    EXPECT_NEAR(theta[1], 1.0, tolerance);
    EXPECT_NEAR(theta[0], 0.5, tolerance);
    EXPECT_LE(theta[1], 1.0);
  }
}

TEST(NloptGlobalMethods, FindTheGlobalMaximumOfRastriginFromALocalMaximum) {
  for (const auto algorithm : kGlobal) {
    SCOPED_TRACE(NloptAlgorithmName(algorithm));
    auto objective = NegatedRastrigin(RastriginSpec());
    NloptOptions options = With(algorithm);
    options.max_evaluations = algorithm == NloptAlgorithm::kEsch ? 20000 : 5000;
    Theta theta;
    OptimizerSummary summary;
    Solve(options, objective, &theta, &summary);
    EXPECT_NEAR(theta[0], 0.0, 0.02) << summary.FullReport();
    EXPECT_NEAR(theta[1], 0.0, 0.02);
    EXPECT_GT(summary.best_value, -0.1);
  }
  // A local method started in the same place stays on the local maximum: the problem is a real test.
  auto objective = NegatedRastrigin(RastriginSpec());
  Theta theta;
  OptimizerSummary summary;
  Solve(With(NloptAlgorithm::kBobyqa), objective, &theta, &summary);
  EXPECT_LT(summary.best_value, -10.0);
}

TEST(NloptGlobalMethods, RefuseInfiniteBounds) {
  for (const auto algorithm : kGlobal) {
    auto objective =
        NegatedRosenbrock(ParameterSpec({{.name = "x", .lower = -1.0, .upper = 1.0}, {.name = "open"}}));
    Theta theta;
    OptimizerSummary summary;
    try {
      Solve(With(algorithm), objective, &theta, &summary);
      ADD_FAILURE() << "accepted an infinite bound";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("parameter open"));
      EXPECT_THAT(e.what(), HasSubstr("finite bounds"));
    }
  }
}

TEST(NloptMethods, GiveBitIdenticalResultsWhenRunTwice) {
  for (const auto algorithm : kAll) {
    SCOPED_TRACE(NloptAlgorithmName(algorithm));
    auto objective = NegatedRastrigin(RastriginSpec());
    NloptOptions options = With(algorithm);
    options.max_evaluations = 1500;
    options.seed = 12345;
    Theta first, second;
    OptimizerSummary a, b;
    Solve(options, objective, &first, &a);
    Solve(options, objective, &second, &b);
    std::string difference;
    EXPECT_TRUE(SameOutcome(a, b, &difference)) << difference;
  }
}

TEST(NloptGlobalMethods, DependOnTheSeed) {
  for (const auto algorithm : kGlobal) {
    SCOPED_TRACE(NloptAlgorithmName(algorithm));
    auto objective = NegatedRastrigin(RastriginSpec());
    NloptOptions options = With(algorithm);
    options.max_evaluations = 500;
    Theta first, second;
    OptimizerSummary a, b;
    Solve(options, objective, &first, &a);
    options.seed = 1;
    Solve(options, objective, &second, &b);
    EXPECT_FALSE(SameOutcome(a, b));
  }
}

TEST(NloptMethods, TreatMaxEvaluationsAsAHardLimitAndCallEvaluateOnly) {
  for (const auto algorithm : kAll) {
    SCOPED_TRACE(NloptAlgorithmName(algorithm));
    auto rastrigin = NegatedRastrigin(RastriginSpec());
    CountingObjective counting(rastrigin);
    NloptOptions options = With(algorithm);
    options.max_evaluations = 37;
    options.x_tolerance = 0.0;
    options.function_tolerance = 0.0;
    Theta theta;
    OptimizerSummary summary;
    Solve(options, counting, &theta, &summary);
    EXPECT_EQ(summary.termination_type, TerminationType::kMaxEvaluations);
    EXPECT_EQ(summary.evaluations, 37);
    EXPECT_EQ(counting.evaluate_calls, 37);
    EXPECT_TRUE(counting.batch_sizes.empty());
    EXPECT_EQ(counting.evaluate(theta), summary.best_value);
  }
}

TEST(NloptMethods, PassOnWhatTheObjectiveThrows) {
  int calls = 0;
  FunctionObjective objective(RosenbrockSpec(), [&calls](std::span<const double>) -> double {
    if (++calls == 5) throw std::domain_error("simulator diverged");
    return 0.0;
  });
  Theta theta;
  OptimizerSummary summary;
  EXPECT_THROW(
      {
        try {
          Solve(With(NloptAlgorithm::kSbplx), objective, &theta, &summary);
        } catch (const std::domain_error& e) {
          EXPECT_STREQ(e.what(), "simulator diverged");
          throw;
        }
      },
      std::domain_error);
}

TEST(NloptMethods, NeverPickANanValueAsTheBest) {
  FunctionObjective objective(RosenbrockSpec(), [](std::span<const double> t) {
    return t[0] > 0.5 ? std::nan("") : -(t[0] - 2.0) * (t[0] - 2.0) - t[1] * t[1];
  });
  Theta theta;
  OptimizerSummary summary;
  Solve(With(NloptAlgorithm::kBobyqa), objective, &theta, &summary);
  EXPECT_FALSE(std::isnan(summary.best_value));
  EXPECT_LE(theta[0], 0.5);
}

TEST(NloptOptions, IsValidRejectsEachBadFieldByName) {
  const std::vector<std::pair<std::string, std::function<void(NloptOptions&)>>> cases = {
      {"algorithm", [](auto& o) { o.algorithm = static_cast<NloptAlgorithm>(17); }},
      {"max_evaluations", [](auto& o) { o.max_evaluations = 0; }},
      {"max_evaluations", [](auto& o) { o.max_evaluations = std::int64_t{1} << 40; }},
      {"initial_step", [](auto& o) { o.initial_step = 0.0; }},
      {"x_tolerance", [](auto& o) { o.x_tolerance = -1.0; }},
      {"function_tolerance", [](auto& o) { o.function_tolerance = INFINITY; }},
      {"population", [](auto& o) { o.population = -3; }},
      {"checkpoint_every", [](auto& o) { o.checkpoint_every = -1; }},
      {"on_checkpoint", [](auto& o) { o.checkpoint_every = 10; }},
      {"resume_from",
       [](auto& o) {
         o.resume_from = nlohmann::json{{"format", kCheckpointFormat}, {"method", "sbplx"}};
       }},
  };
  std::string error;
  EXPECT_TRUE(NloptOptions{}.IsValid(&error)) << error;
  auto objective = NegatedRosenbrock(RosenbrockSpec());
  for (const auto& [field, mutate] : cases) {
    NloptOptions options;
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
  EXPECT_EQ(NloptAlgorithmFromName("crs2"), NloptAlgorithm::kCrs2);
  EXPECT_EQ(NloptAlgorithmFromName("CRS2"), std::nullopt);
}

}  // namespace
}  // namespace pegasus
