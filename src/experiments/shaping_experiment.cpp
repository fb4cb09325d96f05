#include "pegasus/experiments/shaping_experiment.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <span>
#include <stdexcept>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/flags.hpp"
#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/learners.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/random/block_stream.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {
namespace {

// sarsa_runs steps this many runs in lockstep on one thread; a work item is one such group.
constexpr std::size_t kRunsPerItem = 4;

bool known_potential(const std::string& name) {
  return name == "none" || name == "phi0" || name == "half" || name == "phi1";
}

// Learns runs `run_ids` on `model` and writes their records.
template <TabularModel M>
std::vector<ShapingRunRecord> learn(const M& model, const TdOptions& td, std::uint64_t seed, int potential,
                                    std::span<const int> run_ids) {
  std::vector<BlockUniformStream> rngs;
  std::vector<QTable> qs;
  rngs.reserve(run_ids.size());
  qs.reserve(run_ids.size());
  for (int r : run_ids) {
    rngs.emplace_back(seed, static_cast<std::uint32_t>(r));
    qs.emplace_back(model.num_states(), model.num_actions(), 0.0);
  }
  const std::vector<LearningCurve> curves = sarsa_runs(model, td, std::span(rngs), std::span(qs));
  std::vector<ShapingRunRecord> out;
  for (std::size_t k = 0; k < run_ids.size(); ++k)
    out.push_back({.potential = potential,
                   .run = run_ids[k],
                   .steps = curves[k].steps,
                   .truncated_trials = curves[k].truncated_episodes});
  return out;
}

// Calls f(model) with the world of `o`, shaped by `phi` unless it is empty.
template <class F>
auto with_model(const ShapingExperimentOptions& o, const std::vector<double>& phi, F&& f) {
  auto dispatch = [&](const auto& world) {
    if (phi.empty()) return f(world);
    return f(shape(world, TablePotential{phi}, 1.0));
  };
  if (o.world == ShapingWorld::kGridworld) return dispatch(corner_gridworld(o.size, o.intended));
  return dispatch(flag_world(o.size, o.intended));
}

ShapingCurve summarize_curve(const std::string& name, std::span<const ShapingRunRecord> runs, int trials) {
  ShapingCurve c{.potential = name};
  c.mean.assign(static_cast<std::size_t>(trials), 0.0);
  c.standard_error.assign(static_cast<std::size_t>(trials), 0.0);
  const double n = static_cast<double>(runs.size());
  for (int t = 0; t < trials; ++t) {
    const auto i = static_cast<std::size_t>(t);
    double sum = 0.0;
    for (const auto& r : runs) sum += static_cast<double>(r.steps[i]);
    const double mean = sum / n;
    double ss = 0.0;
    for (const auto& r : runs)
      ss += (static_cast<double>(r.steps[i]) - mean) * (static_cast<double>(r.steps[i]) - mean);
    c.mean[i] = mean;
    c.standard_error[i] = runs.size() > 1 ? std::sqrt(ss / (n - 1.0) / n) : 0.0;
  }
  for (const auto& r : runs) {
    for (auto s : r.steps) c.total_steps += s;
    c.truncated_trials += r.truncated_trials;
  }
  return c;
}

// Where run r of potential p sits among the records.
std::size_t run_slot(const ShapingExperimentOptions& o, int p, int r) {
  return static_cast<std::size_t>(p) * static_cast<std::size_t>(o.runs) + static_cast<std::size_t>(r);
}

// -V*(start): every step costs 1 and the goal ends the episode.
double optimal_expected_steps(const ShapingExperimentOptions& o) {
  const FiniteMdp mdp = o.world == ShapingWorld::kGridworld
                            ? to_finite_mdp(corner_gridworld(o.size, o.intended))
                            : to_finite_mdp(flag_world(o.size, o.intended));
  const SolveSummary vi = value_iteration(mdp);
  return -expected_under_initial(mdp, vi.value);
}

// A work item: up to kRunsPerItem unfinished runs of one potential.
struct WorkItem {
  int potential;
  std::vector<int> runs;
};

// The runs not `done`, as work items. The unshaped curve (usually listed first) is by far the slowest, so
// items are claimed in list order and the long ones start first.
std::vector<WorkItem> work_items(const ShapingExperimentOptions& o, const std::vector<std::uint8_t>& done) {
  std::vector<WorkItem> items;
  for (int p = 0; p < static_cast<int>(o.potentials.size()); ++p) {
    WorkItem item{.potential = p, .runs = {}};
    for (int r = 0; r < o.runs; ++r) {
      if (done[run_slot(o, p, r)]) continue;
      item.runs.push_back(r);
      if (item.runs.size() == kRunsPerItem) {
        items.push_back(item);
        item.runs.clear();
      }
    }
    if (!item.runs.empty()) items.push_back(item);
  }
  return items;
}

}  // namespace

