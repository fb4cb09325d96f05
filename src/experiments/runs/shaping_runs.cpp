#include "pegasus/experiments/runs/shaping_runs.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus {

namespace {

const char* legend_name(const std::string& potential) {
  if (potential == "none") return "no shaping";
  if (potential == "half") return "Phi = 0.5 Phi0";
  if (potential == "phi0") return "Phi = Phi0";
  return "Phi = Phi1";
}

nlohmann::json steps_at(const ShapingCurve& c) {
  auto at = [&](std::size_t t) -> nlohmann::json {
    if (t < 1 || t > c.mean.size()) return nullptr;
    return c.mean[t - 1];
  };
  return {{"1", at(1)}, {"10", at(10)}, {"100", at(100)}, {"last", at(c.mean.size())}};
}

nlohmann::json learning_summary(const ShapingExperimentResult& r, const ShapingExperimentOptions& o) {
  nlohmann::json curves = nlohmann::json::array(), total = nlohmann::json::object(),
                 truncated = nlohmann::json::object();
  for (const auto& c : r.curves) {
    curves.push_back(
        {{"potential", c.potential},
         {"steps_at", steps_at(c)},
         {"trials_to_within_25pct",
          c.trials_to_within_25pct ? nlohmann::json(*c.trials_to_within_25pct) : nlohmann::json(nullptr)}});
    total[c.potential] = c.total_steps;
    truncated[c.potential] = c.truncated_trials;
  }
  return {{"experiment", o.world == ShapingWorld::kGridworld ? "shaping-gridworld" : "shaping-flags"},
          {"size", o.size},
          {"runs", o.runs},
          {"trials", o.trials},
          {"optimal_expected_steps", r.optimal_expected_steps},
          {"curves", curves},
          {"total_steps", total},
          {"truncated_trials", truncated}};
}

// Plot points: trials grouped into bins (edges[i] .. edges[i+1] - 1, 1-based), each drawn at its mean trial
// with the mean of its curve values, so that a long run still gives a small SVG. Linear x: equal bins of
// ceil(T / 1000) trials; log x: every trial up to 100, then about 150 bins per decade.
std::vector<int> bin_edges(int trials, bool log_x) {
  std::vector<int> edges = {1};
  const int width = std::max(1, (trials + 999) / 1000);
  while (edges.back() <= trials) {
    const int t = edges.back();
    const int next =
        log_x ? std::max(t + 1, static_cast<int>(std::ceil(t * std::pow(10.0, 1.0 / 150.0)))) : t + width;
    edges.push_back(std::min(next, trials + 1));
  }
  return edges;
}

// The curves binned (bin_edges) as potential, trial, mean, stderr rows, and their chart (Figs 3.2-3.3).
Chart binned_curves(const RunDirectory& dir, const ShapingExperimentResult& r,
                    const ShapingExperimentOptions& o, bool log_scale) {
  const bool grid = o.world == ShapingWorld::kGridworld;
  const std::vector<int> edges = bin_edges(o.trials, log_scale);
  const bool binned = edges.size() - 1 < static_cast<std::size_t>(o.trials);
  const std::string file = log_scale ? "curves_binned_log.csv" : "curves_binned.csv";
  CsvWriter csv({"potential", "trial", "mean", "stderr"});
  for (const auto& c : r.curves) {
    for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
      double x = 0, y = 0, e = 0;
      const int n = edges[b + 1] - edges[b];
      for (int t = edges[b]; t < edges[b + 1]; ++t) {
        x += t;
        y += c.mean[static_cast<std::size_t>(t - 1)];
        e += c.standard_error[static_cast<std::size_t>(t - 1)];
      }
      csv.add_row({std::string(legend_name(c.potential)), x / n, y / n, e / n});
    }
  }
  dir.write_csv(file, csv);
  const AxisScale scale = log_scale ? AxisScale::kLog10 : AxisScale::kLinear;
  return {.title = fmt::format("{} {}x{}{}: {} runs{}", grid ? "Gridworld" : "Flag world", o.size, o.size,
                               grid ? (o.size == 10   ? " (Fig 3.2a)"
                                       : o.size == 50 ? " (Fig 3.2b)"
                                                      : "")
                                    : (o.size == 5 ? " (Fig 3.3a)" : " (Fig 3.3b)"),
                               o.runs, binned ? ", trials binned" : "") +
                   (log_scale ? ", log-log" : ""),
          .x = {"trial", scale},
          .y = {"steps to goal (mean, band +- 1 s.e.)", scale},
          .traces = {{.file = file,
                      .x = "trial",
                      .y = "mean",
                      .group_by = {"potential"},
                      .band = "stderr",
                      .band_name = "+-1 s.e.",
                      .mode = edges.size() <= 61 ? "lines+markers" : "lines"}},
          .references = {{.y = r.optimal_expected_steps, .name = "optimal (value iteration)"}}};
}

// Each finished run is saved as checkpoint/<potential>-<run>.json (written atomically, once); a resumed run
// reads them back. They are removed once the results are written.
constexpr const char* kRunCheckpoints = "checkpoint";

