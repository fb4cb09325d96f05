#include "pegasus/optimizers/training.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "../core/validation.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus {
namespace {

using json = nlohmann::json;

using detail::fail;

json PlanCheckpoint(const TrainingPlan& plan, std::size_t stage, const json& finished, json optimizer) {
  return json{{"format", kTrainingCheckpointFormat},
              {"version", kTrainingCheckpointVersion},
              {"stage", stage},
              {"finished", finished},
              {"optimizer", std::move(optimizer)},
              {"caller", plan.caller_state ? plan.caller_state() : json(nullptr)}};
}

// InputError unless `c` is an object whose "format" is the training checkpoint's (whatever types it holds).
void RequireTrainingCheckpoint(const json& c) {
  const auto format = c.is_object() ? c.find("format") : c.end();
  if (!c.is_object() || format == c.end() || !format->is_string() ||
      format->get<std::string>() != kTrainingCheckpointFormat)
    throw InputError(fmt::format("checkpoint: expected format \"{}\"", kTrainingCheckpointFormat));
}

// What the stages before one did: the merged history counts on from it.
struct StagesBefore {
  std::int64_t iterations = 0;
  std::int64_t evaluations = 0;
  double seconds = 0;
};

// Appends a stage's history to the merged one, counting on from the stages before it, and adds the stage to
// them. Counted from the stages' totals, not their last records: a stage that ends inside an iteration (a
// gradient whose line search found no uphill step) spent evaluations and time that no record shows.
void AppendHistory(const OptimizerSummary& stage, StagesBefore* before,
                   std::vector<IterationRecord>* merged) {
  const std::optional<double> best_before =
      merged->empty() ? std::nullopt : std::optional<double>(merged->back().value);
  for (IterationRecord r : stage.history) {
    r.iteration += before->iterations;
    r.evaluations += before->evaluations;
    r.seconds += before->seconds;
    if (best_before) r.value = std::max(r.value, *best_before);
    merged->push_back(r);
  }
  before->iterations += stage.iterations;
  before->evaluations += stage.evaluations;
  before->seconds += stage.wall_seconds;
}

// Names the sections a domain may belong to, for a section that is none of them.
std::string NoRandomMethod(const std::vector<std::pair<std::string_view, std::uint32_t>>& domains,
                           std::string_view section) {
  std::string sections;
  for (const auto& [name, domain] : domains)
    sections += fmt::format("{}{}", sections.empty() ? "" : ", ", name);
  return fmt::format(
      "seed domains: expected the options section of an optimizer that draws random numbers ({}), got '{}'",
      sections, section);
}

}  // namespace

SeedDomains::SeedDomains() {
  ForEachOptimizerMethod([&](auto member) {
    const OptimizerMethodInfo& info = OptimizerMethodOptions<decltype(member)>::kMethod;
    if (info.seed_domain != 0) domains_.emplace_back(info.section, info.seed_domain);
  });
}

SeedDomains SeedDomains::Refine() {
  SeedDomains refine;
  ForEachOptimizerMethod([&](auto member) {
    const OptimizerMethodInfo& info = OptimizerMethodOptions<decltype(member)>::kMethod;
    if (info.seed_domain != 0) refine.set(info.section, info.refine_seed_domain);
  });
  return refine;
}

std::uint32_t SeedDomains::of(std::string_view section) const {
  for (const auto& [name, domain] : domains_)
    if (name == section) return domain;
  throw InputError(NoRandomMethod(domains_, section));
}

void SeedDomains::set(std::string_view section, std::uint32_t domain) {
  for (auto& [name, value] : domains_)
    if (name == section) {
      value = domain;
      return;
    }
  throw InputError(NoRandomMethod(domains_, section));
}

void DeriveOptimizerSeeds(std::uint64_t run_seed, const SeedDomains& domains, OptimizerOptions* options) {
  ForEachOptimizerMethod([&](auto member) {
    using Options = OptimizerMethodOptions<decltype(member)>;
    if constexpr (Options::kMethod.seed_domain != 0)
      (options->*member).seed = mix_seed(run_seed, domains.of(Options::kMethod.section));
  });
}

bool TrainingPlan::IsValid(std::string* error) const {
  if (stages.empty()) return fail(error, "stages: expected at least one stage");
  for (std::size_t k = 0; k < stages.size(); ++k) {
    const TrainingStage& s = stages[k];
    if (s.name.empty()) return fail(error, fmt::format("stages[{}].name: expected a non-empty name", k));
    if (s.optimizer.method == "none") continue;
    std::string inner;
    if (!s.optimizer.IsValid(&inner)) return fail(error, fmt::format("stages[{}].optimizer.{}", k, inner));
  }
  if (checkpoint_every < 0)
    return fail(error, fmt::format("checkpoint_every: expected an integer >= 0, got {}", checkpoint_every));
  if (checkpoint_every > 0 && !on_checkpoint)
    return fail(error, "on_checkpoint: expected a callback when checkpoint_every > 0");
  for (const IterationCallback* c : callbacks)
    if (c == nullptr) return fail(error, "callbacks: expected no null callback");
  return true;
}

std::string TrainingSummary::BriefReport() const {
  std::string out;
  for (std::size_t k = 0; k < stages.size(); ++k)
    out += fmt::format("{}{}: {}", k == 0 ? "" : "\n", stage_names[k], stages[k].BriefReport());
  return out;
}