bool ShapingExperimentOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (world == ShapingWorld::kGridworld && (size < 2 || size > 1000))
    return fail(fmt::format("size: expected a gridworld side in [2, 1000], got {}", size));
  if (world == ShapingWorld::kFlags && size != 5 && size != 8)
    return fail(fmt::format("size: expected 5 or 8 (the flag worlds of Fig 3.1b and 3.3b), got {}", size));
  if (potentials.empty()) return fail("potentials: expected at least one of none, phi0, half, phi1");
  for (std::size_t i = 0; i < potentials.size(); ++i) {
    const std::string& p = potentials[i];
    if (!known_potential(p))
      return fail(fmt::format("potentials: expected none, phi0, half or phi1, got \"{}\"", p));
    if (p == "phi1" && world == ShapingWorld::kGridworld)
      return fail("potentials: phi1 (remaining flag route) exists only in the flag world");
    if (std::find(potentials.begin(), potentials.begin() + static_cast<std::ptrdiff_t>(i), p) !=
        potentials.begin() + static_cast<std::ptrdiff_t>(i))
      return fail(fmt::format("potentials: \"{}\" is listed twice", p));
  }
  if (runs < 1 || runs > 100000)
    return fail(fmt::format("runs: expected an integer in [1, 100000], got {}", runs));
  if (trials < 1 || trials > 10'000'000)
    return fail(fmt::format("trials: expected an integer in [1, 10000000], got {}", trials));
  if (!(alpha > 0.0 && alpha <= 1.0))
    return fail(fmt::format("alpha: expected a number in (0, 1], got {}", alpha));
  if (!(epsilon >= 0.0 && epsilon <= 1.0))
    return fail(fmt::format("epsilon: expected a number in [0, 1], got {}", epsilon));
  if (!(intended > 0.0 && intended <= 1.0))
    return fail(fmt::format("intended: expected a number in (0, 1], got {}", intended));
  if (max_steps_per_trial < 1)
    return fail(fmt::format("max_steps_per_trial: expected an integer >= 1, got {}", max_steps_per_trial));
  if (threads < 1) return fail(fmt::format("threads: expected an integer >= 1, got {}", threads));
  return true;
}

std::vector<double> shaping_experiment_potential(const ShapingExperimentOptions& o, const std::string& name) {
  if (!known_potential(name)) throw InputError(fmt::format("potentials: unknown potential \"{}\"", name));
  if (name == "none") return {};
  if (o.world == ShapingWorld::kGridworld) {
    if (name == "phi1")
      throw InputError("potentials: phi1 (remaining flag route) exists only in the flag world");
    return manhattan_potential(corner_gridworld(o.size, o.intended), name == "half" ? 0.5 : 1.0);
  }
  const FlagWorld w = flag_world(o.size, o.intended);
  if (name == "phi1") return flags_phi1(w);
  std::vector<double> phi = flags_phi0(w);
  if (name == "half")
    for (double& v : phi) v *= 0.5;
  return phi;
}

