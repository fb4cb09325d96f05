#include "pegasus/experiments/pendulum_experiment.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <limits>
#include <memory>
#include <optional>
#include <utility>

#include "../core/validation.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/policies/policy_json.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus {
namespace {

using Clock = std::chrono::steady_clock;

using detail::fail;

using Evaluator = PegasusEvaluator<Pendulum, PendulumSwingUpPolicy>;

Evaluator episodes_evaluator(int episodes, int horizon, std::uint64_t seed, ScenarioVariant variant,
                             bool refinements = true) {
  return Evaluator(Pendulum{}, PendulumSwingUpPolicy(refinements),
                   ScenarioSet({.seed = seed,
                                .count = episodes,
                                .horizon = horizon,
                                .noise_dim = 0,
                                .initial_noise_dim = 2,
                                .variant = variant}),
                   Discounting{.gamma = 1.0, .horizon = horizon});
}

// The clocks and the evaluation count of a whole training: they run on across the stages and across a
// resume (the counts before it come from the checkpoint).
struct BarClock {
  double seconds_before = 0.0, cpu_seconds_before = 0.0;
  std::int64_t evaluations = 0;
  Clock::time_point start = Clock::now();
  std::clock_t cpu_start = std::clock();

  double seconds() const {
    return seconds_before + std::chrono::duration<double>(Clock::now() - start).count();
  }
  double cpu_seconds() const {
    return cpu_seconds_before + static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  }
};

// A stage's training objective seen through a window: each new best U-hat is checked against the bar on the
// evaluation episodes (the theta padded with zeros to the full class), until the bar is reached. Values
// pass through unchanged, so the search is the same with or without the watch. Each stage has its own
// watch (the best U-hat is per stage: the stages' scenario sets differ) on the training's one clock.
class BarWatch final : public Objective {
 public:
  BarWatch(Objective& inner, const Evaluator& evaluation, ThreadPool* pool, double bar, BarClock& clock,
           PendulumTrainingResult& result)
      : inner_(inner), evaluation_(evaluation), pool_(pool), bar_(bar), clock_(clock), result_(result) {}

  const ParameterSpec& parameters() const override { return inner_.parameters(); }
  double evaluate(std::span<const double> theta) override {
    const double v = inner_.evaluate(theta);
    ++clock_.evaluations;
    note(theta, v);
    return v;
  }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    inner_.evaluate_batch(thetas, values);
    clock_.evaluations += static_cast<std::int64_t>(thetas.size());
    std::size_t best = thetas.size();
    for (std::size_t k = 0; k < thetas.size(); ++k)
      if (std::isfinite(values[k]) && (best == thetas.size() || values[k] > values[best])) best = k;
    if (best < thetas.size()) note(thetas[best], values[best]);
  }

 private:
  void note(std::span<const double> theta, double v) {
    if (!(v > best_) || result_.evaluations_to_bar >= 0) return;
    best_ = v;
    const double mean = evaluation_.evaluate(pendulum_full_theta(theta), pool_);
    const double seconds = clock_.seconds();
    result_.checks.push_back({seconds, clock_.evaluations, v, mean});
    if (mean >= bar_) {
      result_.seconds_to_bar = seconds;
      result_.cpu_seconds_to_bar = clock_.cpu_seconds();
      result_.evaluations_to_bar = clock_.evaluations;
    }
  }

  Objective& inner_;
  const Evaluator& evaluation_;
  ThreadPool* pool_;
  double bar_;
  BarClock& clock_;
  PendulumTrainingResult& result_;
  double best_ = -std::numeric_limits<double>::infinity();
};

nlohmann::json checks_json(const std::vector<PendulumBarCheck>& checks) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& c : checks) j.push_back({c.seconds, c.evaluations, c.uhat, c.mean_return});
  return j;
}

// The bar watch's state as the training checkpoint's "caller" entry keeps it ("bar"), and back.
nlohmann::json bar_clock_json(const BarClock& clock, const PendulumTrainingResult& result) {
  const bool reached = result.evaluations_to_bar >= 0;
  return {
      {"seconds", clock.seconds()},
      {"cpu_seconds", clock.cpu_seconds()},
      {"evaluations", clock.evaluations},
      {"checks", checks_json(result.checks)},
      {"seconds_to_bar", reached ? nlohmann::json(result.seconds_to_bar) : nlohmann::json(nullptr)},
      {"cpu_seconds_to_bar", reached ? nlohmann::json(result.cpu_seconds_to_bar) : nlohmann::json(nullptr)},
      {"evaluations_to_bar", result.evaluations_to_bar}};
}

