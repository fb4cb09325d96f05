// The bicycle experiment as a library: shaping, rides, checkpoints.
#include "pegasus/experiments/bicycle_experiment.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "pegasus/envs/bicycle.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/evaluators/rollout.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {
namespace {

// Potential-based shaping telescopes along a rollout: the shaped return minus the unshaped one is
// gamma^H Phi(s_H) - Phi(s_0) for a ride cut at H, and -Phi(s_0) for one that falls (Phi = 0 there), so
// the shaping pays exactly the progress made along the goal's direction (§4.6 footnote 15).
TEST(BicycleShaping, PotentialShapingPaysTheDiscountedProgress) {
  const BicycleOptions options = BicycleTrainingOptions::default_bicycle();
  const Bicycle bike(options);
  const double gamma = 0.998;
  const auto shaped = shape(bike, BicycleProgressPotential{bike, 2.0}, gamma);
  const BicyclePolicy policy = make_bicycle_policy();
  const ScenarioSet scenarios(
      {.seed = 4, .count = 6, .horizon = 400, .noise_dim = 1, .initial_noise_dim = 5});
  const Discounting d{.gamma = gamma, .horizon = 400};
  for (const Theta& theta : {bicycle_balancing_theta(), Theta(30, 0.0)}) {
    for (int i = 0; i < scenarios.size(); ++i) {
      const double base = scenario_return(bike, policy, theta, scenarios, i, d);
      const double with = scenario_return(shaped, policy, theta, scenarios, i, d);
      // Replay the rollout to find its end.
      std::array<double, 5> p0;
      scenarios.initial_noise(i, p0);
      BicycleState s = bike.initial_state(p0);
      const double phi0 = 2.0 * bike.progress(s);
      int t = 0;
      for (double p = 0; t < d.horizon && !bike.terminal(s); ++t) {
        scenarios.step_noise(i, t, std::span<double>(&p, 1));
        s = bike.step(s, policy.act(theta, bike.observe(s)), std::span<const double>(&p, 1));
      }
      const double expected = bike.terminal(s) ? -phi0 : std::pow(gamma, t) * 2.0 * bike.progress(s) - phi0;
      EXPECT_NEAR(with - base, expected, 1e-9) << "scenario " << i;
    }
  }
}

BicycleExperimentOptions small_experiment() {
  BicycleExperimentOptions o;
  o.trials = 2;
  o.lesson_trials = 0;
  o.training.scenarios = 6;
  o.training.horizon = 150;
  o.training.optimizer.method = "hill-climb";
  o.training.optimizer.hill_climbing.max_iterations = 6;
  o.training.optimizer.hill_climbing.proposals_per_iteration = 4;
  o.riding.rides = 3;
  o.riding.max_km = 0.3;
  o.riding.bicycle.goal = BicycleGoal::circle(200.0, 0.0, 10.0);
  o.seed = 12;
  o.threads = 2;
  return o;
}

// A run resumed from a checkpoint taken in the middle of a training (the optimizer's own checkpoint)
// ends exactly like the uninterrupted run.
TEST(BicycleExperiment, ResumingFromAMidTrainingCheckpointGivesTheSameResult) {
  const BicycleExperimentOptions options = small_experiment();
  std::optional<nlohmann::json> mid;
  BicycleExperimentHooks hooks;
  hooks.checkpoint_every = 2;
  hooks.on_checkpoint = [&](const nlohmann::json& state) {
    if (!mid && state.at("trials").size() == 1 && state.contains("optimizer")) mid = state;
  };
  const BicycleExperimentResult whole = run_bicycle_experiment(options, hooks);
  ASSERT_TRUE(mid.has_value());
  BicycleExperimentHooks resume;
  resume.checkpoint_every = 2;
  resume.resume_from = mid;
  const BicycleExperimentResult resumed = run_bicycle_experiment(options, resume);
  ASSERT_EQ(whole.trials.size(), resumed.trials.size());
  for (std::size_t k = 0; k < whole.trials.size(); ++k)
    EXPECT_EQ(to_json(whole.trials[k]).dump(), to_json(resumed.trials[k]).dump()) << k;
  EXPECT_EQ(nlohmann::json(DoubleToJson(whole.median_of_medians_km)),
            nlohmann::json(DoubleToJson(resumed.median_of_medians_km)));
}

TEST(BicycleExperiment, TrialsRoundTripThroughJson) {
  BicycleTrial t;
  t.method = "pegasus";
  t.trial = 3;
  t.theta = bicycle_balancing_theta();
  t.curve = {0.1, 0.30000000000000004};
  t.rides = {{.distance_km = 0.99123456789, .reached = true, .fell = false},
             {.distance_km = 0.2, .reached = false, .fell = true}};
  const BicycleTrial back = bicycle_trial_from_json(to_json(t));
  EXPECT_EQ(to_json(back).dump(), to_json(t).dump());
  EXPECT_EQ(back.summary.reached, 1);
  EXPECT_EQ(back.summary.falls, 1);
  EXPECT_EQ(back.summary.median_distance_km, 0.99123456789);
}

// A ride's distance is the front tyre's path length up to the moment it enters the goal circle: riding
// straight at a goal 100 m away from rest takes 90 m.
TEST(BicycleRides, DistanceIsThePathLengthToTheGoalCircle) {
  BicycleRideOptions o;
  o.rides = 4;
  o.max_km = 0.5;
  o.bicycle.goal = BicycleGoal::circle(100.0, 0.0, 10.0);
  o.bicycle.start = {.omega = 0, .omega_dot = 0, .theta = 0, .theta_dot = 0, .goal_angle = 0};
  o.bicycle.noise = 0.0;
  o.path_every = 10;
  const auto rides = ride_bicycle(bicycle_balancing_theta(), o);
  for (const auto& r : rides) {
    EXPECT_TRUE(r.reached);
    EXPECT_FALSE(r.fell);
    EXPECT_NEAR(r.distance_km, 0.09 - 0.00111, 1e-6);  // the front tyre starts 1.11 m ahead of the origin
    EXPECT_NEAR(r.x.back(), 90.0, 0.03);
  }
}

// No-fall property on a small setting: the hand-set balancing start of training keeps the bicycle up from
// every start of the initial-state distribution (lean up to 0.05 rad, lean rate 0.1 rad/s, handlebar 0.05 rad
// and 0.2 rad/s, any heading) for 150 m of riding with the rider noise: the starts the rides draw can be
// recovered from, and a trained policy that falls from one has lost what its starting point could do.
TEST(BicycleRides, TheBalancingStartNeverFallsFromTheInitialStateDistribution) {
  BicycleRideOptions o;
  o.rides = 40;
  o.max_km = 0.15;
  o.bicycle.goal = BicycleGoal::circle(5000.0, 0.0, 10.0);  // out of reach: every ride runs its 150 m
  o.seed = 31;
  const auto rides = ride_bicycle(bicycle_balancing_theta(), o);
  const BicycleRideSummary s = summarize_rides(rides);
  EXPECT_EQ(s.falls, 0);
  EXPECT_EQ(s.reached, 0);
  for (const auto& r : rides) EXPECT_NEAR(r.distance_km, 0.15, 1e-4);
}

}  // namespace
}  // namespace pegasus
