// Augmented Random Search (Mania, Guy and Recht 2018): the step of Algorithm 2, top-b selection, the
// normalising objective's hook, the best central theta as the result, and option validation.
#include "pegasus/optimizers/augmented_random_search.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "pegasus/core/error.hpp"
#include "pegasus/optimizers/hill_climbing.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using ::testing::StartsWith;

ParameterSpec Plane(int n) {
  ParameterSpec spec;
  for (int i = 0; i < n; ++i) spec.add({.name = "x" + std::to_string(i), .scale = 0.5 + i});
  return spec;
}

TEST(AugmentedRandomSearch, OneDirectionStepsTwoAlphaAlongTheBetterSideOfTheSameNormals) {
  // On a linear objective c.theta with one direction, sigma_R = |U+ - U-| / 2, so the step is
  // 2 alpha sign(c.delta) delta in scaled units, whatever the slope's size.
  const std::vector<double> c = {3.0, -1.0, 0.5};
  FunctionObjective objective(
      Plane(3), [&](std::span<const double> x) { return c[0] * x[0] + c[1] * x[1] + c[2] * x[2]; });
  AugmentedRandomSearchOptions options;
  options.max_iterations = 1;
  options.directions = 1;
  options.top_directions = 1;
  options.step_size = 0.1;
  options.seed = 9;
  Theta theta = {0.0, 0.0, 0.0};
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);

  UniformStream uniforms(options.seed, options.stream);
  std::vector<double> delta(3);
  FillStandardNormals(uniforms, delta);
  const Theta scale = Plane(3).scales();
  double slope = 0.0;
  for (int i = 0; i < 3; ++i)
    slope += c[static_cast<std::size_t>(i)] * scale[static_cast<std::size_t>(i)] *
             delta[static_cast<std::size_t>(i)];
  for (std::size_t i = 0; i < 3; ++i)
    EXPECT_NEAR(theta[i], 2.0 * options.step_size * (slope > 0 ? 1.0 : -1.0) * scale[i] * delta[i], 1e-12);
  EXPECT_GT(summary.best_value, 0.0);
  EXPECT_EQ(summary.evaluations, 1 + 2 + 1);
}

TEST(AugmentedRandomSearch, ClimbsAConcaveQuadraticWithTopDirectionsOnly) {
  ParameterSpec spec = Plane(4);
  auto objective = ConcaveQuadratic(spec, {1.0, -2.0, 0.5, 3.0}, {1.0, 1.0, 2.0, 2.0});
  AugmentedRandomSearchOptions options;
  options.max_iterations = 300;
  options.directions = 6;
  options.top_directions = 3;
  options.step_size = 0.05;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_GT(summary.best_value, summary.initial_value);
  EXPECT_NEAR(theta[0], 1.0, 0.05);
  EXPECT_NEAR(theta[3], 3.0, 0.05);
  EXPECT_EQ(summary.evaluations, 1 + 300 * 13);
}

// A normalising objective that records when the hook is called: the statistics must move only between
// iterations, never inside a batch.
class RecordingNormalizing final : public Objective, public ObservationNormalizing {
 public:
  explicit RecordingNormalizing(ParameterSpec spec) : spec_(std::move(spec)) {}
  const ParameterSpec& parameters() const override { return spec_; }
  double evaluate(std::span<const double> x) override { return -(x[0] - shift_) * (x[0] - shift_); }
  double EvaluateAndUpdateNormalizer(std::span<const double> x) override {
    const double value = evaluate(x);
    shift_ += 0.01;
    ++updates;
    return value;
  }
  nlohmann::json NormalizerState() const override { return {{"shift", shift_}}; }
  void RestoreNormalizer(const nlohmann::json& state) override { shift_ = state.at("shift").get<double>(); }
  nlohmann::json FrozenNormalizer() const override { return NormalizerState(); }
  void RestoreFrozenNormalizer(const nlohmann::json& frozen) override { RestoreNormalizer(frozen); }
  int updates = 0;

