#pragma once
// The POMDP gridworld experiment of thesis §4.6 (Fig 4.5b). For each number of scenarios m and each of T
// independent trials: compute U-hat of all 4^8 table policies, pick the argmax, and record the EXACT value
// of the chosen policy, its estimate, and the sup over all policies of |U-hat - U| (the uniform-convergence
// quantity of Theorem 10 and Proposition 8). Done for PEGASUS on the normal model, PEGASUS on the hashed
// model, and naive Monte Carlo (fresh randomness for every policy evaluation).
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {

struct PomdpGridworldOptions {
  std::vector<int> scenarios = {1, 2, 4, 8, 16, 32, 64};  // the values of m
  int trials = 200;                                       // T independent scenario sets per m
  int montecarlo_max_m = 16;                              // naive Monte Carlo only for m <= this
  double gamma = 0.99;
  int horizon = 100;
  bool hashed = true;      // also run PEGASUS on the hashed model g'
  bool montecarlo = true;  // also run naive Monte Carlo
  ScenarioVariant variant = ScenarioVariant::kPlain;
  std::uint64_t seed = 1;
  int threads = 1;

  bool IsValid(std::string* error) const;
};

// One (model, estimator, m) cell of one trial.
struct PomdpGridworldRecord {
  int trial = 0;
  std::string model;      // "normal" | "hashed"
  std::string estimator;  // "pegasus" | "montecarlo"
  int m = 0;
  std::uint32_t chosen_policy = 0;
  double true_value = 0;     // exact value of the chosen policy
  double estimate = 0;       // its U-hat
  double sup_deviation = 0;  // max over all policies of |U-hat - U|
};

struct PomdpGridworldSummaryRow {
  std::string model, estimator;
  int m = 0, trials = 0;
  double mean_true_value = 0, stderr_true_value = 0, mean_estimate = 0, mean_sup_deviation = 0;
};

struct PomdpGridworldResult {
  double best_in_class_value = 0;  // exact value of the best table policy
  std::uint32_t best_in_class_policy = 0;
  std::vector<PomdpGridworldRecord> records;  // in (trial, model, estimator, m) order
  std::vector<PomdpGridworldSummaryRow> rows;
};

struct PomdpGridworldHooks {
  // Called after each finished trial with the number of finished trials.
  std::function<void(int)> on_trial;
  // Called after each finished trial with a checkpoint (the records so far) to save.
  std::function<void(const nlohmann::json&)> on_checkpoint;
  // A checkpoint to continue from.
  std::optional<nlohmann::json> resume_from;
};

PomdpGridworldResult run_pomdp_gridworld(const PomdpGridworldOptions& options,
                                         const PomdpGridworldHooks& hooks = {});

// Aggregates per-trial records into the summary rows (mean, standard error) in a fixed order.
std::vector<PomdpGridworldSummaryRow> summarize(const std::vector<PomdpGridworldRecord>& records);

nlohmann::json to_json(const PomdpGridworldRecord& r);
PomdpGridworldRecord record_from_json(const nlohmann::json& j);

}  // namespace pegasus
