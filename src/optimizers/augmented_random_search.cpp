#include "pegasus/optimizers/augmented_random_search.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "pegasus/core/error.hpp"
#include "pegasus/optimizers/hill_climbing.hpp"

namespace pegasus {

using nlohmann::json;

bool AugmentedRandomSearchOptions::IsValid(std::string* error) const {
  if (max_iterations < 0)
    return RejectOption(error, "max_iterations", ">= 0", static_cast<double>(max_iterations));
  if (max_evaluations < 1)
    return RejectOption(error, "max_evaluations", ">= 1", static_cast<double>(max_evaluations));
  if (directions < 1 || directions > kMaxPointsPerIteration)
    return RejectOption(error, "directions", fmt::format("in [1, {}]", kMaxPointsPerIteration), directions);
  if (top_directions < 1 || top_directions > directions)
    return RejectOption(error, "top_directions",
                        fmt::format("1 <= top_directions <= directions = {}", directions), top_directions);
  if (!(step_size > 0.0 && std::isfinite(step_size)))
    return RejectOption(error, "step_size", "a finite value > 0", step_size);
  if (!(exploration_noise > 0.0 && std::isfinite(exploration_noise)))
    return RejectOption(error, "exploration_noise", "a finite value > 0", exploration_noise);
  return IsValidFor("ars", error);
}

void Solve(const AugmentedRandomSearchOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("ars options: " + error);
  if (theta == nullptr || summary == nullptr) throw InputError("ars: theta and summary must be non-null");

  const ParameterSpec& spec = objective.parameters();
  const std::size_t n = spec.size();
  const Theta lower = spec.lower(), upper = spec.upper(), scale = spec.scales();
  RunProgress run("ars", spec, options.callbacks);
  auto* normalizing = dynamic_cast<ObservationNormalizing*>(&objective);
  // U-hat of a central theta, offered as the best so far; with normalisation, the statistics it was
  // measured under are kept when it is the best (null without normalisation).
  json best_normalizer = nullptr;
  auto evaluate_center = [&](std::span<const double> x) {
    if (!normalizing) {
      const double value = objective.evaluate(x);
      run.Offer(x, value);
      return value;
    }
    json frozen = normalizing->FrozenNormalizer();
    const double value = normalizing->EvaluateAndUpdateNormalizer(x);
    if (run.Offer(x, value)) best_normalizer = std::move(frozen);
    return value;
  };

  Theta x;
  double value;
  std::uint64_t stream_position = 0;
  if (options.resume_from) {
    const json& state = run.Resume(*options.resume_from);
    x = VectorFromJson(StateField(state, "theta"), "state.theta");
    if (!spec.contains(x)) throw InputError("checkpoint state.theta: expected a theta inside the bounds");
    value = DoubleFromJson(StateField(state, "value"), "state.value");
    stream_position = StateUnsigned(state, "stream_position");
    const json& normalizer = StateField(state, "normalizer");
    if (normalizing != nullptr && normalizer.is_null())
      throw InputError("checkpoint state.normalizer: expected the statistics of a normalising objective");
    if (normalizing) {
      normalizing->RestoreNormalizer(normalizer);
      best_normalizer = StateField(state, "best_normalizer");
      if (best_normalizer.is_null())
        throw InputError("checkpoint state.best_normalizer: expected the statistics of the best theta");
    }
  } else {
    x = StartingTheta(spec, *theta);
    value = evaluate_center(x);
    run.AddEvaluations(1);
    run.set_initial_value(value);
  }
  UniformStream uniforms(options.seed, options.stream, stream_position);

  const auto directions = static_cast<std::size_t>(options.directions);
  const auto top = static_cast<std::size_t>(options.top_directions);
  const double nu = options.exploration_noise;
  std::vector<Theta> deltas(directions, Theta(n));
  std::vector<Theta> candidates(2 * directions, Theta(n));
  std::vector<double> values(2 * directions);
  std::vector<std::size_t> order(directions);
  const auto per_iteration = static_cast<std::int64_t>(2 * directions + 1);

  TerminationType termination = TerminationType::kFailure;
  std::string message;
  for (;;) {
    if (run.BudgetSpent(options.max_iterations, options.max_evaluations, per_iteration, &termination,
                        &message))
      break;
    for (std::size_t k = 0; k < directions; ++k) {
      FillStandardNormals(uniforms, deltas[k]);
      for (std::size_t i = 0; i < n; ++i) {
        candidates[2 * k][i] = std::clamp(x[i] + nu * scale[i] * deltas[k][i], lower[i], upper[i]);
        candidates[2 * k + 1][i] = std::clamp(x[i] - nu * scale[i] * deltas[k][i], lower[i], upper[i]);
      }
    }
    objective.evaluate_batch(candidates, values);
    run.AddEvaluations(static_cast<std::int64_t>(2 * directions));

    // Top-b directions by max(U+, U-); stable, so ties keep the lower index.
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return std::max(values[2 * a], values[2 * a + 1]) > std::max(values[2 * b], values[2 * b + 1]);
    });
    double mean = 0.0;
    for (std::size_t j = 0; j < top; ++j) mean += values[2 * order[j]] + values[2 * order[j] + 1];
    mean /= static_cast<double>(2 * top);
    double variance = 0.0;
    for (std::size_t j = 0; j < top; ++j)
      for (int side = 0; side < 2; ++side) {
        const double e = values[2 * order[j] + static_cast<std::size_t>(side)] - mean;
        variance += e * e;
      }
    const double sigma = std::sqrt(variance / static_cast<double>(2 * top));
    if (!std::isfinite(sigma)) {
      termination = TerminationType::kFailure;
      message = "a perturbed policy's U-hat is not finite";
      break;
    }
    const double factor = options.step_size / (static_cast<double>(top) * (sigma > 0.0 ? sigma : 1.0));
    for (std::size_t j = 0; j < top; ++j) {
      const std::size_t k = order[j];
      const double difference = values[2 * k] - values[2 * k + 1];
      for (std::size_t i = 0; i < n; ++i) x[i] += factor * difference * scale[i] * deltas[k][i];
    }
    spec.clamp(x);
    value = evaluate_center(x);
    run.AddEvaluations(1);
    if (!run.EndIteration()) {
      termination = TerminationType::kUserRequested;
      message = "an iteration callback asked to stop";
      break;
    }
    if (run.CheckpointDue(options.checkpoint_every)) {
      options.on_checkpoint(
          run.Checkpoint(json{{"theta", VectorToJson(x)},
                              {"value", DoubleToJson(value)},
                              {"stream_position", uniforms.position()},
                              {"normalizer", normalizing ? normalizing->NormalizerState() : json(nullptr)},
                              {"best_normalizer", best_normalizer}}));
    }
  }

  run.Finish(termination, std::move(message), summary);
  // The best central theta is the result, under the statistics its U-hat was measured with (header).
  if (normalizing) normalizing->RestoreFrozenNormalizer(best_normalizer);
  *theta = summary->best_theta;
}

}  // namespace pegasus