std::string run_checkpoint_name(const ShapingExperimentOptions& o, const ShapingRunRecord& r) {
  return fmt::format("{}/{}-{:06}.json", kRunCheckpoints, o.potentials[static_cast<std::size_t>(r.potential)],
                     r.run);
}

std::vector<ShapingRunRecord> load_run_checkpoints(const RunDirectory& dir,
                                                   const ShapingExperimentOptions& o) {
  std::vector<ShapingRunRecord> runs;
  const std::filesystem::path folder = dir.path() / kRunCheckpoints;
  if (!std::filesystem::is_directory(folder)) return runs;
  std::vector<std::filesystem::path> files;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    if (entry.is_regular_file() && entry.path().extension() == ".json" &&
        !entry.path().filename().string().starts_with("."))
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    ShapingRunRecord r = shaping_run_from_json(read_json_file(file));
    if (r.potential < 0 || r.potential >= static_cast<int>(o.potentials.size()) ||
        file.filename() != std::filesystem::path(run_checkpoint_name(o, r)).filename())
      throw std::runtime_error(fmt::format("{}: does not belong to this run's potentials", file.string()));
    runs.push_back(std::move(r));
  }
  return runs;
}

}  // namespace

void run_shaping_learning(const ShapingExperimentOptions& o, RunSink& sink) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  RunDirectory& dir = sink.dir;
  std::ostream& out = sink.out;

  ShapingExperimentHooks hooks;
  hooks.resume_from = load_run_checkpoints(dir, o);
  const auto total = static_cast<std::uint64_t>(o.potentials.size()) * static_cast<std::uint64_t>(o.runs);
  auto bar = sink.progress("runs", total);
  bar.skip(hooks.resume_from.size());
  hooks.on_runs = [&](std::span<const ShapingRunRecord> runs) {
    for (const auto& r : runs) dir.write_text(run_checkpoint_name(o, r), to_json(r).dump());
    bar.advance(runs.size());
  };
  const ShapingExperimentResult result = run_shaping_experiment(o, hooks);
  bar.finish();

  std::vector<std::string> header = {"trial"};
  for (const auto& c : result.curves) {
    header.push_back(c.potential + "_mean");
    header.push_back(c.potential + "_stderr");
  }
  CsvWriter curves(header);
  for (int t = 0; t < o.trials; ++t) {
    std::vector<CsvCell> row = {std::int64_t{t + 1}};
    for (const auto& c : result.curves) {
      row.emplace_back(c.mean[static_cast<std::size_t>(t)]);
      row.emplace_back(c.standard_error[static_cast<std::size_t>(t)]);
    }
    curves.add_row(std::move(row));
  }
  dir.write_csv("curves.csv", curves);
  CsvWriter runs(
      {"potential", "run", "total_steps", "first_trial_steps", "last_trial_steps", "truncated_trials"});
  for (const auto& r : result.runs) {
    std::int64_t sum = 0;
    for (auto s : r.steps) sum += s;
    runs.add_row({o.potentials[static_cast<std::size_t>(r.potential)], std::int64_t{r.run}, sum,
                  r.steps.front(), r.steps.back(), std::int64_t{r.truncated_trials}});
  }
  dir.write_csv("runs.csv", runs);
  const Chart linear = binned_curves(dir, result, o, false), loglog = binned_curves(dir, result, o, true);
  dir.add_charts(ChartSection{
      .id = "shaping",
      .title = o.world == ShapingWorld::kGridworld ? "Shaping curves (Fig 3.2)" : "Shaping curves (Fig 3.3)",
      .intro =
          fmt::format("Sarsa's steps to the goal per trial, mean over {} runs, for each potential; the "
                      "shaded band is +-1 standard error (every trial in curves.csv, binned for drawing).",
                      o.runs),
      .charts = {linear, loglog},
      .data = {"curves.csv", "runs.csv"}});
  dir.write_chart_svg("steps_per_trial.svg", linear);
  dir.write_chart_svg("steps_per_trial_loglog.svg", loglog);
  dir.write_json("summary.json", learning_summary(result, o));
  // Everything is written: the per-run checkpoints are no longer needed (a crash from here on only makes a
  // --resume learn the runs again, to the same result).
  std::filesystem::remove_all(dir.path() / kRunCheckpoints);

  out << fmt::format("optimal expected steps (value iteration): {:.4f}\n", result.optimal_expected_steps);
  for (const auto& c : result.curves) {
    auto fmt_at = [&](std::size_t t) {
      return t <= c.mean.size() ? fmt::format("{:.1f}", c.mean[t - 1]) : std::string("-");
    };
    out << fmt::format(
        "{:>4}: mean steps at trial 1 / 10 / 100 / last: {} / {} / {} / {}; 10-trial average within "
        "25% of optimal {}\n",
        c.potential, fmt_at(1), fmt_at(10), fmt_at(100), fmt_at(c.mean.size()),
        c.trials_to_within_25pct ? fmt::format("from trial {}", *c.trials_to_within_25pct)
                                 : std::string("never"));
    if (c.truncated_trials > 0)
      out << fmt::format("      {} trials were cut off at {} steps\n", c.truncated_trials,
                         o.max_steps_per_trial);
  }
}

