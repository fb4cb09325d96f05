#pragma once
// The bicycle experiment of thesis §4.6: PEGASUS learns to ride Randlov and Alstrom's bicycle to a goal
// 1 km away.
//
// Training (train_bicycle): the bicycle model with its goal infinitely far away (the distance to the goal
// is not a feature, footnote 15), the 15-feature sigmoid policy class (envs/bicycle_policy.hpp), m = 30
// PEGASUS scenarios, gamma = 0.998, H = 500 steps (5 s), continuous-time discounting of the fall (footnote
// 9), and a shaping reward for progress towards the goal. The optimizer is the bounded-step gradient
// ascent of footnote 14 (or hill climbing, or any method of optimizers/optimizer.hpp).
//   shaping "potential":       F = gamma Phi(s') - Phi(s), Phi = per_metre * progress along the goal's
//                              direction (shaping/potential_shaping.hpp): the optimal policy is unchanged;
//   shaping "progress-bonus":  +per_metre * v dt whenever the bicycle got closer to the goal, nothing when
//                              it moved away (the non-potential reward of §3.1, lesson 1);
//   shaping "none".
// Estimator "pegasus" (fixed scenarios, Eq 4.22) or "montecarlo" (fresh noise every evaluation, Eq 4.10;
// lesson 2).
//
// Rides (ride_bicycle): a learned policy rides the bicycle from the initial-state distribution with fresh
// noise towards a goal circle (1 km away, 10 m radius) until it enters the circle, falls, or has ridden
// max_km. The distance of a ride is the path length of the front tyre, the last step counted up to the
// moment it entered the circle.
//
// The experiment (run_bicycle_experiment): `trials` independent trainings (scenario seeds derived from the
// seed and the trial), each policy ridden `rides` times, plus the two lessons of the thesis on the first
// `lesson_trials` scenario sets: the progress bonus instead of the potential, and naive Monte Carlo instead
// of PEGASUS, with the same optimizer and evaluation budget.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pegasus/envs/bicycle.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/parallel/execution_context.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {

struct BicycleTrainingOptions {
  int scenarios = 30;                 // m
  double gamma = 0.998;               // discount per step of 0.01 s
  int horizon = 500;                  // H (steps)
  std::string shaping = "potential";  // "potential" | "progress-bonus" | "none"
  double shaping_per_metre = 1.0;     // Phi = per_metre * progress (m); the bonus is per_metre * v dt
  std::string estimator = "pegasus";  // "pegasus" | "montecarlo"
  ScenarioVariant variant = ScenarioVariant::kPlain;
  std::string initial_policy = "balance";  // "balance" (bicycle_balancing_theta) | "zero"
  // The training bicycle: by default the goal is infinitely far away to the east.
  BicycleOptions bicycle = default_bicycle();
  // The optimizer; by default the bounded-step gradient ascent.
  OptimizerOptions optimizer = default_optimizer();
  std::uint64_t seed = 1;  // scenarios (PEGASUS) or the Monte Carlo streams
  int threads = 1;

  static BicycleOptions default_bicycle();
  static OptimizerOptions default_optimizer();
  bool IsValid(std::string* error) const;
};

struct BicycleTrainingHooks {
  std::int64_t checkpoint_every = 0;          // optimizer iterations between checkpoints (0: none)
  CheckpointCallback on_checkpoint;           // receives the training layer's checkpoint (training.hpp)
  std::optional<nlohmann::json> resume_from;  // such a checkpoint to continue (PEGASUS only)
  IterationCallbacks callbacks;               // told after every iteration (progress, early stops)
};

struct BicycleTrainingResult {
  Theta theta;               // the learned weights
  OptimizerSummary summary;  // iterations, evaluations, U-hat history
};

// Trains on where.pool when given (else a pool of options.threads), split among where.ranks.
BicycleTrainingResult train_bicycle(const BicycleTrainingOptions& options,
                                    const BicycleTrainingHooks& hooks = {},
                                    const ExecutionContext& where = {});

