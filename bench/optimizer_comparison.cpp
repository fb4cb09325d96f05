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
// The suite of issue 48 (--problems cartpole,integrator,mountaincar): the user-style problems of
// bench/optimizer_suite.py written in C++ (the same equations, scenario seeds and linear policy a = clip(W
// o)), run with every method that takes unbounded continuous parameters (gradient, hill-climb, cmaes, ars,
// bobyqa, sbplx) at its default options. A seed's problem is the Python suite's, so the two paths can be
// compared.
//
// Prints a Markdown table (mean over the seeds of U-hat at each budget, best seed in brackets) and writes
// every run's history to --out.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numbers>
#include <span>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/policies/policies.hpp"
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
    if (p != "hover" && p != "bicycle" && p != "cartpole" && p != "integrator" && p != "mountaincar")
      throw std::runtime_error(
          "--problems: expected some of hover, bicycle, cartpole, integrator, mountaincar");
  if (a.seeds < 1 || a.threads < 1 || a.budgets.empty())
    throw std::runtime_error("--seeds, --threads: expected >= 1; --budgets: expected a list");
  std::sort(a.budgets.begin(), a.budgets.end());
  if (a.budgets.front() < 1) throw std::runtime_error("--budgets: expected numbers >= 1");
  return a;
}

constexpr std::array<const char*, 3> kMethods = {"gradient", "hill-climb", "cmaes"};
// The suite's: every method for unbounded continuous parameters (crs2 and esch need bounds, exhaustive a
// table).
constexpr std::array<const char*, 6> kSuiteMethods = {"gradient", "hill-climb", "cmaes",
                                                      "ars",      "bobyqa",     "sbplx"};

// The suite's problems (bench/optimizer_suite.py has the same in numpy; its docstring says what each is).
struct CartPole {
  using State = std::array<double, 4>;
  using Action = std::array<double, 1>;
  using Observation = State;
  static constexpr double kGravity = 9.8, kCartMass = 1.0, kPoleMass = 0.1, kHalfLength = 0.5, kDt = 0.02;
  int state_dim() const { return 4; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 4; }
  ActionSpace action_space() const { return ActionSpace::box({-10}, {10}); }
  State initial_state(std::span<const double> p0) const {
    return {0.1 * (p0[0] - 0.5), 0.1 * (p0[1] - 0.5), 0.1 * (p0[2] - 0.5), 0.1 * (p0[3] - 0.5)};
  }
  State step(const State& s, const Action& a, std::span<const double> p) const {
    const double force = std::clamp(a[0], -10.0, 10.0) + 4.0 * (p[0] - 0.5);
    const double total = kCartMass + kPoleMass, c = std::cos(s[2]), sn = std::sin(s[2]);
    const double temp = (force + kPoleMass * kHalfLength * s[3] * s[3] * sn) / total;
    const double alpha = (kGravity * sn - c * temp) / (kHalfLength * (4.0 / 3.0 - kPoleMass * c * c / total));
    const double acc = temp - kPoleMass * kHalfLength * alpha * c / total;
    return {s[0] + kDt * s[1], s[1] + kDt * acc, s[2] + kDt * s[3], s[3] + kDt * alpha};
  }
  bool terminal(const State& s) const {
    return std::abs(s[0]) > 2.4 || std::abs(s[2]) > 12.0 * std::numbers::pi / 180.0;
  }
  Observation observe(const State& s) const { return s; }
  double reward(const State& s, const Action&, const State& next) const {
    (void)s;
    return terminal(next) ? 0.0 : 1.0;
  }
};

struct WindyIntegrator {
  using State = std::array<double, 4>;  // x, x', the integral of x, the steady wind (not observed)
  using Action = std::array<double, 1>;
  using Observation = std::array<double, 3>;
  static constexpr double kDt = 0.1;
  int state_dim() const { return 4; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 3; }
  ActionSpace action_space() const { return ActionSpace::box({-5}, {5}); }
  State initial_state(std::span<const double> p0) const {
    return {2.0 * p0[0] - 1.0, p0[1] - 0.5, 0.0, 2.0 * p0[2] - 1.0};
  }
  State step(const State& s, const Action& a, std::span<const double> p) const {
    const double v = s[1] + kDt * (std::clamp(a[0], -5.0, 5.0) + s[3] + (p[0] - 0.5));
    const double x = s[0] + kDt * v;
    return {x, v, s[2] + kDt * x, s[3]};
  }
  bool terminal(const State&) const { return false; }
  Observation observe(const State& s) const { return {s[0], s[1], s[2]}; }
  double reward(const State&, const Action& a, const State& next) const {
    return -next[0] * next[0] - 0.01 * a[0] * a[0];
  }
};