namespace {

std::string cell_text(int s, int n) { return fmt::format("({},{})", s % n, s / n); }

std::string states_text(const std::vector<int>& states, int n, std::size_t limit = 40) {
  std::string out;
  for (std::size_t i = 0; i < states.size() && i < limit; ++i)
    out += (i ? " -> " : "") + cell_text(states[i], n);
  if (states.size() > limit) out += fmt::format(" -> ... ({} states)", states.size());
  return out;
}

nlohmann::json outcome_json(const GreedyPolicyOutcome& g, int n) {
  auto cells = [&](const std::vector<int>& states) {
    nlohmann::json a = nlohmann::json::array();
    for (int s : states) a.push_back({s % n, s / n});
    return a;
  };
  return {{"shaping", g.shaping},
          {"reaches_goal", g.reaches_goal},
          {"path", cells(g.path)},
          {"cycle", cells(g.cycle)},
          {"cycle_shaping", g.cycle_shaping},
          {"cycle_reward", g.cycle_reward},
          {"proper", g.proper},
          {"expected_steps", g.expected_steps ? nlohmann::json(*g.expected_steps) : nlohmann::json(nullptr)},
          {"truncated_episodes", g.truncated_episodes}};
}

void print_outcome(std::ostream& out, const GreedyPolicyOutcome& g, int n, double optimal) {
  out << fmt::format("{}: greedy policy after learning, followed along its most likely moves from {}:\n",
                     g.shaping, cell_text(g.path.front(), n));
  if (g.reaches_goal) {
    out << fmt::format("  reaches the goal in {} steps: {}\n", g.path.size() - 1, states_text(g.path, n));
  } else {
    std::vector<int> loop = g.cycle,
                     walk(g.path.begin(), g.path.end() - static_cast<std::ptrdiff_t>(g.cycle.size()));
    loop.push_back(g.cycle.front());
    walk.push_back(g.cycle.front());
    out << fmt::format(
        "  never reaches the goal: {}it goes round the cycle {} forever\n",
        walk.size() > 1 ? fmt::format("it walks {}, then ", states_text(walk, n, 12)) : std::string(),
        states_text(loop, n));
    out << fmt::format(
        "  around the cycle the learner collects shaping {:+.6g} and reward + shaping {:+.6g}\n",
        g.cycle_shaping, g.cycle_reward);
  }
  if (g.expected_steps)
    out << fmt::format(
        "  exact expected steps to the goal in the unshaped gridworld: {:.2f} (optimal {:.2f})\n",
        *g.expected_steps, optimal);
  else
    out << "  it does not reach the goal with probability 1 in the unshaped gridworld\n";
  if (g.truncated_episodes > 0)
    out << fmt::format("  {} of {} learning episodes were cut off\n", g.truncated_episodes,
                       g.episode_steps.size());
}

}  // namespace

void run_shaping_progress_bonus(const ProgressBonusOptions& o, std::ostream& out,
                                const RunDirectory* run_dir) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  const ProgressBonusResult r = run_progress_bonus_demo(o);

  print_outcome(out, r.bonus, o.size, r.optimal_expected_steps);
  print_outcome(out, r.potential, o.size, r.optimal_expected_steps);
  if (run_dir == nullptr) return;
  const RunDirectory& dir = *run_dir;
  dir.write_json("summary.json", {{"experiment", "shaping-progress-bonus"},
                                  {"size", o.size},
                                  {"bonus", o.bonus},
                                  {"optimal_expected_steps", r.optimal_expected_steps},
                                  {"progress_bonus", outcome_json(r.bonus, o.size)},
                                  {"potential", outcome_json(r.potential, o.size)}});
  CsvWriter csv({"episode", "progress_bonus_steps", "potential_steps"});
  for (std::size_t e = 0; e < r.bonus.episode_steps.size(); ++e)
    csv.add_row({static_cast<std::int64_t>(e + 1), r.bonus.episode_steps[e], r.potential.episode_steps[e]});
  dir.write_csv("learning_curves.csv", csv);
  dir.add_charts(ChartSection{.id = "learning-curves",
                              .title = "Learning curves",
                              .intro = "Steps per episode of each learner (learning_curves.csv).",
                              .charts = {{.title = "Steps per episode",
                                          .x = {"episode"},
                                          .y = {"steps to the goal", AxisScale::kLog10},
                                          .traces = {{.file = "learning_curves.csv",
                                                      .x = "episode",
                                                      .y = "progress_bonus_steps",
                                                      .name = "progress bonus",
                                                      .width = 1},
                                                     {.file = "learning_curves.csv",
                                                      .x = "episode",
                                                      .y = "potential_steps",
                                                      .name = "potential-based",
                                                      .width = 1}}}}});
}

}  // namespace pegasus
