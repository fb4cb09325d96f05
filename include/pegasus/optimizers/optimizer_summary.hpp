#pragma once
// What an optimizer run reports (the shape of Ceres' GradientProblemSolver::Summary): counters, the best
// policy found, why the run stopped, and a per-iteration history for plots.
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

enum class TerminationType {
  kConvergence,     // a convergence test passed (step too small, no relative improvement, NLopt tolerance)
  kMaxIterations,   // the iteration limit was reached
  kMaxEvaluations,  // the objective-evaluation limit was reached
  kSearchComplete,  // exhaustive search enumerated every policy
  kFailure,         // the method could not continue (non-finite derivative, NLopt failure)
  kUserRequested,   // an IterationCallback asked to stop (an early stop; the best so far is the result)
};

// "CONVERGENCE", "MAX_ITERATIONS", "MAX_EVALUATIONS", "SEARCH_COMPLETE", "FAILURE", "USER_REQUESTED".
std::string_view TerminationTypeName(TerminationType type);

// One row of the history, written at the end of every iteration.
struct IterationRecord {
  std::int64_t iteration = 0;    // 1-based count of completed iterations
  std::int64_t evaluations = 0;  // objective evaluations so far, this iteration's included
  double value = 0.0;            // best U-hat found so far
  double seconds = 0.0;          // wall time since the run began (time before a resume included)
};

struct OptimizerSummary {
  // Method name as the dispatcher spells it: "exhaustive", "gradient", "hill-climb", "bobyqa", ...
  std::string method;
  std::vector<std::string> parameter_names;

  TerminationType termination_type = TerminationType::kFailure;
  // Human-readable reason for stopping, with the numbers that triggered it.
  std::string message = "Solve was not called";

  // Completed iterations. What an iteration is depends on the method: one gradient step (gradient), one
  // batch of proposals (hill-climb), one block of policies (exhaustive), one evaluation (NLopt methods),
  // one generation (cmaes).
  std::int64_t iterations = 0;
  // Objective evaluations from the start of the run, including those made before a resume.
  std::int64_t evaluations = 0;
  // NLopt resume only: evaluations answered from the checkpoint's log instead of calling the objective.
  std::int64_t replayed_evaluations = 0;
  bool resumed = false;

  // U-hat at the (clamped) starting theta; NaN where the method never evaluates it (exhaustive search,
  // or an NLopt algorithm whose first evaluation is elsewhere).
  double initial_value = std::numeric_limits<double>::quiet_NaN();
  double best_value = std::numeric_limits<double>::quiet_NaN();
  Theta best_theta;
  // Gradient ascent and hill climbing: the step length (scaled units) when the run stopped; CMA-ES: sigma
  // (scaled units); NaN otherwise.
  double final_step = std::numeric_limits<double>::quiet_NaN();

  // Wall time of the whole run, including the time spent before a resume.
  double wall_seconds = 0.0;
  std::vector<IterationRecord> history;
  // Exhaustive search with keep_all_values: U-hat of every policy, in enumeration order.
  std::vector<double> all_values;

  // One line: method, termination, iterations, evaluations, best value, time.
  std::string BriefReport() const;
  // Several lines: everything above plus the message and the best theta by parameter name.
  std::string FullReport() const;
};

// True when two runs ended identically: method, termination and message, counters, best value and theta,
// initial and final step, history and all_values, every double compared bit for bit (any NaN equals any NaN).
// Wall seconds, `resumed` and `replayed_evaluations` are ignored, so an interrupted-and-resumed run can be
// compared with an uninterrupted one. On a difference, *difference (when non-null) names the first one.
bool SameOutcome(const OptimizerSummary& a, const OptimizerSummary& b, std::string* difference = nullptr);

}  // namespace pegasus
