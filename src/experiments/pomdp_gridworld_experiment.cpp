#include "pegasus/experiments/pomdp_gridworld_experiment.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/pomdp_gridworld.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/table_policy_values.hpp"
#include "pegasus/models/hashed_model.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus {
namespace {

constexpr int kObservations = 8;

// Seeds of the independent pieces of one trial, derived from the run's seed.
enum class SeedRole : std::uint64_t { kScenarios = 1, kHash = 2, kMonteCarlo = 3 };
std::uint64_t trial_seed(std::uint64_t seed, int trial, SeedRole role, int m = 0) {
  return mix_seed(mix_seed(seed, static_cast<std::uint64_t>(role)),
                  (static_cast<std::uint64_t>(trial) << 20) | static_cast<std::uint64_t>(m));
}

PomdpGridworldRecord score(int trial, const char* model, const char* estimator, int m,
                           const std::vector<double>& estimates, const std::vector<double>& exact) {
  PomdpGridworldRecord r{.trial = trial, .model = model, .estimator = estimator, .m = m};
  std::size_t best = 0;
  double sup = 0.0;
  for (std::size_t k = 0; k < estimates.size(); ++k) {
    if (estimates[k] > estimates[best]) best = k;  // ties go to the lowest index
    sup = std::max(sup, std::abs(estimates[k] - exact[k]));
  }
  r.chosen_policy = static_cast<std::uint32_t>(best);
  r.true_value = exact[best];
  r.estimate = estimates[best];
  r.sup_deviation = sup;
  return r;
}

}  // namespace

