#pragma once
// CMA-ES, the covariance matrix adaptation evolution strategy (Hansen, "The CMA Evolution Strategy: A
// Tutorial", arXiv:1604.00772, 2016): the standard derivative-free method for tuning controllers, and with
// PEGASUS's fixed scenarios (§4.4) its objective U-hat is deterministic, so no noise handling is needed.
//
// One iteration (generation) samples population_size points x_k = mean + sigma * scale o y_k, y_k ~ N(0, C)
// (scaled units: parameter i moves by sigma * y_k,i * scale_i), maps them into the bounds and evaluates
// them in one evaluate_batch call. Bounds are handled as pycma's BoundTransform does: the search runs
// unconstrained and the objective sees T(x), T a continuously differentiable map onto the box that is the
// identity away from the bounds, quadratic within a margin of them (min(width / 20, scale)) and mirrored
// beyond; a maximum on a bound becomes an ordinary interior maximum of U-hat(T(x)), which clipping would
// not give (clipped steps shrink C towards the bound until it degenerates). The update is
// the tutorial's Eqs 39-47 (Table 1 defaults, negative weights included): weighted recombination of the
// ranked candidates, cumulative step-size adaptation, rank-one and rank-mu covariance updates; the
// eigendecomposition of C (Eigen's SelfAdjointEigenSolver) is refreshed every 1 / (10 n (c1 + cmu))
// generations at the latest, as the tutorial recommends.
//
// Stops on max_iterations, max_evaluations, sigma * max_i max(|p_c,i|, sqrt(C_ii)) below x_tolerance
// (the whole distribution and its path are smaller than that, scaled units), a range of U-hat below
// function_tolerance over the current generation and the best values of the last 10 + ceil(30 n /
// population) generations, a stall (the run's best U-hat rose by at most stall_tolerance over the last
// stall_generations generations, when stall_generations > 0), or a condition number of C above max_condition
// (FAILURE: C has degenerated).
//
// Restarts (IPOP-CMA-ES, Auger and Hansen, "A restart CMA evolution strategy with increasing population
// size", CEC 2005): when a run stops by x_tolerance, function_tolerance or a stall and restarts remain, a new
// run starts from the first mean with the first sigma, C = I and twice the population; max_iterations and
// max_evaluations count over all runs, and the result is the best theta of any run. A larger population
// searches more globally, so a run stuck on a local maximum of a multimodal U-hat is left for a wider search.
//
// Randomness comes only from UniformStream(seed, stream) (FillStandardNormals, a fixed order per
// generation): the run is a pure function of the options and the objective, on any library. Ranking breaks
// ties by candidate index, and NaN ranks last (IsImprovement). Checkpoint state: {"population", "mean",
// "sigma", "C" (row by row), "B", "D", "p_sigma", "p_c", "eigen_iteration", "recent_best",
// "stream_position", "restarts", "run_first_iteration", "run_best", "start"}: everything the next generation
// reads, so a resumed run continues bit for bit (a checkpoint without the last four, written before restarts,
// resumes a run of no restarts). The
// mean is a point of the search space (it may lie beyond a bound); every theta evaluated is inside.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/optimizer_method.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/optimizers/run_progress.hpp"

