#pragma once
// The training layer: a plan of optimizer stages run one after another, the best theta of each the start of
// the next (thesis §5.3: gradient ascent, then random-walk hill climbing from its result), with
//   - seeds derived per stage in one place (DeriveOptimizerSeeds), apart from the scenarios' streams;
//   - one checkpoint schema for the whole plan (below), so a killed run resumes bit-identically in any stage;
//   - one merged history: iterations, evaluations and seconds count on across stages;
//   - iteration callbacks (run_progress.hpp's IterationCallback) for progress, logging and early stops.
//
//   TrainingPlan plan;
//   plan.seed = run_seed;
//   plan.stages = {{.name = "gradient", .optimizer = gradient_options},
//                  {.name = "refine", .optimizer = hill_climbing_options}};
//   TrainingSummary summary;
//   Theta theta;                      // empty: the spec's initial values
//   Train(plan, objective, &theta, &summary);
//
// Checkpoint (a JSON object, handed to plan.on_checkpoint after every checkpoint of a stage and at the end of
// every stage but the last):
//   format     "pegasus.training.checkpoint"
//   version    1
//   stage      index of the stage running (or about to run)
//   finished   [SummaryToJson of each finished stage]
//   optimizer  the running stage's optimizer checkpoint, or null at a stage boundary
//   caller     plan.caller_state() at that moment, or null without one
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus {

inline constexpr std::string_view kTrainingCheckpointFormat = "pegasus.training.checkpoint";
inline constexpr int kTrainingCheckpointVersion = 1;

// The seed domains of a stage's optimizers: each method that draws random numbers (kMethod.seed_domain != 0,
// optimizer_method.hpp) gets mix_seed(run seed, its domain), so a stage's optimizer never shares a stream
// with the scenarios or with another stage. Keyed by the method's options section ("hill_climbing", "cmaes").
class SeedDomains {
 public:
  // Each random method's first-stage domain (kMethod.seed_domain): what every trainer uses for its first
  // stage.
  SeedDomains();
  // Each random method's refinement domain (kMethod.refine_seed_domain): apart from the first stage's.
  static SeedDomains Refine();

  // The domain of the method whose options section is `section`; InputError when no random method has it.
  std::uint32_t of(std::string_view section) const;
  void set(std::string_view section, std::uint32_t domain);
  // (section, domain) of every random method, in kOptimizerMethods' order.
  const std::vector<std::pair<std::string_view, std::uint32_t>>& all() const { return domains_; }

  bool operator==(const SeedDomains&) const = default;

 private:
  std::vector<std::pair<std::string_view, std::uint32_t>> domains_;
};

// Sets every random method's seed in *options from the run's seed and the stage's domains.
void DeriveOptimizerSeeds(std::uint64_t run_seed, const SeedDomains& domains, OptimizerOptions* options);

struct TrainingStage {
  // Names the stage in reports and messages ("race", "refine"). Non-empty.
  std::string name;
  // The stage's optimizer (its seeds are set by Train from the plan's seed and `seeds`, unless
  // derive_seeds is false; its checkpointing by the plan). method "none" skips the stage.
  OptimizerOptions optimizer;
  SeedDomains seeds{};
  // False: the optimizer's own seeds are used as they are (a caller that chose them itself).
  bool derive_seeds = true;
  // The stage's objective; null: the one passed to Train (a refinement may use more scenarios).
  Objective* objective = nullptr;
  // Maps the theta the stage starts from (the previous stage's best, or Train's start) to this stage's
  // parameters; null: as it is. For a refinement that frees parameters an earlier stage held fixed.
  std::function<Theta(const Theta&)> start_from = nullptr;
};

struct TrainingPlan {
  std::vector<TrainingStage> stages;
  // A best U-hat that is not finite throws NonFiniteObjective (a run on it must never end as a success);
  // false: Train returns it, for a caller that reports it as its own verdict (mujoco train: summary.json's
  // uhat_finite and exit code 1).
  bool refuse_nonfinite_result = true;
  // The run's seed: the root of every stage's optimizer seeds.
  std::uint64_t seed = 1;
  // Optimizer iterations between checkpoints (0: none); every checkpoint goes to on_checkpoint.
  std::int64_t checkpoint_every = 0;
  CheckpointCallback on_checkpoint;
  // A checkpoint from on_checkpoint: the plan continues exactly where it was.
  std::optional<nlohmann::json> resume_from;
  // Called after every iteration of every stage (not owned). A kTerminate ends the current stage with
  // USER_REQUESTED and skips the stages after it.
  IterationCallbacks callbacks;
  // The caller's own state, stored in every checkpoint under "caller" (what it must restore on resume besides
  // the optimizers, such as clocks and measurements taken while training); the caller reads it back from
  // resume_from->at("caller").
  std::function<nlohmann::json()> caller_state;

  // False, with "stages[k].<field>: expected ..." in *error, when the plan cannot run.
  bool IsValid(std::string* error) const;
};

struct TrainingSummary {
  // One per stage that ran, in order (skipped stages have none).
  std::vector<OptimizerSummary> stages;
  std::vector<std::string> stage_names;
  // Merged: iterations, evaluations and seconds count on from the previous stage, and the value is the best
  // so far over all stages.
  std::vector<IterationRecord> history;
  double initial_value = 0;  // the first stage's initial U-hat
  double best_value = 0;     // the last stage's best U-hat
  Theta best_theta;
  bool stopped_by_callback = false;

  std::string BriefReport() const;  // one line per stage
};

// Optimizer iterations done by the plan that wrote `checkpoint` (its finished stages and the running one):
// where a progress bar of a resumed run starts. InputError when it is not a training checkpoint.
std::int64_t TrainingCheckpointIterations(const nlohmann::json& checkpoint);

// A training whose best U-hat is not finite (NaN, or infinite): the objective gave no result a run may end
// with. The CLI exits 1 on it (a failure, never a success).
class NonFiniteObjective : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Runs the plan from *theta (empty: the spec's initial values); *theta becomes the last stage's best.
// InputError for an invalid plan or a checkpoint that does not belong to it; NonFiniteObjective when the best
// U-hat found is not finite.
void Train(const TrainingPlan& plan, Objective& objective, Theta* theta, TrainingSummary* summary);

}  // namespace pegasus
