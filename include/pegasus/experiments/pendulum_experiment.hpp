#pragma once
// PEGASUS on Gymnasium's Pendulum-v1 (envs/pendulum.hpp): the race against RLtools of issue 7.
//
// Training (train_pendulum) runs in two stages, each a PEGASUS search on fixed scenarios (Eq 4.22; a
// scenario is a start state, the steps are deterministic), H = 200 steps, gamma = 1 (the undiscounted
// return Gymnasium reports), by any optimizer of optimizers/optimizer.hpp (random-walk hill climbing by
// default):
//   race:    the five numbers of the swing-up (envs/pendulum_policy.hpp, PendulumSwingUpPolicy(false)),
//            from all gains zero, on m = `scenarios` start states: a small search that gets to the bar fast.
//   refine:  all seven numbers (the lead and the skew from 0, so it starts exactly at the race's policy),
//            on m = `refine_scenarios` other start states. The many scenarios keep the finer class from
//            fitting a few starts; U-hat can only go up on them. refine_scenarios = 0 skips this stage.
//
// The bar: the mean return over `evaluation_episodes` fresh starts (a scenario set of its own seed,
// independent of the training scenarios) must reach `bar` (-200). Every time a search finds a new best
// U-hat, that policy is evaluated on those episodes; the first time it reaches the bar, the wall time since
// the start of training (evaluations included) is seconds_to_bar. The search then runs on to its budget,
// and the final policy's mean return over the same episodes is mean_return_100.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pegasus/envs/pendulum.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {

struct PendulumTrainingOptions {
  int scenarios = 32;                              // m of the race: training start states
  int horizon = PendulumConstants::episode_steps;  // H (steps of 0.05 s), both stages
  // Both stages. Stratified (Latin hypercube) start states cover the start box evenly, which keeps the
  // searches from fitting the quirks of a few starts: on 60000 other starts the final policies of seeds
  // 1-8 averaged -143.96 against -144.15 with plain starts.
  ScenarioVariant variant = ScenarioVariant::kStratified;
  OptimizerOptions optimizer = default_optimizer();  // the race
  // m of the refinement (0: no refinement). On 60000 other starts the final policies of seeds 1-8 averaged
  // -144.26 after a refinement (100 iterations) on 32 starts (worst seed -146.37), -143.96 on 256 (worst
  // -144.59).
  int refine_scenarios = 256;
  OptimizerOptions refine_optimizer = default_refine_optimizer();
  int evaluation_episodes = 100;  // fresh starts for the bar and the final mean return
  double bar = -200.0;            // mean return that counts as solved
  std::uint64_t seed = 1;         // training scenarios, the optimizer, and (derived) the evaluation starts
  int threads = 1;

  // Hill climbing, 150 iterations of 8 proposals from a step of 1 (scaled units, at most 4).
  static OptimizerOptions default_optimizer();
  // Hill climbing, 60 iterations of 8 proposals from a step of 0.3 (at most 1): a local refinement of a
  // policy that already swings up, which a large step would throw away. (100 iterations gained 0.06 on
  // 60000 starts over seeds 1-8, for two thirds more time.)
  static OptimizerOptions default_refine_optimizer();
  bool IsValid(std::string* error) const;
};

struct PendulumTrainingHooks {
  std::int64_t checkpoint_every = 0;  // optimizer iterations between checkpoints (0: none)
  // Receives the training layer's checkpoints (optimizers/training.hpp; stage 0 is the race, 1 the
  // refinement) with the bar's clocks and checks under "caller": {"bar": ...}.
  CheckpointCallback on_checkpoint;
  std::optional<nlohmann::json> resume_from;  // a state given to on_checkpoint
};

// One look at the evaluation episodes, made when the search found a new best U-hat.
struct PendulumBarCheck {
  double seconds = 0.0;          // wall time since training began
  std::int64_t evaluations = 0;  // U-hat evaluations so far
  double uhat = 0.0;             // the new best U-hat (training scenarios)
  double mean_return = 0.0;      // mean return over the evaluation episodes
};

struct PendulumTrainingResult {
  Theta theta;                        // the final policy, all PendulumSwingUpPolicy::kCount numbers
  OptimizerSummary summary;           // the race (five numbers, `scenarios` start states)
  OptimizerSummary refine_summary;    // the refinement; method empty when it did not run
  double race_mean_return_100 = 0.0;  // the race's policy, evaluation episodes
  double mean_return_100 = 0.0;       // final policy, evaluation episodes
  double seconds_to_bar = 0.0;        // NaN when the bar was never reached
  // Processor time of this process (all its threads) until then: robust when the machine is shared.
  double cpu_seconds_to_bar = 0.0;
  std::int64_t evaluations_to_bar = -1;  // -1 when never reached
  std::vector<PendulumBarCheck> checks;
};

PendulumTrainingResult train_pendulum(const PendulumTrainingOptions& options,
                                      const PendulumTrainingHooks& hooks = {}, ThreadPool* pool = nullptr);

// A theta of the five-number class (or of the full one) as the full class: the numbers it lacks at their
// initial values (the lead and the skew 0), which acts exactly as the five-number policy.
Theta pendulum_full_theta(std::span<const double> theta);

// Seed of the evaluation starts, apart from the training scenarios' seed.
std::uint64_t pendulum_evaluation_seed(std::uint64_t seed);
// Seed of 5000 further starts on which summary.json and the benchmark report the final policy
// (mean_return_5000), apart from both.
std::uint64_t pendulum_large_evaluation_seed(std::uint64_t seed);
// Returns of theta (PendulumSwingUpPolicy::kCount numbers) over `episodes` starts of ScenarioSet(seed),
// each a 200-step episode.
std::vector<double> pendulum_episode_returns(const Theta& theta, int episodes, std::uint64_t seed,
                                             ThreadPool* pool = nullptr);

// {"policy": "pendulum-swing-up", "parameters": {"swing.gain": ..., ...}}: all seven numbers.
nlohmann::json pendulum_policy_json(const Theta& theta);
// The theta of such a file: all seven numbers, or the first five (the class without lead and skew, which
// act() reads as 0). InputError "SOURCE: field 'F': ..." naming the first bad field.
Theta pendulum_policy_from_json(const nlohmann::json& j, const std::string& source);

}  // namespace pegasus
