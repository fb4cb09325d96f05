#pragma once
// PEGASUS on Gymnasium's Pendulum-v1 (envs/pendulum.hpp): the race against RLtools of issue 7.
//
// Training (train_pendulum): the swing-up policy class (envs/pendulum_policy.hpp) is searched on m fixed
// PEGASUS scenarios (Eq 4.22; a scenario is a start state, the steps are deterministic), H = 200 steps,
// gamma = 1 (the undiscounted return Gymnasium reports), by any optimizer of optimizers/optimizer.hpp
// (random-walk hill climbing by default).
//
// The bar: the mean return over `evaluation_episodes` fresh starts (a scenario set of its own seed,
// independent of the training scenarios) must reach `bar` (-200). Every time the search finds a new best
// U-hat, that policy is evaluated on those episodes; the first time it reaches the bar, the wall time since
// the start of training (evaluations included) is seconds_to_bar. The search then runs on to its budget,
// and the final policy's mean return over the same episodes is mean_return_100.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pegasus/envs/pendulum.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {

struct PendulumTrainingOptions {
  int scenarios = 32;  // m: training start states
  int horizon = PendulumConstants::episode_steps;  // H (steps of 0.05 s)
  ScenarioVariant variant = ScenarioVariant::kPlain;
  OptimizerOptions optimizer = default_optimizer();
  int evaluation_episodes = 100;  // fresh starts for the bar and the final mean return
  double bar = -200.0;            // mean return that counts as solved
  std::uint64_t seed = 1;         // training scenarios, the optimizer, and (derived) the evaluation starts
  int threads = 1;

  static OptimizerOptions default_optimizer();
  bool IsValid(std::string* error) const;
};

struct PendulumTrainingHooks {
  std::int64_t checkpoint_every = 0;          // optimizer iterations between checkpoints (0: none)
  CheckpointCallback on_checkpoint;           // receives {"optimizer": ..., "bar": ...}
  std::optional<nlohmann::json> resume_from;  // a state given to on_checkpoint
};

// One look at the evaluation episodes, made when the search found a new best U-hat.
struct PendulumBarCheck {
  double seconds = 0.0;           // wall time since training began
  std::int64_t evaluations = 0;   // U-hat evaluations so far
  double uhat = 0.0;              // the new best U-hat (training scenarios)
  double mean_return = 0.0;       // mean return over the evaluation episodes
};

struct PendulumTrainingResult {
  Theta theta;
  OptimizerSummary summary;
  double mean_return_100 = 0.0;   // final policy, evaluation episodes
  double seconds_to_bar = 0.0;    // NaN when the bar was never reached
  // Processor time of this process (all its threads) until then: robust when the machine is shared.
  double cpu_seconds_to_bar = 0.0;
  std::int64_t evaluations_to_bar = -1;  // -1 when never reached
  std::vector<PendulumBarCheck> checks;
};

PendulumTrainingResult train_pendulum(const PendulumTrainingOptions& options, const PendulumTrainingHooks& hooks = {},
                                      ThreadPool* pool = nullptr);

// Seed of the evaluation starts, apart from the training scenarios' seed.
std::uint64_t pendulum_evaluation_seed(std::uint64_t seed);
// Returns of theta over `episodes` starts of ScenarioSet(seed), each a 200-step episode.
std::vector<double> pendulum_episode_returns(const Theta& theta, int episodes, std::uint64_t seed,
                                             ThreadPool* pool = nullptr);

// {"policy": "pendulum-swing-up", "parameters": {"swing.gain": ..., ...}}.
nlohmann::json pendulum_policy_json(const Theta& theta);

}  // namespace pegasus
