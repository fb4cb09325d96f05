#pragma once
// One entry point for every optimizer, so a config can pick the method by name:
//
//   OptimizerOptions options;
//   options.method = "hill-climb";               // from the config
//   options.hill_climbing.proposals_per_iteration = 8;
//   std::string error;
//   if (!options.IsValid(&error)) throw InputError("optimizer." + error);
//   Theta theta;                                  // empty: start from the spec's initial values
//   OptimizerSummary summary;
//   Solve(options, objective, &theta, &summary);
//
// Methods: "exhaustive", "gradient", "hill-climb", "bobyqa", "sbplx", "crs2", "esch", "cmaes", "ars".
//
// The methods are listed once, in kOptimizerMethods below; the dispatcher, the config section, the training
// layer's seeds and the Python module iterate over it through each Options struct's kMethod and VisitFields
// (optimizer_method.hpp). Adding a method: its header and source, a member here and its line in the list (the
// build refuses a member missing from the list).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

#include "pegasus/optimizers/augmented_random_search.hpp"
#include "pegasus/optimizers/cmaes.hpp"
#include "pegasus/optimizers/exhaustive_search.hpp"
#include "pegasus/optimizers/gradient_ascent.hpp"
#include "pegasus/optimizers/hill_climbing.hpp"
#include "pegasus/optimizers/nlopt_optimizer.hpp"
#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/optimizer_method.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"

namespace pegasus {

// The method names the dispatcher accepts, in the order of kOptimizerMethods.
std::span<const std::string_view> OptimizerMethodNames();

struct OptimizerOptions {
  // Which optimizer runs; one of OptimizerMethodNames(). CMA-ES by default: on the optimizer suite
  // (docs/how-to/choose-optimizer.md, bench/optimizer_suite.py) it is the one method within 2% of the best
  // method's U-hat on every problem; gradient ascent stalls on the cart-pole and the mountain car.
  std::string method = "cmaes";
  // Options of each method; only the selected one is used and validated.
  ExhaustiveSearchOptions exhaustive;
  GradientAscentOptions gradient;
  HillClimbingOptions hill_climbing;
  // Used by "bobyqa", "sbplx", "crs2" and "esch"; its `algorithm` is overridden by `method`.
  NloptOptions nlopt;
  CmaesOptions cmaes;
  // Augmented Random Search ("ars").
  AugmentedRandomSearchOptions ars;

  // Sets checkpoint_every, on_checkpoint and resume_from of every method's options at once.
  void SetCheckpointing(std::int64_t checkpoint_every, CheckpointCallback on_checkpoint,
                        std::optional<nlohmann::json> resume_from = std::nullopt);

  // The selected method's iteration limit (evaluations for the NLopt methods, whose iteration is one
  // evaluation; policy blocks at most for exhaustive search): what a progress bar counts to.
  std::int64_t IterationLimit() const;

  // Sets the iteration callbacks of every method's options at once.
  void SetCallbacks(const IterationCallbacks& callbacks);

  // Sets the seed of every method that draws random numbers (kMethod.seed_domain != 0) to `seed`.
  void SetSeeds(std::uint64_t seed);

  // False when `method` is unknown or the selected method's options are invalid; *error then names the
  // field with its prefix ("method", "gradient.max_step", "nlopt.population", "cmaes.initial_step", ...).
  bool IsValid(std::string* error) const;
};

// Every method's options, once: each entry a member of OptimizerOptions whose type has kMethod and
// VisitFields. Methods are listed in this order everywhere (OptimizerMethodNames, --help, Python).
inline constexpr std::tuple kOptimizerMethods{&OptimizerOptions::exhaustive,    &OptimizerOptions::gradient,
                                              &OptimizerOptions::hill_climbing, &OptimizerOptions::nlopt,
                                              &OptimizerOptions::cmaes,         &OptimizerOptions::ars};

// The Options type of an entry of kOptimizerMethods.
template <class Member>
using OptimizerMethodOptions =
    std::remove_cvref_t<decltype(std::declval<OptimizerOptions&>().*std::declval<Member>())>;

// Calls f(member) for every entry of kOptimizerMethods, in order; member is a pointer to the
// OptimizerOptions member, so `options.*member` is that method's Options and
// `OptimizerMethodOptions<decltype(member)>::kMethod` its description.
template <class F>
constexpr void ForEachOptimizerMethod(F&& f) {
  std::apply([&](auto... member) { (f(member), ...); }, kOptimizerMethods);
}

// Runs options.method; see that method's Solve. Throws InputError when the options are invalid.
void Solve(const OptimizerOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary);

}  // namespace pegasus