void restore_bar_clock(const nlohmann::json& bar, BarClock& clock, PendulumTrainingResult& result) {
  clock.seconds_before = bar.at("seconds").get<double>();
  clock.cpu_seconds_before = bar.at("cpu_seconds").get<double>();
  clock.evaluations = bar.at("evaluations").get<std::int64_t>();
  for (const auto& c : bar.at("checks"))
    result.checks.push_back(
        {c.at(0).get<double>(), c.at(1).get<std::int64_t>(), c.at(2).get<double>(), c.at(3).get<double>()});
  if (!bar.at("seconds_to_bar").is_null()) {
    result.seconds_to_bar = bar.at("seconds_to_bar").get<double>();
    result.cpu_seconds_to_bar = bar.at("cpu_seconds_to_bar").get<double>();
    result.evaluations_to_bar = bar.at("evaluations_to_bar").get<std::int64_t>();
  }
}

}  // namespace

Theta pendulum_full_theta(std::span<const double> theta) {
  Theta full = PendulumSwingUpPolicy().parameters().initial();
  std::copy_n(theta.begin(), std::min(theta.size(), full.size()), full.begin());
  return full;
}

OptimizerOptions PendulumTrainingOptions::default_optimizer() {
  OptimizerOptions o;
  o.method = "hill-climb";
  o.hill_climbing.max_iterations = 150;
  o.hill_climbing.proposals_per_iteration = 8;
  o.hill_climbing.initial_step = 1.0;
  o.hill_climbing.max_step = 4.0;
  o.hill_climbing.min_step = 1e-3;
  o.gradient.max_iterations = 100;
  o.nlopt.max_evaluations = 1000;
  o.nlopt.initial_step = 1.0;
  return o;
}

OptimizerOptions PendulumTrainingOptions::default_refine_optimizer() {
  OptimizerOptions o = default_optimizer();
  o.hill_climbing.max_iterations = 60;
  o.hill_climbing.initial_step = 0.3;
  o.hill_climbing.max_step = 1.0;
  return o;
}

bool PendulumTrainingOptions::IsValid(std::string* error) const {
  if (scenarios < 1)
    return fail(error, fmt::format("scenarios: expected an integer >= 1, got {}", scenarios));
  if (refine_scenarios < 0)
    return fail(error, fmt::format("refine_scenarios: expected an integer >= 0, got {}", refine_scenarios));
  if (horizon < 1) return fail(error, fmt::format("horizon: expected an integer >= 1, got {}", horizon));
  if (evaluation_episodes < 1)
    return fail(error,
                fmt::format("evaluation_episodes: expected an integer >= 1, got {}", evaluation_episodes));
  if (!std::isfinite(bar)) return fail(error, fmt::format("bar: expected a finite number, got {}", bar));
  if (threads < 1) return fail(error, fmt::format("threads: expected an integer >= 1, got {}", threads));
  std::string inner;
  if (!optimizer.IsValid(&inner)) return fail(error, "optimizer." + inner);
  if (refine_scenarios > 0 && !refine_optimizer.IsValid(&inner))
    return fail(error, "refine_optimizer." + inner);
  return true;
}

std::uint64_t pendulum_evaluation_seed(std::uint64_t seed) { return mix_seed(seed, 0x4576616c); /* "Eval" */ }
std::uint64_t pendulum_large_evaluation_seed(std::uint64_t seed) {
  return mix_seed(seed, 0x4c617267); /* "Larg" */
}

std::vector<double> pendulum_episode_returns(const Theta& theta, int episodes, std::uint64_t seed,
                                             ThreadPool* pool) {
  const Evaluator evaluator =
      episodes_evaluator(episodes, PendulumConstants::episode_steps, seed, ScenarioVariant::kPlain);
  if (theta.size() != evaluator.policy().parameters().size())
    throw InputError(fmt::format("pendulum: expected {} policy parameters, got {}",
                                 evaluator.policy().parameters().size(), theta.size()));
  std::vector<double> returns(static_cast<std::size_t>(episodes));
  evaluator.per_scenario(theta, returns, pool);
  return returns;
}