// U-hat of theta on m scenarios of the training problem (the objective train_bicycle maximises).
double bicycle_uhat(const BicycleTrainingOptions& options, const Theta& theta,
                    const ExecutionContext& where = {});

struct BicycleRideOptions {
  int rides = 50;
  double max_km = 10.0;      // a ride that has not reached the goal after this path length stops
  BicycleOptions bicycle{};  // default: the goal circle of bike.c, (1000, 0) m, radius 10 m
  std::uint64_t seed = 1;
  int path_every = 0;  // keep every k-th front tyre position for plots (0: none)
  bool IsValid(std::string* error) const;
};

struct BicycleRide {
  double distance_km = 0.0;  // path length of the front tyre until the goal, a fall or max_km
  bool reached = false;
  bool fell = false;
  std::vector<double> x{}, y{};  // sampled front tyre positions (path_every > 0)
};

struct BicycleRideSummary {
  int rides = 0, reached = 0, falls = 0;
  // Median and largest distance over the rides that reached the goal (NaN when none did).
  double median_distance_km = 0.0, worst_distance_km = 0.0;
};

std::vector<BicycleRide> ride_bicycle(const Theta& theta, const BicycleRideOptions& options,
                                      ThreadPool* pool = nullptr);
BicycleRideSummary summarize_rides(const std::vector<BicycleRide>& rides);

struct BicycleExperimentOptions {
  int trials = 10;
  int lesson_trials = 2;  // scenario sets on which the two lessons are measured (0: none)
  BicycleTrainingOptions training{};
  BicycleRideOptions riding{};
  std::uint64_t seed = 1;
  int threads = 1;
  bool IsValid(std::string* error) const;
};

// One trained policy and its rides.
struct BicycleTrial {
  std::string method;  // "pegasus" | "progress-bonus" | "montecarlo"
  int trial = 0;       // scenario set index
  Theta theta;
  double initial_uhat = 0.0, final_uhat = 0.0;
  // U-hat of the final theta on the trial's PEGASUS scenarios with potential shaping (the objective of the
  // main method; for the lessons it says how good their policy is by the main method's yardstick).
  double pegasus_uhat = 0.0;
  std::int64_t iterations = 0, evaluations = 0;
  std::vector<double> curve;  // best U-hat after each optimizer iteration
  BicycleRideSummary summary;
  std::vector<BicycleRide> rides;  // without paths
};

struct BicycleExperimentHooks {
  std::function<void(const BicycleTrial&)> on_trial;         // after each finished trial
  std::function<void(const nlohmann::json&)> on_checkpoint;  // state to save (trials so far, optimizer)
  std::optional<nlohmann::json> resume_from;
  std::int64_t checkpoint_every = 10;  // optimizer iterations between mid-training checkpoints
};

struct BicycleExperimentResult {
  std::vector<BicycleTrial> trials;   // PEGASUS trials first (trial order), then the lessons
  double median_of_medians_km = 0.0;  // over the PEGASUS policies
};

BicycleExperimentResult run_bicycle_experiment(const BicycleExperimentOptions& options,
                                               const BicycleExperimentHooks& hooks = {});

// Seeds of trial k: its training scenarios and its rides.
std::uint64_t bicycle_training_seed(std::uint64_t seed, int trial);
std::uint64_t bicycle_ride_seed(std::uint64_t seed, int trial);

// The policy file: {"policy": "bicycle-sigmoid-15", "parameters": {"w.T.omega": 0.5, ...}} with every
// parameter of make_bicycle_policy(). read_bicycle_policy throws InputError naming the file and field.
nlohmann::json bicycle_policy_json(const Theta& theta);
Theta read_bicycle_policy(const std::filesystem::path& file);
Theta bicycle_policy_from_json(const nlohmann::json& j, const std::string& source);

nlohmann::json to_json(const BicycleTrial& trial);
BicycleTrial bicycle_trial_from_json(const nlohmann::json& j);

}  // namespace pegasus
