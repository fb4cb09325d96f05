// Rollouts stepped in lockstep (envs/bicycle_lockstep.hpp) are the single rollouts, bit for bit.
#include "pegasus/envs/bicycle_lockstep.hpp"

#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "pegasus/envs/bicycle.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/random/counter_rng.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {
namespace {

// Policies that fall at once (w = 0), balance (the hand-set start), and random ones in between, so that
// lanes end at different steps and some run to the horizon.
std::vector<Theta> assorted_thetas() {
  std::vector<Theta> thetas = {Theta(30, 0.0), bicycle_balancing_theta()};
  UniformStream rng(29, 0);
  for (int k = 0; k < 4; ++k) {
    Theta t = bicycle_balancing_theta();
    for (double& w : t) w += 0.8 * (rng.next() - 0.5);
    thetas.push_back(t);
  }
  return thetas;
}

template <class Model>
void expect_lockstep_matches_single(const Model& model, const ScenarioSet& scenarios, const Discounting& d) {
  const BicyclePolicy policy = make_bicycle_policy();
  const std::vector<Theta> thetas = assorted_thetas();
  // Every (theta, scenario) pair, in groups of up to 4 lanes that mix thetas and scenarios; the last group
  // is partial.
  std::vector<std::pair<int, int>> pairs;
  for (int t = 0; t < static_cast<int>(thetas.size()); ++t)
    for (int i = 0; i < scenarios.size(); ++i) pairs.push_back({t, i});
  pairs.pop_back();  // 6 * 7 - 1 = 41 pairs: ten groups of 4 and one of 1
  int ended_early = 0, ran_through = 0;
  for (std::size_t first = 0; first < pairs.size(); first += 4) {
    const std::size_t lanes = std::min<std::size_t>(4, pairs.size() - first);
    std::array<std::span<const double>, 4> lane_theta;
    std::array<int, 4> lane_scenario{};
    std::array<double, 4> out{};
    for (std::size_t j = 0; j < lanes; ++j) {
      lane_theta[j] = thetas[static_cast<std::size_t>(pairs[first + j].first)];
      lane_scenario[j] = pairs[first + j].second;
    }
    lockstep_returns<4>(model, policy, std::span(lane_theta).first(lanes),
                        std::span<const int>(lane_scenario).first(lanes), scenarios, d,
                        std::span(out).first(lanes));
    for (std::size_t j = 0; j < lanes; ++j) {
      const double single = scenario_return(model, policy, lane_theta[j], scenarios, lane_scenario[j], d);
      EXPECT_EQ(out[j], single) << "pair " << first + j;  // bit for bit
      (single < -50.0 ? ended_early : ran_through) += 1;
    }
  }
  EXPECT_GT(ended_early, 0);  // falls (w = 0) ...
  EXPECT_GT(ran_through, 0);  // ... and rides to the horizon were both compared
}

TEST(BicycleLockstep, ReturnsAreTheSingleRolloutsBitForBit) {
  const Bicycle bike(BicycleTrainingOptions::default_bicycle());
  const Discounting d{.gamma = 0.998, .horizon = 300};
  for (const ScenarioVariant variant : {ScenarioVariant::kPlain, ScenarioVariant::kSobol}) {
    const ScenarioSet scenarios(
        {.seed = 8, .count = 7, .horizon = 300, .noise_dim = 1, .initial_noise_dim = 5, .variant = variant});
    expect_lockstep_matches_single(bike, scenarios, d);
    expect_lockstep_matches_single(shape(bike, BicycleProgressPotential{bike, 1.0}, d.gamma), scenarios, d);
    expect_lockstep_matches_single(
        ProgressBonusModel<Bicycle, BicycleGoalDistance>(bike, BicycleGoalDistance{bike}, 0.0278), scenarios,
        d);
  }
}

// The training objective (lockstep) gives PegasusEvaluator's U-hat bit for bit, on one thread or two.
TEST(BicycleLockstep, TrainingObjectiveIsPegasusEvaluatorsUhat) {
  BicycleTrainingOptions o;
  o.scenarios = 9;
  o.horizon = 250;
  o.seed = 5;
  const Bicycle bike(o.bicycle);
  const PegasusEvaluator evaluator(shape(bike, BicycleProgressPotential{bike, o.shaping_per_metre}, o.gamma),
                                   make_bicycle_policy(),
                                   ScenarioSet({.seed = o.seed,
                                                .count = o.scenarios,
                                                .horizon = o.horizon,
                                                .noise_dim = 1,
                                                .initial_noise_dim = 5}),
                                   Discounting{.gamma = o.gamma, .horizon = o.horizon});
  for (const Theta& theta : assorted_thetas()) {
    const double expected = evaluator.evaluate(theta);
    for (int threads : {1, 2}) {
      o.threads = threads;
      EXPECT_EQ(bicycle_uhat(o, theta), expected) << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace pegasus