bool PomdpGridworldOptions::IsValid(std::string* error) const {
  auto fail = [&](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (scenarios.empty()) return fail("scenarios: expected a non-empty list of m values");
  for (int m : scenarios)
    if (m < 1 || m > 100000)
      return fail(fmt::format("scenarios: expected every m in [1, 100000], got {}", m));
  if (trials < 1) return fail(fmt::format("trials: expected an integer >= 1, got {}", trials));
  if (montecarlo_max_m < 0) return fail("montecarlo_max_m: expected an integer >= 0");
  if (!(gamma >= 0.0 && gamma <= 1.0))
    return fail(fmt::format("gamma: expected a number in [0, 1], got {}", gamma));
  if (horizon < 1 || horizon > 100000)
    return fail(fmt::format("horizon: expected an integer in [1, 100000], got {}", horizon));
  if (threads < 1) return fail(fmt::format("threads: expected an integer >= 1, got {}", threads));
  return true;
}

nlohmann::json to_json(const PomdpGridworldRecord& r) {
  return {{"trial", r.trial},
          {"model", r.model},
          {"estimator", r.estimator},
          {"m", r.m},
          {"chosen_policy", r.chosen_policy},
          {"true_value", r.true_value},
          {"estimate", r.estimate},
          {"sup_deviation", r.sup_deviation}};
}

PomdpGridworldRecord record_from_json(const nlohmann::json& j) {
  return {.trial = j.at("trial").get<int>(),
          .model = j.at("model").get<std::string>(),
          .estimator = j.at("estimator").get<std::string>(),
          .m = j.at("m").get<int>(),
          .chosen_policy = j.at("chosen_policy").get<std::uint32_t>(),
          .true_value = j.at("true_value").get<double>(),
          .estimate = j.at("estimate").get<double>(),
          .sup_deviation = j.at("sup_deviation").get<double>()};
}

std::vector<PomdpGridworldSummaryRow> summarize(const std::vector<PomdpGridworldRecord>& records) {
  // Keyed in a fixed order: model, estimator, m.
  std::map<std::tuple<std::string, std::string, int>, std::vector<const PomdpGridworldRecord*>> groups;
  for (const auto& r : records) groups[{r.model, r.estimator, r.m}].push_back(&r);
  std::vector<PomdpGridworldSummaryRow> rows;
  for (const auto& [key, group] : groups) {
    PomdpGridworldSummaryRow row{
        .model = std::get<0>(key), .estimator = std::get<1>(key), .m = std::get<2>(key)};
    row.trials = static_cast<int>(group.size());
    double sum = 0, sum2 = 0, est = 0, sup = 0;
    for (const auto* r : group) {
      sum += r->true_value;
      sum2 += r->true_value * r->true_value;
      est += r->estimate;
      sup += r->sup_deviation;
    }
    const double n = static_cast<double>(group.size());
    row.mean_true_value = sum / n;
    const double variance = n > 1 ? std::max(0.0, (sum2 - sum * sum / n) / (n - 1)) : 0.0;
    row.stderr_true_value = std::sqrt(variance / n);
    row.mean_estimate = est / n;
    row.mean_sup_deviation = sup / n;
    rows.push_back(row);
  }
  return rows;
}

PomdpGridworldResult run_pomdp_gridworld(const PomdpGridworldOptions& options,
                                         const PomdpGridworldHooks& hooks) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  const PomdpGridworld grid;
  const Discounting d{.gamma = options.gamma, .horizon = options.horizon};
  ThreadPool pool(options.threads);

  PomdpGridworldResult result;
  const std::vector<double> exact = grid.exact_values_of_all_policies(d, &pool);
  const auto best = std::max_element(exact.begin(), exact.end());
  result.best_in_class_value = *best;
  result.best_in_class_policy = static_cast<std::uint32_t>(best - exact.begin());

  int first_trial = 0;
  if (hooks.resume_from) {
    for (const auto& j : hooks.resume_from->at("records")) result.records.push_back(record_from_json(j));
    first_trial = hooks.resume_from->at("trials_done").get<int>();
  }

  const int max_m = *std::max_element(options.scenarios.begin(), options.scenarios.end());
  const TablePolicy policy(kObservations, PomdpGridworld::kActions);
  std::vector<double> estimates(exact.size());
  std::vector<Theta> all_thetas;
  for (std::uint64_t k = 0; k < exact.size(); ++k) all_thetas.push_back(policy.theta_of_index(k));

  for (int trial = first_trial; trial < options.trials; ++trial) {
    // One scenario set per trial; m scenarios are its first m (common random numbers across m).
    const ScenarioOptions base{.seed = trial_seed(options.seed, trial, SeedRole::kScenarios),
                               .count = max_m,
                               .horizon = options.horizon,
                               .noise_dim = 1,
                               .initial_noise_dim = 0,
                               .variant = options.variant};
    const HashedModel<PomdpGridworld> hashed(grid, trial_seed(options.seed, trial, SeedRole::kHash));
    for (int m : options.scenarios) {
      ScenarioOptions o = base;
      o.count = m;
      // Sobol and stratified sets depend on m as a whole; plain and antithetic ones are prefixes.
      const ScenarioSet set(o);
      TablePolicyValues(grid, kObservations, set, d).compute(estimates, &pool);
      result.records.push_back(score(trial, "normal", "pegasus", m, estimates, exact));
      if (options.hashed) {
        TablePolicyValues(hashed, kObservations, set, d).compute(estimates, &pool);
        result.records.push_back(score(trial, "hashed", "pegasus", m, estimates, exact));
      }
    }
    if (options.montecarlo) {
      for (int m : options.scenarios) {
        if (m > options.montecarlo_max_m) continue;
        MonteCarloEvaluator mc(grid, policy, m, d, trial_seed(options.seed, trial, SeedRole::kMonteCarlo, m));
        mc.evaluate_batch(all_thetas, estimates, &pool);
        result.records.push_back(score(trial, "normal", "montecarlo", m, estimates, exact));
      }
    }
    if (hooks.on_checkpoint) {
      nlohmann::json records = nlohmann::json::array();
      for (const auto& r : result.records) records.push_back(to_json(r));
      hooks.on_checkpoint({{"trials_done", trial + 1}, {"records", records}});
    }
    if (hooks.on_trial) hooks.on_trial(trial + 1);
  }
  result.rows = summarize(result.records);
  return result;
}

}  // namespace pegasus
