#include "pegasus/optimizers/gradient_ascent.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "incumbent.hpp"
#include "pegasus/core/error.hpp"

namespace pegasus {

using nlohmann::json;

bool GradientAscentOptions::IsValid(std::string* error) const {
  if (max_iterations < 0)
    return RejectOption(error, "max_iterations", ">= 0", static_cast<double>(max_iterations));
  if (max_evaluations < 1)
    return RejectOption(error, "max_evaluations", ">= 1", static_cast<double>(max_evaluations));
  if (!(relative_step > 0.0 && std::isfinite(relative_step)))
    return RejectOption(error, "relative_step", "a finite value > 0", relative_step);
  if (!(max_step > 0.0 && std::isfinite(max_step)))
    return RejectOption(error, "max_step", "a finite value > 0", max_step);
  if (!(initial_step > 0.0 && initial_step <= max_step))
    return RejectOption(error, "initial_step", fmt::format("0 < initial_step <= max_step = {}", max_step),
                        initial_step);
  if (!(min_step >= 0.0 && min_step <= initial_step))
    return RejectOption(error, "min_step", fmt::format("0 <= min_step <= initial_step = {}", initial_step),
                        min_step);
  if (!(step_growth >= 1.0 && std::isfinite(step_growth)))
    return RejectOption(error, "step_growth", "a finite value >= 1", step_growth);
  if (max_backtracks < 0) return RejectOption(error, "max_backtracks", ">= 0", max_backtracks);
  if (!(function_tolerance >= 0.0 && std::isfinite(function_tolerance)))
    return RejectOption(error, "function_tolerance", "a finite value >= 0", function_tolerance);
  return IsValidFor("gradient", error);
}

namespace {

// One gradient ascent: where it stands (theta, its U-hat, the step length) and the scratch of the whole
// run, so an iteration allocates nothing (STYLE.md). Its members are the steps of one iteration.
struct Ascent : Incumbent {
  Ascent(const GradientAscentOptions& run_options, const ParameterSpec& parameters)
      : options(run_options),
        spec(parameters),
        lower(parameters.lower()),
        upper(parameters.upper()),
        scale(parameters.scales()) {}

  void AllocateScratch() {
    const std::size_t n = spec.size();
    probes.assign(2 * n, x);
    probe_values.assign(2 * n, 0.0);
    plus.resize(n), minus.resize(n), direction.resize(n), trial.resize(n);
  }

  std::int64_t probe_count() const { return static_cast<std::int64_t>(probes.size()); }

  // §5.3: numerically evaluated derivatives, all 2n probes in one batch so the objective can run them
  // in parallel. Probes are clipped to the bounds; dividing by the clipped width keeps the estimate
  // one-sided rather than wrong at a bound.
  void EvaluateProbes(Objective& objective, RunProgress& run) {
    for (std::size_t i = 0; i < spec.size(); ++i) {
      const double h = options.relative_step * scale[i];
      plus[i] = std::min(x[i] + h, upper[i]);
      minus[i] = std::max(x[i] - h, lower[i]);
      std::copy(x.begin(), x.end(), probes[2 * i].begin());
      std::copy(x.begin(), x.end(), probes[2 * i + 1].begin());
      probes[2 * i][i] = plus[i];
      probes[2 * i + 1][i] = minus[i];
    }
    objective.evaluate_batch(probes, probe_values);
    run.AddEvaluations(probe_count());
  }

  // The normalised projected gradient into `direction`; true, with the reason, when there is none: a
  // derivative is not finite (failure) or every component is zero (convergence).
  bool FindDirection(TerminationType* termination, std::string* message) {
    double norm_squared = 0.0;
    for (std::size_t i = 0; i < spec.size(); ++i) {
      const double width = plus[i] - minus[i];
      // Derivative with respect to theta_i / scale_i (§5.3: scale the derivatives per parameter).
      double g = width > 0.0 ? (probe_values[2 * i] - probe_values[2 * i + 1]) / width * scale[i] : 0.0;
      if (!std::isfinite(g)) {
        *termination = TerminationType::kFailure;
        *message = fmt::format("derivative with respect to {} is not finite (U-hat {} at +h, {} at -h)",
                               spec[i].name, probe_values[2 * i], probe_values[2 * i + 1]);
        return true;
      }
      // Projected gradient: a component pushing out through an active bound cannot be followed.
      if ((x[i] >= upper[i] && g > 0.0) || (x[i] <= lower[i] && g < 0.0)) g = 0.0;
      direction[i] = g;
      norm_squared += g * g;
    }
    if (norm_squared == 0.0) {
      *termination = TerminationType::kConvergence;
      *message = "the projected gradient is zero";
      return true;
    }
    // §4.6: a normalised direction with a bounded length keeps a wild derivative estimate near a
    // discontinuity of U-hat from throwing theta far away.
    const double norm = std::sqrt(norm_squared);
    for (double& d : direction) d /= norm;
    return false;
  }

