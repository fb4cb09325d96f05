#pragma once
// Gradient ascent on U-hat with numerically evaluated derivatives, as used for the bicycle (§4.6) and the
// helicopter hover (§5.3).
//
// Every quantity of length is in *scaled units*: parameter i moves by (units) * scale_i, where scale_i is
// the parameter's typical useful change (ParameterSpec). One iteration:
//   1. Central differences with h_i = relative_step * scale_i, all 2n probes in one evaluate_batch call.
//      Probes are clipped to the bounds and divided by the distance actually spanned.
//   2. The derivative is multiplied by scale_i (the derivative with respect to theta_i / scale_i), so
//      parameters of very different magnitudes are comparable; §5.3 found this scaling essential because
//      the derivative estimates were sometimes numerically unstable. Components pushing against an
//      active bound are dropped (projected gradient).
//   3. The direction is normalised and the step length bounded by max_step, so one bad derivative near a
//      discontinuity of U-hat cannot throw theta far away (§4.6, footnote 14).
//   4. A step that does not increase U-hat is undone and retried at half the length, up to max_backtracks
//      times (§5.3: verify each step went uphill, else redo it with a smaller step). After an accepted step
//      the length grows by step_growth, up to max_step.
// Stops on max_iterations, max_evaluations, a step length below min_step, a relative improvement at or
// below function_tolerance, a zero projected gradient, or max_backtracks failed halvings.
//
// Checkpoint state: {"theta": [...], "value": U-hat at theta, "step": current step length}.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/optimizer_method.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/optimizers/run_progress.hpp"

namespace pegasus {

struct GradientAscentOptions : OptimizerRunOptions {
  // Stop after this many iterations (one gradient plus its line search). 0 evaluates the start only.
  std::int64_t max_iterations = 1000;
  // Stop before an iteration whose evaluations (2n for the gradient, then one per trial step) would pass
  // this many in total. >= 1.
  std::int64_t max_evaluations = 1'000'000;
  // Central-difference half-width as a fraction of each parameter's scale: h_i = relative_step * scale_i.
  // Larger values smooth over small discontinuities of U-hat; smaller values are more exact. > 0.
  double relative_step = 1e-3;
  // Length of the first trial step, in scaled units. 0 < initial_step <= max_step.
  double initial_step = 0.1;
  // Upper bound on the length of any step, in scaled units (§4.6). > 0.
  double max_step = 1.0;
  // Stop when backtracking has shrunk the step length below this (scaled units). 0 <= min_step <=
  // initial_step.
  double min_step = 1e-10;
  // Factor applied to the step length after an accepted step (capped at max_step). >= 1.
  double step_growth = 2.0;
  // Halvings tried in one iteration before giving up on finding an uphill step. >= 0.
  int max_backtracks = 30;
  // Stop when an accepted step improves U-hat by no more than function_tolerance * |U-hat|. >= 0.
  double function_tolerance = 1e-12;

  // False, with "field: expected ..., got ..." in *error, when a field is out of range.
  bool IsValid(std::string* error) const;
  std::int64_t IterationLimit() const { return max_iterations; }

  static constexpr OptimizerMethodInfo kMethod{
      .section = "gradient",
      .type_name = "GradientAscentOptions",
      .description = "Bounded-step gradient ascent (thesis 4.6 footnote 14).",
      .method_names = {"gradient"}};
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = GradientAscentOptions;
    v.integer("max_iterations", &O::max_iterations, "gradient ascent: iterations at most (0: the start only)",
              0);
    v.integer("max_evaluations", &O::max_evaluations, "gradient ascent: U-hat evaluations at most", 1);
    v.real("relative_step", &O::relative_step,
           "gradient ascent: central-difference half-width, in parameter scales", 0, kNoUpperLimit, true);
    v.real("initial_step", &O::initial_step, "gradient ascent: first step length, in parameter scales", 0,
           kNoUpperLimit, true);
    v.real("max_step", &O::max_step, "gradient ascent: longest step, in parameter scales (thesis 4.6)", 0,
           kNoUpperLimit, true);
    v.real("min_step", &O::min_step, "gradient ascent: stop when backtracking shrinks the step below this", 0,
           kNoUpperLimit);
    v.real("step_growth", &O::step_growth, "gradient ascent: step factor after an accepted step", 1,
           kNoUpperLimit);
    v.integer("max_backtracks", &O::max_backtracks,
              "gradient ascent: step halvings tried before an iteration gives up", 0);
    v.real("function_tolerance", &O::function_tolerance,
           "gradient ascent: stop when a step improves U-hat by at most this fraction", 0, kNoUpperLimit);
  }
};

// Maximises objective from *theta (clamped into the bounds; empty = the spec's initial values). On return
// *theta is the best theta found and *summary describes the run. Throws InputError for invalid options or
// a checkpoint that does not belong to this problem.
void Solve(const GradientAscentOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary);

}  // namespace pegasus
