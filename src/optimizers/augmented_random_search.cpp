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

namespace {

// One ARS run: the central theta and its U-hat, the statistics of a normalising objective (ARS's "V2"),
// and the buffers of an iteration's 2N evaluations. Its members are the steps of one iteration.
class RandomSearch {
 public:
  RandomSearch(const AugmentedRandomSearchOptions& options, const ParameterSpec& spec, Objective& objective,
               RunProgress& run)
      : options_(options),
        spec_(spec),
        objective_(objective),
        run_(run),
        normalizing_(dynamic_cast<ObservationNormalizing*>(&objective)),
        lower_(spec.lower()),
        upper_(spec.upper()),
        scale_(spec.scales()),
        directions_(static_cast<std::size_t>(options.directions)),
        top_(static_cast<std::size_t>(options.top_directions)),
        deltas_(directions_, Theta(spec.size())),
        candidates_(2 * directions_, Theta(spec.size())),
        values_(2 * directions_),
        order_(directions_) {}

  void Start(const Theta& first) {
    x_ = first;
    value_ = EvaluateCenter();
    run_.AddEvaluations(1);
    run_.set_initial_value(value_);
  }

  // Continues from a checkpoint's state; returns the position of its uniform stream.
  std::uint64_t Resume(const json& state) {
    x_ = VectorFromJson(StateField(state, "theta"), "state.theta");
    if (!spec_.contains(x_)) throw InputError("checkpoint state.theta: expected a theta inside the bounds");
    value_ = DoubleFromJson(StateField(state, "value"), "state.value");
    const std::uint64_t stream_position = StateUnsigned(state, "stream_position");
    const json& normalizer = StateField(state, "normalizer");
    if (normalizing_ != nullptr && normalizer.is_null())
      throw InputError("checkpoint state.normalizer: expected the statistics of a normalising objective");
    if (normalizing_) {
      normalizing_->RestoreNormalizer(normalizer);
      best_normalizer_ = StateField(state, "best_normalizer");
      if (best_normalizer_.is_null())
        throw InputError("checkpoint state.best_normalizer: expected the statistics of the best theta");
    }
    return stream_position;
  }

  std::int64_t evaluations_per_iteration() const { return static_cast<std::int64_t>(2 * directions_ + 1); }

  // N directions delta_k ~ N(0, I) and U-hat at theta +/- nu delta_k (scaled units), in one batch.
  void SampleAndEvaluate(UniformStream& uniforms) {
    const double nu = options_.exploration_noise;
    for (std::size_t k = 0; k < directions_; ++k) {
      FillStandardNormals(uniforms, deltas_[k]);
      for (std::size_t i = 0; i < x_.size(); ++i) {
        candidates_[2 * k][i] = std::clamp(x_[i] + nu * scale_[i] * deltas_[k][i], lower_[i], upper_[i]);
        candidates_[2 * k + 1][i] = std::clamp(x_[i] - nu * scale_[i] * deltas_[k][i], lower_[i], upper_[i]);
      }
    }
    objective_.evaluate_batch(candidates_, values_);
    run_.AddEvaluations(static_cast<std::int64_t>(2 * directions_));
  }

  // Top-b directions by max(U+, U-); stable, so ties keep the lower index.
  void RankDirections() {
    std::iota(order_.begin(), order_.end(), std::size_t{0});
    std::stable_sort(order_.begin(), order_.end(), [&](std::size_t a, std::size_t b) {
      return std::max(values_[2 * a], values_[2 * a + 1]) > std::max(values_[2 * b], values_[2 * b + 1]);
    });
  }

  // sigma_R: the standard deviation of the top b directions' 2b values.
  double TopSpread() const {
    double mean = 0.0;
    for (std::size_t j = 0; j < top_; ++j) mean += values_[2 * order_[j]] + values_[2 * order_[j] + 1];
    mean /= static_cast<double>(2 * top_);
    double variance = 0.0;
    for (std::size_t j = 0; j < top_; ++j)
      for (int side = 0; side < 2; ++side) {
        const double e = values_[2 * order_[j] + static_cast<std::size_t>(side)] - mean;
        variance += e * e;
      }
    return std::sqrt(variance / static_cast<double>(2 * top_));
  }