struct NoisyMountainCar {
  using State = std::array<double, 2>;
  using Action = std::array<double, 1>;
  using Observation = State;
  int state_dim() const { return 2; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 1; }
  ActionSpace action_space() const { return ActionSpace::box({-1}, {1}); }
  State initial_state(std::span<const double> p0) const { return {-0.6 + 0.2 * p0[0], 0.0}; }
  State step(const State& s, const Action& a, std::span<const double> p) const {
    const double u = std::clamp(a[0], -1.0, 1.0);
    double v =
        std::clamp(s[1] + 0.0015 * u - 0.0025 * std::cos(3.0 * s[0]) + 0.001 * (p[0] - 0.5), -0.07, 0.07);
    const double x = std::clamp(s[0] + v, -1.2, 0.6);
    if (x <= -1.2 && v < 0) v = 0.0;
    return {x, v};
  }
  bool terminal(const State& s) const { return s[0] >= 0.45; }
  Observation observe(const State& s) const { return {s[0] + 0.5, 100.0 * s[1]}; }
  double reward(const State&, const Action& a, const State& next) const {
    const double u = std::clamp(a[0], -1.0, 1.0);
    return -0.1 * u * u + (terminal(next) ? 100.0 : 0.0);
  }
};

// The observation itself as the linear policy's features (Python's LinearPolicy: a = clip(W o)).
template <std::size_t N>
struct Identity {
  int size() const { return static_cast<int>(N); }
  void operator()(const std::array<double, N>& o, std::span<double> phi) const {
    std::copy(o.begin(), o.end(), phi.begin());
  }
};

// `options` running `method` with at most `budget` evaluations (and as many iterations).
OptimizerOptions with_budget(OptimizerOptions options, const std::string& method, std::int64_t budget) {
  options.method = method;
  options.gradient.max_iterations = options.hill_climbing.max_iterations = options.cmaes.max_iterations =
      options.ars.max_iterations = budget;
  options.gradient.max_evaluations = options.hill_climbing.max_evaluations = options.cmaes.max_evaluations =
      options.ars.max_evaluations = options.nlopt.max_evaluations = budget;
  return options;
}

// The options of `method` for a problem whose trainer uses `defaults`, allowed `budget` evaluations.
OptimizerOptions method_options(OptimizerOptions defaults, const std::string& method, std::int64_t budget,
                                std::uint64_t seed) {
  OptimizerOptions options = with_budget(std::move(defaults), method, budget);
  // The streams as the trainers derive them from the run's seed (hover_task.cpp, bicycle_experiment.cpp).
  DeriveOptimizerSeeds(seed, SeedDomains(), &options);
  return options;
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

// One suite problem: scenarios 20, the horizon and gamma 1 of bench/optimizer_suite.py, every suite method
// from W = 0 at its default options (OptimizerOptions{}'s) within the largest budget.
template <class Model>
std::vector<Run> run_suite_problem(const Args& a, const std::string& name, int horizon,
                                   std::shared_ptr<ThreadPool> pool) {
  const Model model;
  constexpr std::size_t kObservations = std::tuple_size_v<typename Model::Observation>;
  const LinearPolicy<1, Identity<kObservations>> policy(Identity<kObservations>{}, model.action_space());
  std::vector<Run> runs;
  for (int s = 1; s <= a.seeds; ++s) {
    const ScenarioSet scenarios({.seed = static_cast<std::uint64_t>(s),
                                 .count = 20,
                                 .horizon = horizon,
                                 .noise_dim = model.noise_dim(),
                                 .initial_noise_dim = model.initial_noise_dim()});
    PegasusObjective objective(PegasusEvaluator(model, policy, scenarios, {.gamma = 1.0, .horizon = horizon}),
                               pool);
    for (const char* method : kSuiteMethods) {
      const OptimizerOptions options = with_budget(OptimizerOptions{}, method, a.budgets.back());
      Theta theta;
      Run run{name, method, static_cast<std::uint64_t>(s), {}, 0};
      const auto t = Clock::now();
      Solve(options, objective, &theta, &run.summary);
      run.seconds = std::chrono::duration<double>(Clock::now() - t).count();
      std::cerr << name << " seed " << s << ": " << run.summary.BriefReport() << "\n";
      runs.push_back(std::move(run));
    }
  }
  return runs;
}

std::vector<Run> run_problem(const Args& a, const std::string& problem, std::shared_ptr<ThreadPool> pool) {
  if (problem == "hover") return run_hover(a, pool);
  if (problem == "bicycle") return run_bicycle(a, *pool);
  if (problem == "cartpole") return run_suite_problem<CartPole>(a, problem, 500, pool);
  if (problem == "integrator") return run_suite_problem<WindyIntegrator>(a, problem, 200, pool);
  return run_suite_problem<NoisyMountainCar>(a, problem, 400, pool);
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
    for (const char* method : kSuiteMethods) {
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
      auto more = run_problem(a, problem, pool);
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
