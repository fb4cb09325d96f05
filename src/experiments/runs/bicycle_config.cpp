// The bicycle experiments' config sections (experiments/runs/bicycle_config.hpp).
#include "pegasus/experiments/runs/bicycle_config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/core/reward_limits.hpp"
#include "pegasus/runs/optimizer_config.hpp"

namespace pegasus {
namespace {

// ---- Fields shared by the sections ------------------------------------------------------------

void declare_fall_reward(ConfigSchema& s) {
  s.add_double("fall_reward", BicycleOptions{}.fall_reward, "reward of falling over (absorbing)")
      .range(-kMaxRewardWeight, 0);
}

// The objective U-hat: scenarios, discount, horizon and rewards.
void declare_objective(ConfigSchema& s) {
  const BicycleTrainingOptions d;
  s.add_int("scenarios", d.scenarios, "PEGASUS scenarios m").min(1).max(100000);
  s.add_double("gamma", d.gamma, "discount per 0.01 s step").greater_than(0).max(1);
  s.add_int("horizon", d.horizon, "training rollout length H (steps of 0.01 s)").min(1).max(1000000);
  s.add_double("shaping_per_metre", d.shaping_per_metre,
               "shaping potential per metre of progress towards the goal")
      .range(0, kMaxRewardWeight);
  declare_fall_reward(s);
}

// The objective, and how it is searched.
void declare_training(ConfigSchema& s) {
  const BicycleTrainingOptions d;
  declare_objective(s);
  s.add_string("variant", to_string(d.variant), "scenario variant").choices(scenario_variant_names());
  s.add_string("initial_policy", d.initial_policy,
               "starting weights: a crude hand-set balancing feedback, or all zero")
      .choices({"balance", "zero"});
  // Bounded-step gradient ascent (thesis 4.6) by default; every method for a continuous class without bounds.
  declare_optimizer_options(s, "optimizer", d.optimizer, continuous_class_methods(false));
}

void declare_policy(ConfigSchema& s) {
  s.add_string("policy", "", "policy file (JSON with parameter names and values)").input_file();
}

// `least_rides`: 0 where rides are optional (bicycle train), else 1.
void declare_riding(ConfigSchema& s, std::int64_t rides, std::int64_t least_rides) {
  const BicycleRideOptions d;
  s.add_int("rides", rides,
            "rides of each policy, from the initial-state distribution with fresh noise" +
                std::string(least_rides == 0 ? " (0: none)" : ""))
      .min(static_cast<double>(least_rides))
      .max(1000000);
  s.add_double("max_km", d.max_km, "a ride that has not reached the goal stops after this distance")
      .greater_than(0)
      .max(1000);
  s.add_double("goal_km", d.bicycle.goal.x / 1000.0, "distance of the goal from the start")
      .greater_than(0)
      .max(100);
  s.add_double("goal_radius", d.bicycle.goal.radius, "radius of the goal circle (m)").greater_than(0);
  // A goal circle around the start would count every ride as reached at 0 km.
  s.add_constraint([](const ConfigSchema& c) {
    const double distance_m = 1000 * c.get_double("goal_km"), radius_m = c.get_double("goal_radius");
    return radius_m < distance_m ? std::string()
                                 : fmt::format(
                                       "goal_radius: expected less than the goal's distance ({:g} m, "
                                       "goal_km), got {:g} m: the rides would start inside the goal",
                                       distance_m, radius_m);
  });
}

}  // namespace

BicycleTrainingOptions read_bicycle_objective_config(const ConfigSchema& c, std::uint64_t seed, int threads) {
  BicycleTrainingOptions o;
  o.scenarios = static_cast<int>(c.get_int("scenarios"));
  o.gamma = c.get_double("gamma");
  o.horizon = static_cast<int>(c.get_int("horizon"));
  o.shaping_per_metre = c.get_double("shaping_per_metre");
  o.bicycle.fall_reward = c.get_double("fall_reward");
  o.seed = seed;
  o.threads = threads;
  return o;
}

BicycleTrainingOptions read_bicycle_training_config(const ConfigSchema& c, std::uint64_t seed, int threads) {
  BicycleTrainingOptions o = read_bicycle_objective_config(c, seed, threads);
  o.variant = parse_scenario_variant(c.get_string("variant"));
  o.initial_policy = c.get_path("initial_policy");
  read_optimizer_options(c, "optimizer", &o.optimizer);
  return o;
}

BicycleRideOptions read_bicycle_ride_config(const ConfigSchema& c, std::uint64_t seed) {
  BicycleRideOptions o;
  o.rides = static_cast<int>(c.get_int("rides"));
  o.max_km = c.get_double("max_km");
  o.bicycle.goal = BicycleGoal::circle(1000.0 * c.get_double("goal_km"), 0.0, c.get_double("goal_radius"));
  o.bicycle.fall_reward = c.get_double("fall_reward");
  o.seed = bicycle_ride_seed(seed, 0);  // apart from the training scenarios
  return o;
}

void declare_bicycle_experiment_config(ConfigSchema& s) {
  const BicycleExperimentOptions d;
  s.add_int("trials", d.trials, "independent trainings (scenario sets)").min(1).max(100000);
  s.add_int("lesson_trials", d.lesson_trials,
            "the first scenario sets (at most trials) on which the progress bonus and naive Monte Carlo are "
            "also trained")
      .min(0)
      .max(100000);
  declare_training(s);
  declare_riding(s, 50, 1);
}

BicycleExperimentOptions read_bicycle_experiment_config(const ConfigSchema& c, std::uint64_t seed,
                                                        int threads) {
  BicycleExperimentOptions o;
  o.trials = static_cast<int>(c.get_int("trials"));
  o.lesson_trials = static_cast<int>(std::min(c.get_int("lesson_trials"), c.get_int("trials")));
  o.training = read_bicycle_training_config(c, seed, threads);
  o.riding = read_bicycle_ride_config(c, seed);
  o.seed = seed;
  o.threads = threads;
  return o;
}

void declare_bicycle_train_config(ConfigSchema& s) {
  declare_training(s);
  declare_riding(s, 20, 0);
}

void declare_bicycle_ride_config(ConfigSchema& s) {
  declare_policy(s);
  declare_fall_reward(s);
  declare_riding(s, 50, 1);
}

void declare_bicycle_variance_config(ConfigSchema& s) {
  declare_policy(s);
  s.add_int("sets", 100, "independent scenario sets per method").min(2).max(1000000);
  declare_objective(s);
}

Theta read_bicycle_policy_config(const ConfigSchema& c) {
  const std::string file = c.get_path("policy");
  if (file.empty())
    throw InputError("--policy: expected a policy file (policy.json of pegasus bicycle train)");
  return read_bicycle_policy(file);
}

}  // namespace pegasus