namespace pegasus {

inline constexpr int kCmaesMaxRestarts = 20;

struct CmaesOptions : OptimizerRunOptions {
  // Seed and stream of the UniformStream that draws every sample. Change either for an independent run;
  // keep them apart from the scenario seed's streams to avoid correlated noise.
  std::uint64_t seed = 0;
  std::uint32_t stream = 0x434d4145;  // "CMAE"
  // Stop after this many generations. 0 evaluates the start only.
  std::int64_t max_iterations = 1000;
  // Stop before a generation that would pass this many evaluations in total (the start counts one). >= 1.
  std::int64_t max_evaluations = 1'000'000;
  // Candidates per generation (lambda), all evaluated in one batch; 0 = the tutorial's default
  // 4 + floor(3 ln n). Larger populations search more globally and give more parallel work. 0 or >= 2.
  int population_size = 0;
  // sigma at the start, in scaled units: the first samples spread about initial_step * scale_i around the
  // start in parameter i. > 0.
  double initial_step = 0.3;
  // Stop when sigma * max_i max(|p_c,i|, sqrt(C_ii)) falls below this (scaled units). >= 0.
  double x_tolerance = 1e-11;
  // Stop when U-hat varies by less than this over the recent generations (see above). >= 0; 0 never stops.
  double function_tolerance = 1e-12;
  // Stop (FAILURE) when the condition number of C exceeds this. > 1.
  double max_condition = 1e14;
  // A run stops when its best U-hat rose by at most stall_tolerance over its last stall_generations
  // generations (0 = never). >= 0.
  std::int64_t stall_generations = 0;
  double stall_tolerance = 0.0;
  // Runs after the first (IPOP, see above): each starts again from the first mean with twice the previous
  // population. In [0, kCmaesMaxRestarts], and the last population at most kMaxPointsPerIteration.
  int restarts = 0;

  // False, with "field: expected ..., got ..." in *error, when a field is out of range.
  bool IsValid(std::string* error) const;
  std::int64_t IterationLimit() const { return max_iterations; }

  static constexpr OptimizerMethodInfo kMethod{
      .section = "cmaes",
      .type_name = "CmaesOptions",
      .description =
          "CMA-ES (Hansen's tutorial, arXiv:1604.00772): population_size candidates per generation in "
          "one batch, bounds by pycma's BoundTransform, IPOP restarts; deterministic from (seed, "
          "stream).",
      .method_names = {"cmaes"},
      .seed_domain = 0x434d4145,          // "CMAE"
      .refine_seed_domain = 0x52434d41};  // "RCMA"
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = CmaesOptions;
    v.internal("seed", &O::seed, "Seed of the stream that draws every sample.");
    v.internal("stream", &O::stream, "Stream of that seed (change it, or the seed, for an independent run).");
    v.integer("max_iterations", &O::max_iterations, "CMA-ES: generations at most (0: the start only)", 0);
    v.integer("max_evaluations", &O::max_evaluations, "CMA-ES: U-hat evaluations at most", 1);
    v.integer("population_size", &O::population_size,
              "CMA-ES: samples per generation (0: 4 + floor(3 ln n), Hansen's default)", 0,
              kMaxPointsPerIteration);
    v.real("initial_step", &O::initial_step, "CMA-ES: first sigma, in parameter scales", 0, kNoUpperLimit,
           true);
    v.real("x_tolerance", &O::x_tolerance, "CMA-ES: stop when every step is below this, in scales (0: off)",
           0, kNoUpperLimit);
    v.real("function_tolerance", &O::function_tolerance,
           "CMA-ES: stop when recent best U-hats differ by less than this (0: off)", 0, kNoUpperLimit);
    v.real("max_condition", &O::max_condition,
           "CMA-ES: fail when the covariance's condition number passes this", 1, kNoUpperLimit);
    v.integer("stall_generations", &O::stall_generations,
              "CMA-ES: a run stops when its best U-hat rose by at most stall_tolerance over this many "
              "generations (0: off)",
              0);
    v.real("stall_tolerance", &O::stall_tolerance, "CMA-ES: see stall_generations", 0, kNoUpperLimit);
    v.integer(
        "restarts", &O::restarts,
        "CMA-ES: runs after the first (IPOP): each starts again from the start with twice the population", 0,
        kCmaesMaxRestarts);
  }
};

// The population size the first run of these options uses on n parameters (resolves population_size = 0);
// restart r uses 2^r times as many.
int CmaesPopulationSize(const CmaesOptions& options, std::size_t parameter_count);

// Maximises objective from *theta (clamped into the bounds; empty = the spec's initial values), which is
// evaluated first and is the distribution's first mean. On return *theta is the best theta evaluated and
// summary->final_step is sigma (scaled units). Throws InputError for invalid options or a foreign
// checkpoint.
void Solve(const CmaesOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary);

}  // namespace pegasus
