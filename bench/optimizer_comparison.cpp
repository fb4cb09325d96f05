// CMA-ES against gradient ascent and random-walk hill climbing on the two continuous PEGASUS problems of
// the thesis: U-hat of the best policy found after 100, 300, 1000 and 3000 evaluations (issue 14). A plain
// program run by hand (not a Google Benchmark: the figure is U-hat per evaluation, not time).
//
//   pegasus_optimizer_comparison [--problems hover,bicycle] [--seeds 3] [--budgets 100,300,1000,3000]
//                                [--threads 2] [--hover-scenarios 5] [--hover-seconds 10]
//                                [--bicycle-scenarios 30] [--bicycle-horizon 500] [--model model.json]
//                                [--out FILE.json]
//
// Problems, each as its command trains it:
//   hover    `heli hover` (thesis §5.3): the hover task on the identified model with the CLI's reward
//            (typical errors 0.5 m, 0.5 m/s, 0.1 rad, 0.1; action cost about the logs' trim), the 34-weight
//            hover policy from the logs' trim, gamma 0.9995; m scenarios of `seconds` s (small settings by
//            default: the thesis's 30 x 35 s cost 0.2 s per U-hat). The model is --model (model.json of
//            `pegasus heli identify`) or, by default, identified as experiments/heli-demo.toml does (a 200 s
//            pilot flight of seed 1, 100 cross-validation points, bandwidth scales 1, 2, 4, no coordinate
//            passes).
//   bicycle  `bicycle train` (thesis §4.6): train_bicycle with its defaults (m = 30, H = 500, potential
//            shaping, the balancing start).
// Methods: "gradient" and "hill-climb" with the options the problem's trainer uses by default
// (HoverTrainingOptions / BicycleTrainingOptions::default_optimizer), "cmaes" with CmaesOptions' defaults;
// each may use up to the largest budget (max_iterations unbounded), so a method stopping early (its own
// convergence test) keeps its last value. Seed s (1..seeds) is the run's --seed as a command would take it:
// the scenario set and every optimizer stream derive from it, so each seed is another sample of the
// problem and all three methods of one seed maximise the same U-hat.
//
// Prints a Markdown table (mean over the seeds of U-hat at each budget, best seed in brackets) and writes
// every run's history to --out.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/random/seed.hpp"
#include "pegasus/sysid/identify.hpp"

namespace {

using namespace pegasus;
using Clock = std::chrono::steady_clock;

struct Args {
  std::vector<std::string> problems{"hover", "bicycle"};
  int seeds = 3;
  std::vector<std::int64_t> budgets{100, 300, 1000, 3000};
  int threads = 2;
  int hover_scenarios = 5;
  double hover_seconds = 10;
  int bicycle_scenarios = 30;
  int bicycle_horizon = 500;
  std::string model;
  std::string out;
};

template <typename T, typename Parse>
std::vector<T> split(const std::string& text, Parse parse) {
  std::vector<T> out;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) out.push_back(parse(item));
  return out;
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(k + ": expected a value");
      return argv[++i];
    };
    if (k == "--problems")
      a.problems = split<std::string>(value(), [](const std::string& s) { return s; });
    else if (k == "--seeds")
      a.seeds = std::stoi(value());
    else if (k == "--budgets")
      a.budgets = split<std::int64_t>(value(), [](const std::string& s) { return std::stoll(s); });
    else if (k == "--threads")
      a.threads = std::stoi(value());
    else if (k == "--hover-scenarios")
      a.hover_scenarios = std::stoi(value());
    else if (k == "--hover-seconds")
      a.hover_seconds = std::stod(value());
    else if (k == "--bicycle-scenarios")
      a.bicycle_scenarios = std::stoi(value());
    else if (k == "--bicycle-horizon")
      a.bicycle_horizon = std::stoi(value());
    else if (k == "--model")
      a.model = value();
    else if (k == "--out")
      a.out = value();
    else
      throw std::runtime_error("unknown option " + k + " (see the comment at the top of the source)");
  }
  for (const auto& p : a.problems)
    if (p != "hover" && p != "bicycle") throw std::runtime_error("--problems: expected hover and/or bicycle");
  if (a.seeds < 1 || a.threads < 1 || a.budgets.empty())
    throw std::runtime_error("--seeds, --threads: expected >= 1; --budgets: expected a list");
  std::sort(a.budgets.begin(), a.budgets.end());
  if (a.budgets.front() < 1) throw std::runtime_error("--budgets: expected numbers >= 1");
  return a;
}