  // theta <- theta + alpha / (b sigma_R) sum_k (U+_k - U-_k) delta_k, clipped into the bounds, and its
  // U-hat evaluated once more.
  void MoveCenter(double sigma) {
    const double factor = options_.step_size / (static_cast<double>(top_) * (sigma > 0.0 ? sigma : 1.0));
    for (std::size_t j = 0; j < top_; ++j) {
      const std::size_t k = order_[j];
      const double difference = values_[2 * k] - values_[2 * k + 1];
      for (std::size_t i = 0; i < x_.size(); ++i) x_[i] += factor * difference * scale_[i] * deltas_[k][i];
    }
    spec_.clamp(x_);
    value_ = EvaluateCenter();
    run_.AddEvaluations(1);
  }

  json State(std::uint64_t stream_position) const {
    return json{{"theta", VectorToJson(x_)},
                {"value", DoubleToJson(value_)},
                {"stream_position", stream_position},
                {"normalizer", normalizing_ ? normalizing_->NormalizerState() : json(nullptr)},
                {"best_normalizer", best_normalizer_}};
  }

  // The best central theta is the result, under the statistics its U-hat was measured with (header).
  void RestoreBestNormalizer() {
    if (normalizing_) normalizing_->RestoreFrozenNormalizer(best_normalizer_);
  }

 private:
  // U-hat of the central theta, offered as the best so far; with normalisation, the statistics it was
  // measured under are kept when it is the best.
  double EvaluateCenter() {
    if (!normalizing_) {
      const double value = objective_.evaluate(x_);
      run_.Offer(x_, value);
      return value;
    }
    json frozen = normalizing_->FrozenNormalizer();
    const double value = normalizing_->EvaluateAndUpdateNormalizer(x_);
    if (run_.Offer(x_, value)) best_normalizer_ = std::move(frozen);
    return value;
  }

  const AugmentedRandomSearchOptions& options_;
  const ParameterSpec& spec_;
  Objective& objective_;
  RunProgress& run_;
  ObservationNormalizing* normalizing_;  // null without normalisation
  const Theta lower_, upper_, scale_;
  const std::size_t directions_, top_;
  Theta x_;
  double value_ = 0.0;
  json best_normalizer_ = nullptr;  // the statistics the best theta was measured under (null without)
  std::vector<Theta> deltas_;
  std::vector<Theta> candidates_;  // theta + nu delta_k, theta - nu delta_k, for each k in turn
  std::vector<double> values_;
  std::vector<std::size_t> order_;  // directions, best first
};

}  // namespace

void Solve(const AugmentedRandomSearchOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("ars options: " + error);
  if (theta == nullptr || summary == nullptr) throw InputError("ars: theta and summary must be non-null");

  const ParameterSpec& spec = objective.parameters();
  RunProgress run("ars", spec, options.callbacks);
  RandomSearch search(options, spec, objective, run);
  std::uint64_t stream_position = 0;
  if (options.resume_from)
    stream_position = search.Resume(run.Resume(*options.resume_from));
  else
    search.Start(StartingTheta(spec, *theta));
  UniformStream uniforms(options.seed, options.stream, stream_position);

  TerminationType termination = TerminationType::kFailure;
  std::string message;
  for (;;) {
    if (run.BudgetSpent(options.max_iterations, options.max_evaluations, search.evaluations_per_iteration(),
                        &termination, &message))
      break;
    search.SampleAndEvaluate(uniforms);
    search.RankDirections();
    const double sigma = search.TopSpread();
    if (!std::isfinite(sigma)) {
      termination = TerminationType::kFailure;
      message = "a perturbed policy's U-hat is not finite";
      break;
    }
    search.MoveCenter(sigma);
    if (!run.EndIteration()) {
      termination = TerminationType::kUserRequested;
      message = "an iteration callback asked to stop";
      break;
    }
    if (run.CheckpointDue(options.checkpoint_every))
      options.on_checkpoint(run.Checkpoint(search.State(uniforms.position())));
  }

  run.Finish(termination, std::move(message), summary);
  search.RestoreBestNormalizer();
  *theta = summary->best_theta;
}

}  // namespace pegasus
