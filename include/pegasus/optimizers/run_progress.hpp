#pragma once
// Bookkeeping shared by every optimizer: counters, the best policy so far, the history, wall time, and the
// common part of a checkpoint. Also the JSON encoding of doubles used by checkpoints.
//
// Checkpoint layout (a JSON object):
//   format        "pegasus.optimizer.checkpoint"
//   version       1
//   method        "gradient", "hill-climb", "exhaustive", "bobyqa", ...
//   parameters    parameter names, in order (a resume must use the same parameter set)
//   iterations, evaluations, elapsed_seconds, initial_value, best_value, best_theta
//   history       [[iteration, evaluations, value, seconds], ...] (empty for the NLopt methods, whose
//                 evaluation log holds the same information and rebuilds it on resume)
//   state         what the method needs to continue (documented in each method's header)
// Doubles are JSON numbers, which nlohmann writes with the shortest text that parses back to the same
// bits, so a resumed run continues from exactly the saved numbers. NaN and infinities, which JSON cannot
// hold, are written as the strings "nan", "inf" and "-inf".
#include <chrono>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

// What an IterationCallback is told at the end of every iteration of every optimizer (in the manner of
// Ceres's IterationSummary): the method, the iteration's record and the best theta so far.
struct IterationReport {
  std::string_view method;
  IterationRecord record;              // iteration, evaluations so far, best U-hat so far, seconds
  std::span<const double> best_theta;  // valid during the call only
};

enum class CallbackReturnType {
  kContinue,   // go on
  kTerminate,  // stop after this iteration: TerminationType::kUserRequested, the best so far is the result
};

// Called after every iteration (progress bars, logs, early stops; Ceres's IterationCallback). It must not
// change the objective; a run whose callbacks always continue is bit-identical to one without callbacks.
class IterationCallback {
 public:
  virtual ~IterationCallback() = default;
  virtual CallbackReturnType operator()(const IterationReport& report) = 0;
};
// Not owned: each must outlive the run.
using IterationCallbacks = std::vector<IterationCallback*>;

// Receives every checkpoint an optimizer writes. To survive a crash, write it atomically (to a temporary
// file, then rename it over the old one).
using CheckpointCallback = std::function<void(const nlohmann::json&)>;

inline constexpr std::string_view kCheckpointFormat = "pegasus.optimizer.checkpoint";
inline constexpr int kCheckpointVersion = 1;

nlohmann::json DoubleToJson(double value);
// `field` names the value in the InputError thrown when it is neither a number nor one of the strings.
double DoubleFromJson(const nlohmann::json& value, std::string_view field);
nlohmann::json VectorToJson(std::span<const double> values);
std::vector<double> VectorFromJson(const nlohmann::json& values, std::string_view field);

// A finished run's summary as JSON and back, for tasks that chain optimizer runs and must checkpoint the
// earlier ones: method, termination, message, iterations, evaluations, initial_value, best_value,
// best_theta, final_step, wall_seconds, history. `field` prefixes the names in the InputError of a bad value.
nlohmann::json SummaryToJson(const OptimizerSummary& summary);
OptimizerSummary SummaryFromJson(const nlohmann::json& summary, std::string_view field);

// The "method" of a checkpoint, so a caller can pick the optimizer that wrote it. Throws InputError when
// the JSON is not a checkpoint.
std::string CheckpointMethod(const nlohmann::json& checkpoint);

// The member `name` of a checkpoint's method state; InputError naming it when absent or, for the typed
// versions, of another type.
const nlohmann::json& StateField(const nlohmann::json& state, const char* name);
std::int64_t StateInteger(const nlohmann::json& state, const char* name);
std::uint64_t StateUnsigned(const nlohmann::json& state, const char* name);

// True when `candidate` beats `incumbent` for maximisation. NaN never beats a number and every number
// beats NaN, so one bad evaluation cannot become the best; ties keep the incumbent.
inline bool IsImprovement(double candidate, double incumbent) {
  return candidate > incumbent || (incumbent != incumbent && candidate == candidate);
}

// The most points one iteration of any method evaluates (a population, proposals, directions): past it the
// batch's memory, not the objective, decides whether a run can start (2^31 ended in std::bad_alloc).
inline constexpr int kMaxPointsPerIteration = 100000;

// For IsValid: writes "field: expected <expected>, got <got>" to *error (when non-null); returns false.
bool RejectOption(std::string* error, std::string_view field, std::string_view expected, double got);