std::int64_t TrainingCheckpointIterations(const json& checkpoint) {
  RequireTrainingCheckpoint(checkpoint);
  std::int64_t done = 0;
  // Counts for a progress bar only: entries of another shape count as none (Train refuses them by name).
  auto iterations = [](const json& j) -> std::int64_t {
    const auto it = j.is_object() ? j.find("iterations") : j.end();
    return j.is_object() && it != j.end() && it->is_number_integer() ? it->get<std::int64_t>() : 0;
  };
  const auto finished = checkpoint.find("finished");
  if (finished != checkpoint.end() && finished->is_array())
    for (const json& s : *finished) done += iterations(s);
  if (const auto optimizer = checkpoint.find("optimizer"); optimizer != checkpoint.end())
    done += iterations(*optimizer);
  return done;
}

void Train(const TrainingPlan& plan, Objective& objective, Theta* theta, TrainingSummary* summary) {
  std::string error;
  if (!plan.IsValid(&error)) throw InputError("training plan: " + error);
  if (theta == nullptr || summary == nullptr)
    throw InputError("training: theta and summary must be non-null");
  *summary = TrainingSummary{};

  std::size_t first_stage = 0;
  json finished = json::array();
  std::optional<json> resume;
  if (plan.resume_from) {
    const json& c = *plan.resume_from;
    RequireTrainingCheckpoint(c);
    if (!c.contains("version") || c["version"] != kTrainingCheckpointVersion)
      throw InputError(fmt::format("checkpoint: version: expected {}", kTrainingCheckpointVersion));
    if (!c.contains("stage") || !c["stage"].is_number_unsigned() ||
        c["stage"].get<std::size_t>() >= plan.stages.size())
      throw InputError(fmt::format("checkpoint: stage: expected an index below {}", plan.stages.size()));
    first_stage = c["stage"].get<std::size_t>();
    if (!c.contains("finished") || !c["finished"].is_array() || c["finished"].size() > first_stage)
      throw InputError("checkpoint: finished: expected the summaries of the stages before `stage`");
    finished = c["finished"];
    if (c.contains("optimizer") && !c["optimizer"].is_null()) resume = c["optimizer"];
  }

  // The stages already finished, from the checkpoint.
  StagesBefore before;
  std::size_t next_finished = 0;
  for (std::size_t k = 0; k < first_stage; ++k) {
    if (plan.stages[k].optimizer.method == "none") continue;
    if (next_finished >= finished.size())
      throw InputError(fmt::format("checkpoint: finished: expected a summary of stage {}", k));
    OptimizerSummary s = SummaryFromJson(finished[next_finished++], fmt::format("finished[{}]", k));
    AppendHistory(s, &before, &summary->history);
    *theta = s.best_theta;
    summary->stage_names.push_back(plan.stages[k].name);
    summary->stages.push_back(std::move(s));
  }

  for (std::size_t k = first_stage; k < plan.stages.size(); ++k) {
    const TrainingStage& stage = plan.stages[k];
    if (stage.optimizer.method == "none") continue;
    OptimizerOptions options = stage.optimizer;
    if (stage.derive_seeds) DeriveOptimizerSeeds(plan.seed, stage.seeds, &options);
    if (plan.checkpoint_every > 0) {
      options.SetCheckpointing(
          plan.checkpoint_every,
          [&plan, k, &finished](const json& c) { plan.on_checkpoint(PlanCheckpoint(plan, k, finished, c)); },
          k == first_stage ? resume : std::nullopt);
    }
    options.SetCallbacks(plan.callbacks);
    if (stage.start_from) *theta = stage.start_from(*theta);
    OptimizerSummary s;
    Solve(options, stage.objective != nullptr ? *stage.objective : objective, theta, &s);
    *theta = s.best_theta;
    const bool stopped = s.termination_type == TerminationType::kUserRequested;
    AppendHistory(s, &before, &summary->history);
    finished.push_back(SummaryToJson(s));
    summary->stage_names.push_back(stage.name);
    summary->stages.push_back(std::move(s));
    if (stopped) {
      summary->stopped_by_callback = true;
      break;
    }
    // A stage boundary is a checkpoint: a kill now resumes at the next stage, not in this one.
    if (plan.checkpoint_every > 0 && k + 1 < plan.stages.size())
      plan.on_checkpoint(PlanCheckpoint(plan, k + 1, finished, nullptr));
  }
  if (summary->stages.empty()) throw InputError("training plan: every stage has method \"none\"");
  summary->initial_value = summary->stages.front().initial_value;
  summary->best_value = summary->stages.back().best_value;
  summary->best_theta = summary->stages.back().best_theta;
  // A NaN or infinite U-hat is no result: a run on it must not end as a success (issue 51: a NaN target or
  // time step trained to "U-hat NaN" with exit 0).
  if (plan.refuse_nonfinite_result && !std::isfinite(summary->best_value))
    throw NonFiniteObjective(fmt::format(
        "training: the best U-hat found is {} (not a finite number): the objective's returns are not finite "
        "(a NaN or infinite reward, state or time step in the task or model)",
        summary->best_value));
}

}  // namespace pegasus