PendulumTrainingResult train_pendulum(const PendulumTrainingOptions& options,
                                      const PendulumTrainingHooks& hooks, ThreadPool* pool) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("pendulum training: " + error);
  auto shared_pool = borrow_pool(pool, options.threads);
  const Evaluator evaluation =
      episodes_evaluator(options.evaluation_episodes, PendulumConstants::episode_steps,
                         pendulum_evaluation_seed(options.seed), ScenarioVariant::kPlain);
  const bool refine = options.refine_scenarios > 0;

  PendulumTrainingResult result;
  result.seconds_to_bar = std::numeric_limits<double>::quiet_NaN();
  result.cpu_seconds_to_bar = std::numeric_limits<double>::quiet_NaN();
  BarClock clock;
  // The watch's state travels in the training checkpoint's "caller" entry.
  if (hooks.resume_from) restore_bar_clock(hooks.resume_from->at("caller").at("bar"), clock, result);

  // The race searches the five-number class; the refinement frees the lead and the skew, starting from the
  // race's best padded with zeros, on its own, larger scenario set.
  PegasusObjective<Pendulum, PendulumSwingUpPolicy> race(
      episodes_evaluator(options.scenarios, options.horizon, options.seed, options.variant, false),
      shared_pool);
  BarWatch race_watch(race, evaluation, shared_pool.get(), options.bar, clock, result);
  std::optional<PegasusObjective<Pendulum, PendulumSwingUpPolicy>> refinement;
  std::optional<BarWatch> refine_watch;
  TrainingPlan plan;
  plan.seed = options.seed;
  plan.stages.push_back({.name = "race", .optimizer = options.optimizer, .objective = &race_watch});
  if (refine) {
    refinement.emplace(episodes_evaluator(options.refine_scenarios, options.horizon,
                                          mix_seed(options.seed, 0x52656669),  // "Refi"
                                          options.variant),
                       shared_pool);
    refine_watch.emplace(*refinement, evaluation, shared_pool.get(), options.bar, clock, result);
    plan.stages.push_back({.name = "refine",
                           .optimizer = options.refine_optimizer,
                           .seeds = SeedDomains::Refine(),
                           .objective = &*refine_watch,
                           .start_from = [](const Theta& t) { return pendulum_full_theta(t); }});
  }
  if (hooks.on_checkpoint && hooks.checkpoint_every > 0) {
    plan.checkpoint_every = hooks.checkpoint_every;
    plan.on_checkpoint = hooks.on_checkpoint;
    plan.caller_state = [&] { return nlohmann::json{{"bar", bar_clock_json(clock, result)}}; };
  }
  plan.resume_from = hooks.resume_from;
  Theta theta = race.parameters().initial();
  TrainingSummary summary;
  Train(plan, race_watch, &theta, &summary);

  result.summary = summary.stages.front();
  const Theta race_theta = pendulum_full_theta(result.summary.best_theta);
  result.race_mean_return_100 = evaluation.evaluate(race_theta, shared_pool.get());
  result.theta = race_theta;
  if (refine && summary.stages.size() > 1) {
    result.refine_summary = summary.stages[1];
    if (!result.refine_summary.best_theta.empty()) result.theta = result.refine_summary.best_theta;
  }
  result.mean_return_100 =
      refine ? evaluation.evaluate(result.theta, shared_pool.get()) : result.race_mean_return_100;
  return result;
}

nlohmann::json pendulum_policy_json(const Theta& theta) {
  const PendulumSwingUpPolicy policy;
  nlohmann::json parameters = nlohmann::json::object();
  for (std::size_t k = 0; k < theta.size() && k < policy.parameters().size(); ++k)
    parameters[policy.parameters()[k].name] = theta[k];
  return parameter_policy_json("pendulum-swing-up", std::move(parameters));
}

Theta pendulum_policy_from_json(const nlohmann::json& j, const std::string& source) {
  const PendulumSwingUpPolicy policy;
  const auto& parameters =
      policy_parameters_json(j, source, "pendulum-swing-up", policy.parameters(), "the pendulum policy");
  // Five numbers (the class before the lead and the skew) or all seven.
  const std::size_t count = parameters.size() <= PendulumSwingUpPolicy::kBaseCount
                                ? PendulumSwingUpPolicy::kBaseCount
                                : policy.parameters().size();
  return named_parameters(parameters, source, policy.parameters(), count);
}

}  // namespace pegasus
