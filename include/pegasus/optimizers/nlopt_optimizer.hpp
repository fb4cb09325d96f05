#pragma once
// Derivative-free optimizers from NLopt behind the same Options/Summary shape: BOBYQA and Sbplx (local)
// and CRS2 and ESCH (global; they need finite bounds on every parameter). NLopt minimises, so it sees
// -U-hat; a NaN U-hat is shown to it as +infinity (the worst value).
//
// NLopt asks for one theta at a time, so these methods call Objective::evaluate, never evaluate_batch.
// An iteration is one evaluation. Initial steps (and BOBYQA's trust region) are initial_step * scale_i,
// capped at half the width of the bounds because BOBYQA needs that much room.
//
// Determinism: NLopt's random generator (used by CRS2 and ESCH) is seeded with `seed` by nlopt::srand
// right before each run. The generator is NLopt's own global (thread-local where NLopt was built with
// thread-local storage), so do not run two NLopt solves concurrently on one thread of control.
//
// Checkpoint/resume: NLopt's internal state cannot be saved. A checkpoint therefore holds the evaluation
// log, every theta asked for and the U-hat returned, in order. A resume re-runs NLopt from the same start
// with the same seed and answers the logged evaluations from the log without calling the objective; NLopt
// is deterministic given the values it receives, so it asks for the same thetas, and each is checked bit
// for bit against the log (InputError if one differs: the checkpoint belongs to other options or another
// objective). Once the log is used up the run continues live. Replaying costs NLopt's own overhead only.
// Each checkpoint holds the whole log, so its size and the time to write it grow with the evaluations so
// far: checkpoint every few hundred evaluations, not every few. Resuming needs the same options.
// Checkpoint state: {"algorithm", "seed", "start": theta, "log": [[theta, value, seconds], ...]}.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>

#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/optimizer_method.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/optimizers/run_progress.hpp"

namespace pegasus {

enum class NloptAlgorithm {
  kBobyqa,  // "bobyqa": local, quadratic models in a trust region (LN_BOBYQA)
  kSbplx,   // "sbplx": local, Nelder-Mead on subspaces (LN_SBPLX)
  kCrs2,    // "crs2": global, controlled random search with local mutation (GN_CRS2_LM)
  kEsch,    // "esch": global, evolutionary strategy (GN_ESCH)
};

// "bobyqa", "sbplx", "crs2", "esch".
std::string_view NloptAlgorithmName(NloptAlgorithm algorithm);
// The algorithm with that name, or nullopt.
std::optional<NloptAlgorithm> NloptAlgorithmFromName(std::string_view name);

struct NloptOptions : OptimizerRunOptions {
  NloptAlgorithm algorithm = NloptAlgorithm::kBobyqa;
  // Evaluations allowed, a hard limit (NLopt's own maxeval can overrun by a few in CRS2). 1 .. 2^31 - 1.
  std::int64_t max_evaluations = 10'000;
  // Local methods: initial step / trust-region radius in scaled units (initial_step * scale_i). > 0.
  double initial_step = 0.1;
  // Stop when a step changes every parameter by less than x_tolerance * scale_i (NLopt xtol_abs). 0 = off.
  double x_tolerance = 1e-10;
  // Stop when a step changes U-hat by less than function_tolerance * |U-hat| (NLopt ftol_rel). 0 = off.
  double function_tolerance = 1e-14;
  // CRS2 / ESCH population size; 0 = NLopt's default.
  int population = 0;
  // Seed of NLopt's random generator (nlopt::srand), set before every run.
  std::uint64_t seed = 0;

  // False, with "field: expected ..., got ..." in *error, when a field is out of range.
  bool IsValid(std::string* error) const;
  // One iteration is one evaluation.
  std::int64_t IterationLimit() const { return max_evaluations; }

  static constexpr OptimizerMethodInfo kMethod{.section = "nlopt",
                                               .type_name = "NloptOptions",
                                               .description = "NLopt: bobyqa, sbplx, crs2, esch.",
                                               .method_names = {"bobyqa", "sbplx", "crs2", "esch"},
                                               .need_finite_bounds = {"crs2", "esch"},
                                               .seed_domain = 0x4e4c6f70,          // "NLop"
                                               .refine_seed_domain = 0x524e4c6f};  // "RNLo"
  // The options with `algorithm` set from OptimizerOptions::method, one of kMethod.method_names.
  NloptOptions ForMethod(std::string_view method) const;
  // `algorithm` is not a field: OptimizerOptions::method chooses it.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = NloptOptions;
    v.integer("max_evaluations", &O::max_evaluations, "bobyqa, sbplx, crs2, esch: U-hat evaluations at most",
              1);
    v.real("initial_step", &O::initial_step, "bobyqa, sbplx: initial step, in parameter scales", 0,
           kNoUpperLimit, true);
    v.real("x_tolerance", &O::x_tolerance,
           "NLopt methods: stop when a step moves every parameter less (0: off)", 0, kNoUpperLimit);
    v.real("function_tolerance", &O::function_tolerance,
           "NLopt methods: stop when a step changes U-hat by a smaller fraction (0: off)", 0, kNoUpperLimit);
    v.integer("population", &O::population, "crs2, esch: population size (0: NLopt's default)", 0,
              kMaxPointsPerIteration);
    v.internal("seed", &O::seed, "Seed of NLopt's random generator, set before every run.");
  }
};

// Maximises objective from *theta (clamped into the bounds; empty = the spec's initial values). On return
// *theta is the best theta evaluated. Throws InputError for invalid options, infinite bounds with a global
// algorithm, or a checkpoint whose log does not match this run; rethrows what the objective throws.
void Solve(const NloptOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary);

}  // namespace pegasus
