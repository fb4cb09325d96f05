#pragma once
// The learning-speed experiments of thesis §3.4 (Figs 3.2 and 3.3): Sarsa (0.1-greedy, learning rate 0.02,
// Q initialised to 0) on the 80/20 gridworld or the flag world, with no shaping and with potential-based
// shaping, averaged over independent runs; the steps to the goal of every trial (episode) of every run.
//
// Potentials (Phi of the goal / terminal state is 0; F = Phi(s') - Phi(s) since gamma = 1):
//   "none"  no shaping
//   "phi0"  gridworld: -manhattan(s, goal)/0.8; flag world: -((n - n_s - 0.5)/n) t  (flags_phi0)
//   "half"  0.5 * phi0 (the thesis's deliberately poor gridworld potential)
//   "phi1"  flag world only: -(remaining Manhattan length of the flag route)/0.8  (flags_phi1)
//
// Determinism. Run r of every potential draws from BlockUniformStream(seed, stream = r), so the curves are
// compared under common random numbers; runs are independent work items (any thread, any order, stepped
// four at a time by sarsa_runs, which is identical to running them separately) and every mean over runs is
// taken in run order, so neither --threads nor a resume changes a bit of the result.
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pegasus {

enum class ShapingWorld { kGridworld, kFlags };

struct ShapingExperimentOptions {
  ShapingWorld world = ShapingWorld::kGridworld;
  // Gridworld: side n >= 2 (start (0, 0), goal (n-1, n-1)); flag world: 5 or 8.
  int size = 10;
  // Curves to learn, in legend order; each one of "none", "phi0", "half", "phi1" (phi1: flag world only).
  std::vector<std::string> potentials = {"none", "half", "phi0"};
  // Independent runs per potential (the thesis averaged 40). Must be >= 1.
  int runs = 40;
  // Trials (episodes) per run. Must be >= 1.
  int trials = 300;
  // Sarsa learning rate in (0, 1] and exploration rate in [0, 1] (§3.4: 0.02 and 0.1).
  double alpha = 0.02;
  double epsilon = 0.1;
  // Probability that a move goes the intended way before the uniform slip (§3.4: 0.8).
  double intended = 0.8;
  // A trial that takes this many steps is cut off (and counted). Must be >= 1.
  std::int64_t max_steps_per_trial = 100'000'000;
  // Root of the randomness; worker threads (never changes a result).
  std::uint64_t seed = 1;
  int threads = 1;

  bool IsValid(std::string* error) const;
};

// The learning curve of one run under one potential.
struct ShapingRunRecord {
  int potential = 0;  // index into options.potentials
  int run = 0;
  std::vector<std::int64_t> steps{};  // steps to the goal, one per trial
  int truncated_trials = 0;           // trials cut off at max_steps_per_trial
};

struct ShapingCurve {
  std::string potential{};
  std::vector<double> mean{};            // mean steps over runs, per trial (trial t at index t - 1)
  std::vector<double> standard_error{};  // of that mean, per trial (0 with one run)
  // First trial t >= window whose trailing `window`-trial average of `mean` is within 25% of the optimal
  // expected steps (|avg - opt| <= 0.25 opt); nullopt if none.
  std::optional<int> trials_to_within_25pct{};
  std::int64_t total_steps = 0;  // over all runs and trials
  int truncated_trials = 0;      // over all runs
};

struct ShapingExperimentResult {
  double optimal_expected_steps = 0.0;   // exact: -V*(start) of the same MDP, by value iteration
  std::vector<ShapingCurve> curves{};    // in options.potentials order
  std::vector<ShapingRunRecord> runs{};  // in (potential, run) order
};

struct ShapingExperimentHooks {
  // Called with the runs of each finished work item (up to four runs of one potential, learned together),
  // one call at a time, from whichever thread finished them: the place to save a checkpoint.
  std::function<void(std::span<const ShapingRunRecord>)> on_runs{};
  // Runs finished earlier (a resumed run): they are kept, not learned again.
  std::vector<ShapingRunRecord> resume_from{};
};

ShapingExperimentResult run_shaping_experiment(const ShapingExperimentOptions& options,
                                               const ShapingExperimentHooks& hooks = {});

// The potential `name` of the world described by `options` (one value per state of its MDP); empty for
// "none". Throws InputError for an unknown name or phi1 on the gridworld.
std::vector<double> shaping_experiment_potential(const ShapingExperimentOptions& options,
                                                 const std::string& name);

// First 1-based trial t >= window at which the average of mean[t - window .. t - 1] is within
// `fraction` * target of target; nullopt if none.
std::optional<int> trials_to_within(const std::vector<double>& mean, double target, double fraction = 0.25,
                                    int window = 10);

nlohmann::json to_json(const ShapingRunRecord& r);
// Throws std::runtime_error when a field is missing or has the wrong type.
ShapingRunRecord shaping_run_from_json(const nlohmann::json& j);

}  // namespace pegasus