 private:
  ParameterSpec spec_;
  double shift_ = 0.0;
};

TEST(AugmentedRandomSearch, UpdatesTheNormaliserOncePerIterationAndResumesItBitForBit) {
  RecordingNormalizing objective(Plane(1));
  AugmentedRandomSearchOptions options;
  options.max_iterations = 12;
  std::vector<nlohmann::json> checkpoints;
  options.checkpoint_every = 4;
  options.on_checkpoint = [&](const nlohmann::json& c) { checkpoints.push_back(c); };
  Theta theta;
  OptimizerSummary whole;
  Solve(options, objective, &theta, &whole);
  EXPECT_EQ(objective.updates, 13);  // the start and every iteration
  ASSERT_EQ(checkpoints.size(), 3u);

  RecordingNormalizing fresh(Plane(1));
  options.resume_from = checkpoints[0];
  options.on_checkpoint = [](const nlohmann::json&) {};
  Theta resumed_theta;
  OptimizerSummary resumed;
  Solve(options, fresh, &resumed_theta, &resumed);
  std::string difference;
  EXPECT_TRUE(SameOutcome(resumed, whole, &difference)) << difference;
  EXPECT_EQ(resumed_theta, theta);
  EXPECT_EQ(fresh.NormalizerState(), objective.NormalizerState());
}

// Statistics that make every later measurement worse: U-hat = -(x - 1)^2 - shift, the shift growing by 0.01
// after each central evaluation. ARS climbs towards 1 while the penalty grows, so its best central value
// comes in the middle of the run, not at its end.
class DriftingNormalizing final : public Objective, public ObservationNormalizing {
 public:
  explicit DriftingNormalizing(ParameterSpec spec) : spec_(std::move(spec)) {}
  const ParameterSpec& parameters() const override { return spec_; }
  double evaluate(std::span<const double> x) override { return -(x[0] - 1.0) * (x[0] - 1.0) - shift_; }
  double EvaluateAndUpdateNormalizer(std::span<const double> x) override {
    central.push_back(evaluate(x));
    shift_ += 0.01;
    return central.back();
  }
  nlohmann::json NormalizerState() const override { return {{"shift", shift_}}; }
  void RestoreNormalizer(const nlohmann::json& state) override { shift_ = state.at("shift").get<double>(); }
  nlohmann::json FrozenNormalizer() const override { return NormalizerState(); }
  void RestoreFrozenNormalizer(const nlohmann::json& frozen) override { RestoreNormalizer(frozen); }
  std::vector<double> central;  // every central U-hat, in order

 private:
  ParameterSpec spec_;
  double shift_ = 0.0;
};

TEST(AugmentedRandomSearch, ReturnsTheBestCentralThetaUnderTheStatisticsItWasMeasuredWith) {
  DriftingNormalizing objective(Plane(1));
  AugmentedRandomSearchOptions options;
  options.max_iterations = 120;
  options.directions = 1;
  options.top_directions = 1;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_EQ(objective.central.size(), 121u);
  const double best = *std::max_element(objective.central.begin(), objective.central.end());
  EXPECT_EQ(summary.best_value, best);
  EXPECT_LT(objective.central.back(), best - 0.1);  // the last iterate is not the result
  EXPECT_GT(theta[0], 0.3);                         // nor is the start
  // Re-measured under the restored statistics, the returned theta gives the recorded value, bit for bit.
  EXPECT_EQ(objective.evaluate(theta), summary.best_value);
}

TEST(AugmentedRandomSearch, IsValidNamesTheField) {
  std::string error;
  AugmentedRandomSearchOptions options;
  EXPECT_TRUE(options.IsValid(&error)) << error;
  options.top_directions = 9;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("top_directions: expected 1 <= top_directions <= directions = 8"));
  options = {};
  options.exploration_noise = 0.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("exploration_noise:"));
  options = {};
  options.step_size = -1.0;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("step_size:"));
}

}  // namespace
}  // namespace pegasus
