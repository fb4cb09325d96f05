#pragma once
// Augmented Random Search (Mania, Guy and Recht 2018, "Simple random search provides a competitive approach
// to reinforcement learning", Algorithm 2): a finite-difference ascent on U-hat along random directions,
// which pairs naturally with PEGASUS's fixed scenarios (§4.4): both sides of every antithetic pair see the
// same scenarios, so their difference measures the policy change alone.
//
// One iteration, theta in scaled units (theta_i / scale_i):
//   draw N directions delta_k ~ N(0, I);
//   evaluate U+_k = U(theta + nu delta_k) and U-_k = U(theta - nu delta_k) in one batch of 2N evaluations;
//   keep the b directions with the largest max(U+_k, U-_k) (ties: lower k);
//   sigma_R = standard deviation of those 2b values (1 when it is 0: all equal);
//   theta <- theta + alpha / (b sigma_R) sum_k (U+_k - U-_k) delta_k, clipped into the bounds;
//   U(theta) is then evaluated once more (the history's value).
// When the objective also implements ObservationNormalizing (ARS's "V2"), that last evaluation is made by
// EvaluateAndUpdateNormalizer: the observations of theta's rollouts join the running statistics, which are
// frozen for the next iteration's 2N evaluations. The values of different iterations were then measured
// under different normalisations, so the result is the best central theta together with the statistics it
// was measured under (FrozenNormalizer before its evaluation): on return the objective holds them again, and
// U-hat(best_theta) under them is best_value, bit for bit. The run goes on from the last iterate and its
// statistics, as the paper's ARS does; only the result is the best one seen.
//
// Evaluations per iteration: 2N + 1; in environment steps, each evaluation is m rollouts of at most H
// control steps (the objective counts them exactly: MujocoObjective::environment_steps).
//
// Randomness comes only from UniformStream(seed, stream). Checkpoint state: {"theta", "value",
// "stream_position", "normalizer" and "best_normalizer" (null without normalisation)}; a resumed run
// continues bit for bit.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/optimizer_method.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/optimizers/run_progress.hpp"

namespace pegasus {

// An objective whose policies act on observations normalised by statistics gathered from rollouts.
class ObservationNormalizing {
 public:
  virtual ~ObservationNormalizing() = default;
  // U-hat(theta) under the current frozen statistics; then the observations of these rollouts join the
  // running statistics, which become the frozen ones.
  virtual double EvaluateAndUpdateNormalizer(std::span<const double> theta) = 0;
  // Everything that rides in a checkpoint: the running statistics and the objective's own counters.
  virtual nlohmann::json NormalizerState() const = 0;
  virtual void RestoreNormalizer(const nlohmann::json& state) = 0;
  // The statistics alone that the next evaluation uses (no counters), and a return to them: ARS hands back
  // its best central theta with the statistics it was measured under.
  virtual nlohmann::json FrozenNormalizer() const = 0;
  virtual void RestoreFrozenNormalizer(const nlohmann::json& frozen) = 0;
};

struct AugmentedRandomSearchOptions : OptimizerRunOptions {
  // Seed and stream of the UniformStream that draws every direction.
  std::uint64_t seed = 0;
  std::uint32_t stream = 0x41525321;  // "ARS!"
  // Stop after this many iterations. >= 0.
  std::int64_t max_iterations = 100;
  // Stop before an iteration that would pass this many evaluations in total. >= 1.
  std::int64_t max_evaluations = 1'000'000;
  // N: directions per iteration (2N evaluations in one batch). >= 1.
  int directions = 8;
  // b: the best directions used in the step. 1 <= top_directions <= directions.
  int top_directions = 8;
  // alpha: step size (scaled units). > 0.
  double step_size = 0.02;
  // nu: standard deviation of the exploration noise (scaled units). > 0.
  double exploration_noise = 0.03;

  // False, with "field: expected ..., got ..." in *error, when a field is out of range.
  bool IsValid(std::string* error) const;
  std::int64_t IterationLimit() const { return max_iterations; }

  static constexpr OptimizerMethodInfo kMethod{
      .section = "ars",
      .type_name = "AugmentedRandomSearchOptions",
      .description =
          "Augmented Random Search (Mania, Guy and Recht 2018): N antithetic directions per iteration "
          "(2N evaluations in one batch), the b best used in the step.",
      .method_names = {"ars"},
      .seed_domain = 0x41525321,          // "ARS!"
      .refine_seed_domain = 0x52415253};  // "RARS"
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = AugmentedRandomSearchOptions;
    v.internal("seed", &O::seed, "Seed of the stream that draws every direction.");
    v.internal("stream", &O::stream, "Stream of that seed (change it, or the seed, for an independent run).");
    v.integer("max_iterations", &O::max_iterations, "ARS: iterations at most (0: the start only)", 0);
    v.integer("max_evaluations", &O::max_evaluations, "ARS: U-hat evaluations at most", 1);
    v.integer("directions", &O::directions, "ARS: random directions per iteration (each evaluated +-)", 1,
              kMaxPointsPerIteration);
    v.integer("top_directions", &O::top_directions, "ARS: best directions that move theta (b)", 1);
    v.real("step_size", &O::step_size, "ARS: step size alpha, in parameter scales", 0, kNoUpperLimit, true);
    v.real("exploration_noise", &O::exploration_noise, "ARS: direction size nu, in parameter scales", 0,
           kNoUpperLimit, true);
  }
};

// Maximises objective from *theta (clamped; empty = the spec's initial values). On return *theta is the
// best central theta (with a normalising objective, its statistics restored: header). Throws InputError for
// invalid options or a foreign checkpoint.
void Solve(const AugmentedRandomSearchOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary);

}  // namespace pegasus