constexpr std::array<const char*, 3> kMethods = {"gradient", "hill-climb", "cmaes"};

// The options of `method` for a problem whose trainer uses `defaults`, allowed `budget` evaluations.
OptimizerOptions method_options(OptimizerOptions defaults, const std::string& method, std::int64_t budget,
                                std::uint64_t seed) {
  defaults.method = method;
  defaults.gradient.max_iterations = defaults.hill_climbing.max_iterations = defaults.cmaes.max_iterations =
      budget;
  defaults.gradient.max_evaluations = defaults.hill_climbing.max_evaluations =
      defaults.cmaes.max_evaluations = budget;
  // The streams as the trainers derive them from the run's seed (hover_task.cpp, bicycle_experiment.cpp).
  DeriveOptimizerSeeds(seed, SeedDomains(), &defaults);
  return defaults;
}

// U-hat of the best policy found within `budget` evaluations: the last history row within it, else the
// start's value.
double uhat_at(const OptimizerSummary& s, std::int64_t budget) {
  double value = s.initial_value;
  for (const auto& r : s.history)
    if (r.evaluations <= budget) value = r.value;
  return value;
}

struct Run {
  std::string problem, method;
  std::uint64_t seed;
  OptimizerSummary summary;
  double seconds;
};

std::shared_ptr<const sysid::IdentifiedModel> hover_model(const Args& a, ThreadPool& pool) {
  if (!a.model.empty())
    return std::make_shared<const sysid::IdentifiedModel>(sysid::IdentifiedModel::load(a.model));
  const heli::Aircraft aircraft;
  const sysid::FlightLog log = heli::fly_pilot(aircraft, heli::PilotOptions{}, 200, 1).log;
  sysid::IdentifyOptions o;  // experiments/heli-demo.toml's identification
  o.cv_points = 100;
  o.scale_grid = {1, 2, 4};
  o.coordinate_passes = 0;
  return std::make_shared<const sysid::IdentifiedModel>(sysid::identify(log, o, pool));
}

