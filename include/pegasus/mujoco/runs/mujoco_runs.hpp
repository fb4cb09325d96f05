#pragma once
// PEGASUS policy search on any MJCF model (issue 18) written to a run directory through a RunSink (the
// `mujoco train` and `mujoco rollout` commands map their options onto these). Only with PEGASUS_MUJOCO.
//   run_mujoco_training  the search (checkpointed, resumable), then the final policy on held-out scenarios:
//                        policy.json, progress.csv, evaluation.csv, replay.json, summary.json;
//   run_mujoco_rollout   a policy file's episodes: returns.csv, trajectory.csv (episode 0), replay.json.
#ifdef PEGASUS_HAVE_MUJOCO
#include <cstdint>
#include <string>
#include <vector>

#include "pegasus/mujoco/mujoco_objective.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/run_sink.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {

// ARS (Mania, Guy and Recht 2018) by default, 100 iterations of every iterative method.
OptimizerOptions mujoco_default_optimizer();

struct MujocoTrainingRunOptions {
  std::string model_file;               // MJCF
  std::string task_file;                // TOML naming the model's parts
  std::string policy_class = "linear";  // a registered class (mujoco_policy_class_names())
  std::vector<int> hidden = {16};       // the mlp's hidden widths
  std::string phase_observation;        // phased policy switched by this observation number ("" none)
  double phase_above = 0.0;             // the "above" half acts while that number exceeds this
  bool normalize = true;                // running observation statistics (ARS V2)
  OptimizerOptions optimizer = mujoco_default_optimizer();  // its seeds: the run's
  int scenarios = 8;                                        // PEGASUS scenarios per evaluation of U-hat
  ScenarioVariant variant = ScenarioVariant::kPlain;
  int evaluation_episodes = 100;       // held-out scenarios for the final return and success rate
  std::int64_t checkpoint_every = 10;  // iterations
  std::string initial_policy_file;     // start from this policy.json's theta (normalize = false)
  // Wall seconds after which the search stops at the end of its iteration with the best policy so far
  // (termination USER_REQUESTED); 0: no budget. Counted from this call (a resumed run gets it afresh). A run
  // stopped by it depends on the machine's speed: its summary says so.
  double time_budget_seconds = 0.0;
  std::uint64_t seed = 1;
};
// Returns the exit status: 0, or 1 when U-hat of the result is not finite (the run is written, its summary
// says so, one line is printed: such a run is never a success).
int run_mujoco_training(const MujocoTrainingRunOptions& options, RunSink& sink, ThreadPool& pool);

struct MujocoRolloutRunOptions {
  std::string policy_file;  // policy.json of run_mujoco_training
  std::string task_file;    // another task file for the policy's model ("" the one it was trained on)
  int episodes = 10;        // the first is recorded step by step
  std::uint64_t seed = 1;   // the training's seed replays its held-out episodes
};
// Episodes run in parallel on `pool`; the results do not depend on its size.
void run_mujoco_rollout(const MujocoRolloutRunOptions& options, RunSink& sink, ThreadPool& pool);

}  // namespace pegasus
#endif