std::optional<int> trials_to_within(const std::vector<double>& mean, double target, double fraction,
                                    int window) {
  if (window < 1) throw std::invalid_argument("trials_to_within: window must be >= 1");
  const auto w = static_cast<std::size_t>(window);
  for (std::size_t t = w; t <= mean.size(); ++t) {
    // Each window summed afresh, in trial order: no drift from a running sum.
    double avg = 0.0;
    for (std::size_t k = t - w; k < t; ++k) avg += mean[k];
    avg /= static_cast<double>(window);
    if (std::abs(avg - target) <= fraction * std::abs(target)) return static_cast<int>(t);
  }
  return std::nullopt;
}

nlohmann::json to_json(const ShapingRunRecord& r) {
  return {{"potential", r.potential},
          {"run", r.run},
          {"steps", r.steps},
          {"truncated_trials", r.truncated_trials}};
}

ShapingRunRecord shaping_run_from_json(const nlohmann::json& j) {
  try {
    return {.potential = j.at("potential").get<int>(),
            .run = j.at("run").get<int>(),
            .steps = j.at("steps").get<std::vector<std::int64_t>>(),
            .truncated_trials = j.at("truncated_trials").get<int>()};
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(fmt::format("checkpoint: malformed run record: {}", e.what()));
  }
}

ShapingExperimentResult run_shaping_experiment(const ShapingExperimentOptions& o,
                                               const ShapingExperimentHooks& hooks) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  const int P = static_cast<int>(o.potentials.size());
  const auto slot = [&](int p, int r) { return run_slot(o, p, r); };

  ShapingExperimentResult result;
  result.optimal_expected_steps = optimal_expected_steps(o);

  std::vector<ShapingRunRecord> records(static_cast<std::size_t>(P) * static_cast<std::size_t>(o.runs));
  std::vector<std::uint8_t> done(records.size(), 0);
  for (const auto& r : hooks.resume_from) {
    if (r.potential < 0 || r.potential >= P || r.run < 0 || r.run >= o.runs ||
        r.steps.size() != static_cast<std::size_t>(o.trials))
      throw std::runtime_error(
          fmt::format("checkpoint: run record (potential {}, run {}, {} trials) does not fit this "
                      "experiment",
                      r.potential, r.run, r.steps.size()));
    records[slot(r.potential, r.run)] = r;
    done[slot(r.potential, r.run)] = 1;
  }

  const std::vector<WorkItem> items = work_items(o, done);
  std::vector<std::vector<double>> phis;
  for (const auto& name : o.potentials) phis.push_back(shaping_experiment_potential(o, name));

  const TdOptions td{.episodes = o.trials,
                     .alpha = o.alpha,
                     .epsilon = o.epsilon,
                     .gamma = 1.0,
                     .max_steps_per_episode = o.max_steps_per_trial};
  std::mutex report;
  ThreadPool pool(o.threads);
  pool.parallel_for(
      items.size(),
      [&](std::size_t i) {
        const WorkItem& item = items[i];
        const auto learned = with_model(
            o, phis[static_cast<std::size_t>(item.potential)],
            [&](const auto& model) { return learn(model, td, o.seed, item.potential, item.runs); });
        const std::lock_guard lock(report);
        for (const auto& r : learned) records[slot(r.potential, r.run)] = r;
        if (hooks.on_runs) hooks.on_runs(learned);
      },
      1);

  for (int p = 0; p < P; ++p) {
    const std::span<const ShapingRunRecord> runs(records.data() + slot(p, 0),
                                                 static_cast<std::size_t>(o.runs));
    ShapingCurve c = summarize_curve(o.potentials[static_cast<std::size_t>(p)], runs, o.trials);
    c.trials_to_within_25pct = trials_to_within(c.mean, result.optimal_expected_steps);
    result.curves.push_back(std::move(c));
  }
  result.runs = std::move(records);
  return result;
}

}  // namespace pegasus