  // §5.3: check that each step went uphill; otherwise undo it and redo it with half the length. Moves
  // theta and returns false on an uphill step; true, with the reason, when none was found.
  bool StepUphill(Objective& objective, RunProgress& run, TerminationType* termination,
                  std::string* message) {
    for (int halvings = 0;; ++halvings) {
      if (step < options.min_step) {
        *termination = TerminationType::kConvergence;
        *message = fmt::format("step length {:.3g} fell below min_step = {:.3g}", step, options.min_step);
        return true;
      }
      if (run.evaluations() >= options.max_evaluations) {
        *termination = TerminationType::kMaxEvaluations;
        *message = fmt::format("used max_evaluations = {} while backtracking", options.max_evaluations);
        return true;
      }
      for (std::size_t i = 0; i < spec.size(); ++i)
        trial[i] = std::clamp(x[i] + step * scale[i] * direction[i], lower[i], upper[i]);
      const double trial_value = objective.evaluate(trial);
      run.AddEvaluations(1);
      if (IsImprovement(trial_value, value)) {
        x.swap(trial);
        value = trial_value;
        return false;
      }
      if (halvings == options.max_backtracks) {
        *termination = TerminationType::kConvergence;
        *message = fmt::format("no uphill step after max_backtracks = {} halvings (step length {:.3g})",
                               options.max_backtracks, step);
        return true;
      }
      step *= 0.5;
    }
  }

  const GradientAscentOptions& options;
  const ParameterSpec& spec;
  const Theta lower, upper, scale;
  std::vector<Theta> probes;  // theta +h and -h in each parameter in turn
  std::vector<double> probe_values;
  Theta plus, minus, direction, trial;
};

}  // namespace

void Solve(const GradientAscentOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("gradient ascent options: " + error);
  if (theta == nullptr || summary == nullptr)
    throw InputError("gradient ascent: theta and summary must be non-null");

  const ParameterSpec& spec = objective.parameters();
  Ascent ascent(options, spec);
  RunProgress run("gradient", spec, options.callbacks);
  if (options.resume_from)
    ascent.Resume(run.Resume(*options.resume_from), spec);
  else
    ascent.Start(StartingTheta(spec, *theta), options.initial_step, objective, run);
  ascent.AllocateScratch();

  TerminationType termination = TerminationType::kFailure;
  std::string message;
  for (;;) {
    if (run.BudgetSpent(options.max_iterations, options.max_evaluations, ascent.probe_count() + 1,
                        &termination, &message))
      break;
    ascent.EvaluateProbes(objective, run);
    if (ascent.FindDirection(&termination, &message)) break;
    const double previous_value = ascent.value;
    if (ascent.StepUphill(objective, run, &termination, &message)) break;
    const double improvement = ascent.value - previous_value;

    run.Offer(ascent.x, ascent.value);
    ascent.step = std::min(ascent.step * options.step_growth, options.max_step);
    if (!run.EndIteration()) {
      termination = TerminationType::kUserRequested;
      message = "an iteration callback asked to stop";
      break;
    }
    if (improvement <= options.function_tolerance * std::abs(previous_value)) {
      termination = TerminationType::kConvergence;
      message = fmt::format("relative improvement {:.3g} <= function_tolerance = {:.3g}",
                            improvement / std::abs(previous_value), options.function_tolerance);
      break;
    }
    if (run.CheckpointDue(options.checkpoint_every)) options.on_checkpoint(run.Checkpoint(ascent.State()));
  }

  run.Finish(termination, std::move(message), summary);
  summary->final_step = ascent.step;
  *theta = summary->best_theta;
}

}  // namespace pegasus