// What every optimizer's Options hold besides their own settings: checkpointing and iteration callbacks
// (OptimizerOptions::SetCheckpointing and SetCallbacks set them for every method at once).
struct OptimizerRunOptions {
  // Write a checkpoint every this many iterations (exhaustive search: blocks; NLopt: evaluations); 0 = never.
  std::int64_t checkpoint_every = 0;
  // Receives each checkpoint; required when checkpoint_every > 0.
  CheckpointCallback on_checkpoint;
  // Continue the run that wrote this checkpoint; the starting theta passed to Solve is then ignored (NLopt
  // replays the evaluations logged in it: nlopt_optimizer.hpp).
  std::optional<nlohmann::json> resume_from;
  // Told after every iteration; one may stop the run early. Not owned.
  IterationCallbacks callbacks;

  // For a method's IsValid: false with "field: expected ..." in *error when these fields cannot run `method`
  // (a checkpoint interval without a callback, a checkpoint of another method or of no known format).
  bool IsValidFor(std::string_view method, std::string* error) const;
};

class RunProgress {
 public:
  RunProgress(std::string method, const ParameterSpec& spec, IterationCallbacks callbacks = {});

  std::int64_t iterations() const { return iterations_; }
  std::int64_t evaluations() const { return evaluations_; }
  bool has_best() const { return has_best_; }
  double best_value() const { return best_value_; }
  const Theta& best_theta() const { return best_theta_; }
  const std::vector<IterationRecord>& history() const { return history_; }

  void set_initial_value(double value) { initial_value_ = value; }
  void set_replayed_evaluations(std::int64_t count) { replayed_evaluations_ = count; }
  void AddEvaluations(std::int64_t count) { evaluations_ += count; }
  // Keeps theta as the best so far when IsImprovement(value, best); returns whether it did.
  bool Offer(std::span<const double> theta, double value);
  // Counts a completed iteration, appends it to the history and tells the callbacks; false when one of them
  // asked to stop (the optimizer then finishes with TerminationType::kUserRequested).
  bool EndIteration() { return EndIteration(Seconds()); }
  bool EndIteration(double seconds);
  // Whether the next iteration, which needs `next_evaluations` more evaluations, must not start:
  // max_iterations are done, or it would pass max_evaluations. Then *termination and *message say which, in
  // the words every method uses (`iteration` names its iteration in the message: "an iteration", "a
  // generation").
  bool BudgetSpent(std::int64_t max_iterations, std::int64_t max_evaluations, std::int64_t next_evaluations,
                   TerminationType* termination, std::string* message,
                   std::string_view iteration = "an iteration") const;
  // True when a checkpoint is due after the iteration just ended.
  bool CheckpointDue(std::int64_t checkpoint_every) const {
    return checkpoint_every > 0 && iterations_ > 0 && iterations_ % checkpoint_every == 0;
  }

  // Wall seconds since the run began, including the time recorded in a resumed checkpoint.
  double Seconds() const;

  // The full checkpoint: the common fields plus the method's `state`; the history only when asked.
  nlohmann::json Checkpoint(nlohmann::json state, bool include_history = true) const;
  // Checks that `checkpoint` was written by this method for these parameters (InputError naming the field
  // otherwise) and returns its `state`. With restore_counters, the counters, best, history and elapsed
  // time continue from the checkpoint; without (NLopt, which replays its log), only the time does.
  const nlohmann::json& Resume(const nlohmann::json& checkpoint, bool restore_counters = true);

  // Fills *summary; the history is moved out.
  void Finish(TerminationType type, std::string message, OptimizerSummary* summary);

 private:
  const nlohmann::json& ResumeUnchecked(const nlohmann::json& checkpoint, bool restore_counters);

  std::string method_;
  IterationCallbacks callbacks_;
  std::vector<std::string> parameter_names_;
  std::int64_t iterations_ = 0;
  std::int64_t evaluations_ = 0;
  std::int64_t replayed_evaluations_ = 0;
  bool resumed_ = false;
  double initial_value_;
  bool has_best_ = false;
  double best_value_;
  Theta best_theta_;
  std::vector<IterationRecord> history_;
  double seconds_before_resume_ = 0.0;
  std::chrono::steady_clock::time_point started_;
};

// The theta an optimizer starts from: `requested` clamped into the bounds, or the spec's initial values
// when `requested` is empty. Throws InputError on a size mismatch or a non-finite entry.
Theta StartingTheta(const ParameterSpec& spec, const Theta& requested);

}  // namespace pegasus
