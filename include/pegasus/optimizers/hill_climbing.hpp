#pragma once
// Random-walk hill climbing on U-hat (§5.3; also the non-gradient alternative of §4.6, footnote 14):
// propose a random perturbation of the weights and move there only if U-hat increases.
//
// One iteration draws proposals_per_iteration candidates theta + step * scale_i * z_i, z_i standard
// normal, clipped to the bounds, and evaluates them in one evaluate_batch call. The best candidate (lowest
// index on ties) replaces theta when it is strictly better. The step length (scaled units) then grows by
// step_growth on success and shrinks by step_shrink on failure, within [0, max_step]: with the defaults it
// settles where about one proposal in five succeeds (Rechenberg's 1/5 rule), large when far from a
// maximum and small near one. Stops on max_iterations, max_evaluations, or a step below min_step.
//
// Randomness comes only from UniformStream(seed, stream): the run is a pure function of the options and
// the objective. Checkpoint state: {"theta", "value", "step", "stream_position"}.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>

#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/optimizer_method.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/optimizers/run_progress.hpp"
#include "pegasus/random/counter_rng.hpp"

namespace pegasus {

struct HillClimbingOptions : OptimizerRunOptions {
  // Seed and stream of the UniformStream that draws every perturbation. Change either for an independent
  // run; keep them apart from the scenario seed's streams to avoid correlated noise.
  std::uint64_t seed = 0;
  std::uint32_t stream = 0x48696c6c;  // "Hill"
  // Stop after this many iterations (one batch of proposals). 0 evaluates the start only.
  std::int64_t max_iterations = 1000;
  // Stop before an iteration whose proposals would pass this many evaluations in total. >= 1.
  std::int64_t max_evaluations = 1'000'000;
  // Candidates drawn and evaluated (in one batch) per iteration; the best is accepted if it improves.
  // More proposals use more parallel work per iteration. >= 1.
  int proposals_per_iteration = 1;
  // Standard deviation of the first perturbations, in scaled units. 0 < initial_step <= max_step.
  double initial_step = 0.1;
  // Upper bound on the step (scaled units). > 0.
  double max_step = 1.0;
  // Stop when the step has shrunk below this (scaled units). 0 <= min_step <= initial_step.
  double min_step = 1e-8;
  // Step factor after an accepted proposal. >= 1.
  double step_growth = 1.5;
  // Step factor after an iteration without improvement. In (0, 1]; 1.5^(-1/4) ~ 0.9 gives the 1/5 rule.
  double step_shrink = 0.9;

  // False, with "field: expected ..., got ..." in *error, when a field is out of range.
  bool IsValid(std::string* error) const;
  std::int64_t IterationLimit() const { return max_iterations; }

  static constexpr OptimizerMethodInfo kMethod{.section = "hill_climbing",
                                               .type_name = "HillClimbingOptions",
                                               .description = "Random-walk hill climbing (thesis 5.3).",
                                               .method_names = {"hill-climb"},
                                               .seed_domain = 0x48696c6c,          // "Hill"
                                               .refine_seed_domain = 0x52486c6c};  // "RHll"
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = HillClimbingOptions;
    v.internal("seed", &O::seed, "Seed of the stream that draws every perturbation.");
    v.internal("stream", &O::stream, "Stream of that seed (change it, or the seed, for an independent run).");
    v.integer("max_iterations", &O::max_iterations, "hill climbing: iterations at most (0: the start only)",
              0);
    v.integer("max_evaluations", &O::max_evaluations, "hill climbing: U-hat evaluations at most", 1);
    v.integer("proposals_per_iteration", &O::proposals_per_iteration,
              "hill climbing: proposals per iteration (evaluated in parallel)", 1, kMaxPointsPerIteration);
    v.real("initial_step", &O::initial_step, "hill climbing: first perturbation size, in parameter scales", 0,
           kNoUpperLimit, true);
    v.real("max_step", &O::max_step, "hill climbing: largest perturbation, in parameter scales", 0,
           kNoUpperLimit, true);
    v.real("min_step", &O::min_step, "hill climbing: stop when the step shrinks below this", 0,
           kNoUpperLimit);
    v.real("step_growth", &O::step_growth, "hill climbing: step factor after an improvement", 1,
           kNoUpperLimit);
    v.real("step_shrink", &O::step_shrink, "hill climbing: step factor after an iteration without one", 0, 1,
           true);
  }
};

// Fills `normals` with independent standard normal numbers by the Box-Muller transform: each pair of
// uniforms (u1, u2) in (0, 1) gives sqrt(-2 ln u1) * (cos 2 pi u2, sin 2 pi u2). The stream hands out
// uniforms in the open interval, so the logarithm is always finite. Consumes 2 * ceil(size / 2) uniforms;
// for an odd size the last sine is discarded.
void FillStandardNormals(UniformStream& uniforms, std::span<double> normals);

// Maximises objective from *theta (clamped into the bounds; empty = the spec's initial values). On return
// *theta is the best theta found. Throws InputError for invalid options or a foreign checkpoint.
void Solve(const HillClimbingOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary);

}  // namespace pegasus