std::vector<Run> run_hover(const Args& a, std::shared_ptr<ThreadPool> pool) {
  const auto started = Clock::now();
  const auto model = hover_model(a, *pool);
  std::cerr << fmt::format("hover: model ready in {:.1f} s\n",
                           std::chrono::duration<double>(Clock::now() - started).count());
  std::vector<Run> runs;
  for (int s = 1; s <= a.seeds; ++s) {
    heli::HoverTrainingOptions o;
    o.scenarios = a.hover_scenarios;
    o.seconds = a.hover_seconds;
    o.reward = heli::HoverReward::from_typical(0.5, 0.5, 0.1, 0.1, {});  // `heli hover`'s defaults
    o.seed = static_cast<std::uint64_t>(s);
    auto objective = heli::hover_objective(model, o, pool);
    for (const char* method : kMethods) {
      const OptimizerOptions options =
          method_options(heli::HoverTrainingOptions::default_optimizer(), method, a.budgets.back(), o.seed);
      Theta theta;  // the spec's initial values: the policy from the logs' trim
      Run run{"hover", method, o.seed, {}, 0};
      const auto t = Clock::now();
      Solve(options, *objective, &theta, &run.summary);
      run.seconds = std::chrono::duration<double>(Clock::now() - t).count();
      std::cerr << "hover seed " << s << ": " << run.summary.BriefReport() << "\n";
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

std::vector<Run> run_bicycle(const Args& a, ThreadPool& pool) {
  std::vector<Run> runs;
  for (int s = 1; s <= a.seeds; ++s) {
    BicycleTrainingOptions o;
    o.scenarios = a.bicycle_scenarios;
    o.horizon = a.bicycle_horizon;
    o.seed = static_cast<std::uint64_t>(s);
    for (const char* method : kMethods) {
      o.optimizer =
          method_options(BicycleTrainingOptions::default_optimizer(), method, a.budgets.back(), o.seed);
      Run run{"bicycle", method, o.seed, {}, 0};
      const auto t = Clock::now();
      run.summary = train_bicycle(o, {}, &pool).summary;
      run.seconds = std::chrono::duration<double>(Clock::now() - t).count();
      std::cerr << "bicycle seed " << s << ": " << run.summary.BriefReport() << "\n";
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

std::string table(const Args& a, const std::vector<Run>& runs) {
  std::string out = "| problem | method |";
  std::string rule = "|---|---|";
  for (const auto b : a.budgets) {
    out += fmt::format(" U-hat at {} |", b);
    rule += "---:|";
  }
  out += " evaluations used | seconds per run |\n" + rule + "---:|---:|\n";
  for (const auto& problem : a.problems) {
    for (const char* method : kMethods) {
      std::vector<const Run*> mine;
      for (const auto& r : runs)
        if (r.problem == problem && r.method == method) mine.push_back(&r);
      if (mine.empty()) continue;
      out += fmt::format("| {} | {} |", problem, method);
      for (const auto b : a.budgets) {
        double sum = 0, best = -std::numeric_limits<double>::infinity();
        for (const Run* r : mine) {
          sum += uhat_at(r->summary, b);
          best = std::max(best, uhat_at(r->summary, b));
        }
        out += fmt::format(" {:.5g} ({:.5g}) |", sum / static_cast<double>(mine.size()), best);
      }
      double evaluations = 0, seconds = 0;
      for (const Run* r : mine) {
        evaluations += static_cast<double>(r->summary.evaluations);
        seconds += r->seconds;
      }
      out += fmt::format(" {:.0f} | {:.1f} |\n", evaluations / static_cast<double>(mine.size()),
                         seconds / static_cast<double>(mine.size()));
    }
  }
  return out;
}

nlohmann::json to_json(const Args& a, const std::vector<Run>& runs) {
  nlohmann::json j = {{"budgets", a.budgets},
                      {"seeds", a.seeds},
                      {"threads", a.threads},
                      {"hover", {{"scenarios", a.hover_scenarios}, {"seconds", a.hover_seconds}}},
                      {"bicycle", {{"scenarios", a.bicycle_scenarios}, {"horizon", a.bicycle_horizon}}},
                      {"runs", nlohmann::json::array()}};
  for (const auto& r : runs) {
    nlohmann::json at = nlohmann::json::object();
    for (const auto b : a.budgets) at[std::to_string(b)] = uhat_at(r.summary, b);
    j["runs"].push_back({{"problem", r.problem},
                         {"method", r.method},
                         {"seed", r.seed},
                         {"uhat_at", at},
                         {"seconds", r.seconds},
                         {"summary", SummaryToJson(r.summary)}});
  }
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const Args a = parse(argc, argv);
    auto pool = std::make_shared<ThreadPool>(a.threads);
    std::vector<Run> runs;
    for (const auto& problem : a.problems) {
      auto more = problem == "hover" ? run_hover(a, pool) : run_bicycle(a, *pool);
      runs.insert(runs.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
    }
    std::cout << table(a, runs);
    if (!a.out.empty()) write_file_atomic(a.out, to_json(a, runs).dump(1) + "\n");
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "pegasus_optimizer_comparison: " << e.what() << "\n";
    return 2;
  }
}
