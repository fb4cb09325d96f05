#include "pegasus/optimizers/hill_climbing.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "incumbent.hpp"
#include "pegasus/core/error.hpp"

namespace pegasus {

using nlohmann::json;

bool HillClimbingOptions::IsValid(std::string* error) const {
  if (max_iterations < 0)
    return RejectOption(error, "max_iterations", ">= 0", static_cast<double>(max_iterations));
  if (max_evaluations < 1)
    return RejectOption(error, "max_evaluations", ">= 1", static_cast<double>(max_evaluations));
  if (proposals_per_iteration < 1 || proposals_per_iteration > kMaxPointsPerIteration)
    return RejectOption(error, "proposals_per_iteration", fmt::format("in [1, {}]", kMaxPointsPerIteration),
                        proposals_per_iteration);
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
  if (!(step_shrink > 0.0 && step_shrink <= 1.0))
    return RejectOption(error, "step_shrink", "a value in (0, 1]", step_shrink);
  return IsValidFor("hill-climb", error);
}

void FillStandardNormals(UniformStream& uniforms, std::span<double> normals) {
  for (std::size_t k = 0; k < normals.size(); k += 2) {
    const double radius = std::sqrt(-2.0 * std::log(uniforms.next()));
    const double angle = 2.0 * std::numbers::pi * uniforms.next();
    normals[k] = radius * std::cos(angle);
    if (k + 1 < normals.size()) normals[k + 1] = radius * std::sin(angle);
  }
}

namespace {

// One hill climb: where it stands (theta, its U-hat, the step length) and an iteration's proposals.
struct Climber : Incumbent {
  Climber(const HillClimbingOptions& run_options, const ParameterSpec& parameters)
      : options(run_options),
        spec(parameters),
        lower(parameters.lower()),
        upper(parameters.upper()),
        scale(parameters.scales()) {}

  // Continues from a checkpoint's state; returns the position of its uniform stream.
  std::uint64_t Resume(const json& state) {
    Incumbent::Resume(state, spec);
    return StateUnsigned(state, "stream_position");
  }

  void AllocateScratch() {
    proposals.assign(static_cast<std::size_t>(options.proposals_per_iteration), x);
    proposal_values.assign(proposals.size(), 0.0);
    normals.resize(spec.size());
  }

  // §5.3: random perturbations of the weights, each sized by the parameter's scale, evaluated in one batch.
  void ProposeAndEvaluate(UniformStream& uniforms, Objective& objective, RunProgress& run) {
    for (auto& proposal : proposals) {
      FillStandardNormals(uniforms, normals);
      for (std::size_t i = 0; i < spec.size(); ++i)
        proposal[i] = std::clamp(x[i] + step * scale[i] * normals[i], lower[i], upper[i]);
    }
    objective.evaluate_batch(proposals, proposal_values);
    run.AddEvaluations(static_cast<std::int64_t>(proposals.size()));
  }

  // Moves to the best proposal only when U-hat increases (§5.3), so accepted values never decrease; the
  // step grows after a move and shrinks otherwise.
  void MoveToBest(RunProgress& run) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < proposals.size(); ++k)
      if (IsImprovement(proposal_values[k], proposal_values[best])) best = k;
    if (IsImprovement(proposal_values[best], value)) {
      std::copy(proposals[best].begin(), proposals[best].end(), x.begin());
      value = proposal_values[best];
      run.Offer(x, value);
      step = std::min(step * options.step_growth, options.max_step);
    } else {
      step *= options.step_shrink;
    }
  }

  json State(std::uint64_t stream_position) const {
    json state = Incumbent::State();
    state["stream_position"] = stream_position;
    return state;
  }

  const HillClimbingOptions& options;
  const ParameterSpec& spec;
  const Theta lower, upper, scale;
  std::vector<Theta> proposals;
  std::vector<double> proposal_values;
  Theta normals;
};

}  // namespace

void Solve(const HillClimbingOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("hill climbing options: " + error);
  if (theta == nullptr || summary == nullptr)
    throw InputError("hill climbing: theta and summary must be non-null");

  const ParameterSpec& spec = objective.parameters();
  Climber climber(options, spec);
  RunProgress run("hill-climb", spec, options.callbacks);
  std::uint64_t stream_position = 0;
  if (options.resume_from)
    stream_position = climber.Resume(run.Resume(*options.resume_from));
  else
    climber.Start(StartingTheta(spec, *theta), options.initial_step, objective, run);
  UniformStream uniforms(options.seed, options.stream, stream_position);
  climber.AllocateScratch();

  TerminationType termination = TerminationType::kFailure;
  std::string message;
  for (;;) {
    if (run.BudgetSpent(options.max_iterations, options.max_evaluations,
                        static_cast<std::int64_t>(climber.proposals.size()), &termination, &message))
      break;
    climber.ProposeAndEvaluate(uniforms, objective, run);
    climber.MoveToBest(run);
    if (!run.EndIteration()) {
      termination = TerminationType::kUserRequested;
      message = "an iteration callback asked to stop";
      break;
    }
    if (climber.step < options.min_step) {
      termination = TerminationType::kConvergence;
      message = fmt::format("step {:.3g} fell below min_step = {:.3g}", climber.step, options.min_step);
      break;
    }
    if (run.CheckpointDue(options.checkpoint_every))
      options.on_checkpoint(run.Checkpoint(climber.State(uniforms.position())));
  }

  run.Finish(termination, std::move(message), summary);
  summary->final_step = climber.step;
  *theta = summary->best_theta;
}

}  // namespace pegasus
