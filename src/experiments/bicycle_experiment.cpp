#include "pegasus/experiments/bicycle_experiment.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>

#include "../core/validation.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/envs/bicycle_lockstep.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/parallel/mpi.hpp"
#include "pegasus/policies/policy_json.hpp"
#include "pegasus/random/seed.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {
namespace {

using K = BicycleConstants;

using detail::fail;

ScenarioSet training_scenarios(const BicycleTrainingOptions& o) {
  return ScenarioSet({.seed = o.seed,
                      .count = o.scenarios,
                      .horizon = o.horizon,
                      .noise_dim = 1,
                      .initial_noise_dim = 5,
                      .variant = o.variant});
}

// Calls make(model) with the training model the options describe (Bicycle, shaped or with the bonus).
template <class Make>
std::unique_ptr<Objective> with_training_model(const BicycleTrainingOptions& o, Make&& make) {
  const Bicycle bike(o.bicycle);
  if (o.shaping == "potential")
    return make(shape(bike, BicycleProgressPotential{bike, o.shaping_per_metre}, o.gamma));
  if (o.shaping == "progress-bonus")
    return make(ProgressBonusModel<Bicycle, BicycleGoalDistance>(bike, BicycleGoalDistance{bike},
                                                                 o.shaping_per_metre * K::v * K::dt));
  return make(bike);
}

// PEGASUS's U-hat with the rollouts stepped four at a time (envs/bicycle_lockstep.hpp): the same (theta,
// scenario) pairs, owned by the same threads and MPI ranks as PegasusEvaluator's (pair k on rank k mod N),
// each return bit-identical to scenario_return's, summed in scenario order; so U-hat is PegasusObjective's,
// bit for bit, about 1.2x faster.
template <class Model>
class LockstepPegasusObjective final : public Objective {
 public:
  static constexpr int kLanes = 4;
  LockstepPegasusObjective(PegasusEvaluator<Model, BicyclePolicy> evaluator, std::shared_ptr<ThreadPool> pool,
                           mpi::Communicator ranks)
      : evaluator_(std::move(evaluator)), pool_(std::move(pool)), ranks_(ranks) {}
  const ParameterSpec& parameters() const override { return evaluator_.policy().parameters(); }
  double evaluate(std::span<const double> theta) override {
    const Theta one(theta.begin(), theta.end());
    double value = 0.0;
    evaluate_batch(std::span<const Theta>(&one, 1), std::span<double>(&value, 1));
    return value;
  }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    const auto m = static_cast<std::size_t>(evaluator_.scenarios().size());
    std::vector<double> returns(thetas.size() * m);
    const mpi::Share share = mpi::collective_share(ranks_);
    const std::size_t owned = share.count(returns.size());
    auto group = [&](std::size_t g) {
      std::array<std::span<const double>, kLanes> lane_theta;
      std::array<int, kLanes> lane_scenario{};
      std::array<double, kLanes> lane_return{};
      const std::size_t first = g * kLanes, lanes = std::min<std::size_t>(kLanes, owned - first);
      for (std::size_t j = 0; j < lanes; ++j) {
        const std::size_t k = share.item(first + j);
        lane_theta[j] = thetas[k / m];
        lane_scenario[j] = static_cast<int>(k % m);
      }
      lockstep_returns<kLanes>(evaluator_.model(), evaluator_.policy(), std::span(lane_theta).first(lanes),
                               std::span<const int>(lane_scenario).first(lanes), evaluator_.scenarios(),
                               evaluator_.discounting(), std::span(lane_return).first(lanes));
      for (std::size_t j = 0; j < lanes; ++j) returns[share.item(first + j)] = lane_return[j];
    };
    const std::size_t groups = (owned + kLanes - 1) / kLanes;
    if (pool_) {
      pool_->parallel_for(groups, group);
    } else {
      for (std::size_t g = 0; g < groups; ++g) group(g);
    }
    mpi::allgather_shares(returns, share);
    for (std::size_t k = 0; k < thetas.size(); ++k)
      values[k] = ordered_mean(std::span<const double>(returns.data() + k * m, m));
  }

 private:
  PegasusEvaluator<Model, BicyclePolicy> evaluator_;
  std::shared_ptr<ThreadPool> pool_;
  mpi::Communicator ranks_;
};

std::unique_ptr<Objective> training_objective(const BicycleTrainingOptions& o,
                                              std::shared_ptr<ThreadPool> pool, mpi::Communicator ranks) {
  const Discounting d{.gamma = o.gamma, .horizon = o.horizon};
  return with_training_model(o, [&](auto model) -> std::unique_ptr<Objective> {
    using Model = decltype(model);
    if (o.estimator == "montecarlo") {
      return std::make_unique<MonteCarloObjective<Model, BicyclePolicy>>(
          MonteCarloEvaluator<Model, BicyclePolicy>(model, make_bicycle_policy(), o.scenarios, d, o.seed),
          pool, ranks);
    }
    return std::make_unique<LockstepPegasusObjective<Model>>(
        PegasusEvaluator<Model, BicyclePolicy>(model, make_bicycle_policy(), training_scenarios(o), d), pool,
        ranks);
  });
}

std::uint64_t derived_seed(std::uint64_t seed, std::uint64_t role, int trial) {
  return mix_seed(mix_seed(seed, role), static_cast<std::uint64_t>(trial));
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

// ---- Training -----------------------------------------------------------------------------------------

BicycleOptions BicycleTrainingOptions::default_bicycle() {
  BicycleOptions b;
  b.goal = BicycleGoal::infinitely_far(0.0);
  return b;
}

OptimizerOptions BicycleTrainingOptions::default_optimizer() {
  OptimizerOptions o;
  o.method = "gradient";
  o.gradient.max_iterations = 200;
  o.gradient.relative_step = 0.05;
  o.gradient.initial_step = 0.2;
  o.gradient.max_step = 0.5;
  o.gradient.min_step = 1e-3;
  o.gradient.function_tolerance = 0.0;
  o.hill_climbing.max_iterations = 200;
  o.hill_climbing.proposals_per_iteration = 16;
  o.hill_climbing.initial_step = 0.3;
  o.hill_climbing.max_step = 1.0;
  o.hill_climbing.min_step = 1e-4;
  return o;
}

bool BicycleTrainingOptions::IsValid(std::string* error) const {
  if (scenarios < 1)
    return fail(error, fmt::format("scenarios: expected an integer >= 1, got {}", scenarios));
  if (!(gamma > 0.0 && gamma <= 1.0))
    return fail(error, fmt::format("gamma: expected a number in (0, 1], got {}", gamma));
  if (horizon < 1) return fail(error, fmt::format("horizon: expected an integer >= 1, got {}", horizon));
  if (shaping != "potential" && shaping != "progress-bonus" && shaping != "none")
    return fail(error,
                fmt::format("shaping: expected one of potential, progress-bonus, none; got \"{}\"", shaping));
  if (!detail::reward_weight(shaping_per_metre))
    return fail(error, fmt::format("shaping_per_metre: expected a number in [0, {}], got {}",
                                   kMaxRewardWeight, shaping_per_metre));
  if (estimator != "pegasus" && estimator != "montecarlo")
    return fail(error, fmt::format("estimator: expected pegasus or montecarlo, got \"{}\"", estimator));
  if (initial_policy != "balance" && initial_policy != "zero")
    return fail(error, fmt::format("initial_policy: expected balance or zero, got \"{}\"", initial_policy));
  if (threads < 1) return fail(error, fmt::format("threads: expected an integer >= 1, got {}", threads));
  std::string inner;
  if (!bicycle.IsValid(&inner)) return fail(error, "bicycle." + inner);
  if (!optimizer.IsValid(&inner)) return fail(error, "optimizer." + inner);
  return true;
}

BicycleTrainingResult train_bicycle(const BicycleTrainingOptions& options, const BicycleTrainingHooks& hooks,
                                    const ExecutionContext& where) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("bicycle training: " + error);
  auto objective = training_objective(options, borrow_pool(where.pool, options.threads), where.ranks);
  TrainingPlan plan;
  plan.seed = options.seed;
  plan.stages = {{.name = options.optimizer.method, .optimizer = options.optimizer}};
  plan.callbacks = hooks.callbacks;
  if (hooks.on_checkpoint && hooks.checkpoint_every > 0) {
    plan.checkpoint_every = hooks.checkpoint_every;
    plan.on_checkpoint = hooks.on_checkpoint;
    // A Monte Carlo objective draws new numbers at every call, so only PEGASUS training resumes exactly.
    if (options.estimator == "pegasus") plan.resume_from = hooks.resume_from;
  }
  BicycleTrainingResult result;
  result.theta = options.initial_policy == "balance" ? bicycle_balancing_theta()
                                                     : Theta(2 * BicycleFeatures::kCount, 0.0);
  TrainingSummary summary;
  Train(plan, *objective, &result.theta, &summary);
  result.summary = std::move(summary.stages.front());
  return result;
}

double bicycle_uhat(const BicycleTrainingOptions& options, const Theta& theta,
                    const ExecutionContext& where) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("bicycle training: " + error);
  auto objective = training_objective(options, borrow_pool(where.pool, options.threads), where.ranks);
  return objective->evaluate(theta);
}

// ---- Rides --------------------------------------------------------------------------------------------

bool BicycleRideOptions::IsValid(std::string* error) const {
  if (rides < 1) return fail(error, fmt::format("rides: expected an integer >= 1, got {}", rides));
  if (!(max_km > 0.0 && max_km <= 1000.0))
    return fail(error, fmt::format("max_km: expected a number in (0, 1000], got {}", max_km));
  if (path_every < 0)
    return fail(error, fmt::format("path_every: expected an integer >= 0, got {}", path_every));
  std::string inner;
  if (!bicycle.IsValid(&inner)) return fail(error, "bicycle." + inner);
  return true;
}

std::vector<BicycleRide> ride_bicycle(const Theta& theta, const BicycleRideOptions& options,
                                      ThreadPool* pool) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("bicycle rides: " + error);
  const Bicycle bike(options.bicycle);
  const BicyclePolicy policy = make_bicycle_policy();
  if (theta.size() != policy.parameters().size())
    throw InputError(fmt::format("bicycle rides: expected {} policy parameters, got {}",
                                 policy.parameters().size(), theta.size()));
  constexpr double step_km = K::v * K::dt / 1000.0;
  const int max_steps = static_cast<int>(std::ceil(options.max_km / step_km));
  const ScenarioSet noise({.seed = options.seed,
                           .count = options.rides,
                           .horizon = max_steps,
                           .noise_dim = 1,
                           .initial_noise_dim = 5});

  std::vector<BicycleRide> rides(static_cast<std::size_t>(options.rides));
  auto ride = [&](std::size_t i) {
    BicycleRide& r = rides[i];
    std::array<double, 5> p0;
    noise.initial_noise(static_cast<int>(i), p0);
    BicycleState s = bike.initial_state(p0);
    if (options.path_every > 0) {
      r.x.push_back(s.xf);
      r.y.push_back(s.yf);
    }
    int t = 0;
    double p = 0.0;
    for (; t < max_steps && !bike.terminal(s); ++t) {
      const auto a = policy.act(theta, bike.observe(s));
      noise.step_noise(static_cast<int>(i), t, std::span<double>(&p, 1));
      const BicycleState next = bike.step(s, a, std::span<const double>(&p, 1));
      if (next.status == BicycleState::kAtGoal) {
        r.distance_km = (t + bike.event_fraction(s, a, next)) * step_km;
        r.reached = true;
      }
      s = next;
      if (options.path_every > 0 && ((t + 1) % options.path_every == 0 || bike.terminal(s))) {
        r.x.push_back(s.xf);
        r.y.push_back(s.yf);
      }
    }
    r.fell = s.status == BicycleState::kFallen;
    if (!r.reached) r.distance_km = t * step_km;
  };
  auto owned = borrow_pool(pool, 1);
  owned->parallel_for(rides.size(), ride, 1);
  return rides;
}

BicycleRideSummary summarize_rides(const std::vector<BicycleRide>& rides) {
  BicycleRideSummary s;
  s.rides = static_cast<int>(rides.size());
  std::vector<double> reached;
  for (const auto& r : rides) {
    if (r.reached) reached.push_back(r.distance_km);
    s.falls += r.fell ? 1 : 0;
  }
  s.reached = static_cast<int>(reached.size());
  s.median_distance_km = median(reached);
  s.worst_distance_km = reached.empty() ? std::numeric_limits<double>::quiet_NaN()
                                        : *std::max_element(reached.begin(), reached.end());
  return s;
}

// ---- The experiment -----------------------------------------------------------------------------------

std::uint64_t bicycle_training_seed(std::uint64_t seed, int trial) { return derived_seed(seed, 1, trial); }
std::uint64_t bicycle_ride_seed(std::uint64_t seed, int trial) { return derived_seed(seed, 2, trial); }

bool BicycleExperimentOptions::IsValid(std::string* error) const {
  if (trials < 1) return fail(error, fmt::format("trials: expected an integer >= 1, got {}", trials));
  if (lesson_trials < 0 || lesson_trials > trials)
    return fail(error,
                fmt::format("lesson_trials: expected an integer in [0, trials], got {}", lesson_trials));
  if (threads < 1) return fail(error, fmt::format("threads: expected an integer >= 1, got {}", threads));
  std::string inner;
  if (!training.IsValid(&inner)) return fail(error, inner);
  if (!riding.IsValid(&inner)) return fail(error, inner);
  return true;
}

nlohmann::json to_json(const BicycleTrial& t) {
  nlohmann::json rides = nlohmann::json::array();
  for (const auto& r : t.rides) rides.push_back({r.distance_km, r.reached, r.fell});
  return {{"method", t.method},
          {"trial", t.trial},
          {"theta", VectorToJson(t.theta)},
          {"initial_uhat", DoubleToJson(t.initial_uhat)},
          {"final_uhat", DoubleToJson(t.final_uhat)},
          {"pegasus_uhat", DoubleToJson(t.pegasus_uhat)},
          {"iterations", t.iterations},
          {"evaluations", t.evaluations},
          {"curve", VectorToJson(t.curve)},
          {"rides", rides}};
}

BicycleTrial bicycle_trial_from_json(const nlohmann::json& j) {
  BicycleTrial t;
  t.method = j.at("method").get<std::string>();
  t.trial = j.at("trial").get<int>();
  t.theta = VectorFromJson(j.at("theta"), "theta");
  t.initial_uhat = DoubleFromJson(j.at("initial_uhat"), "initial_uhat");
  t.final_uhat = DoubleFromJson(j.at("final_uhat"), "final_uhat");
  t.pegasus_uhat = DoubleFromJson(j.at("pegasus_uhat"), "pegasus_uhat");
  t.iterations = j.at("iterations").get<std::int64_t>();
  t.evaluations = j.at("evaluations").get<std::int64_t>();
  t.curve = VectorFromJson(j.at("curve"), "curve");
  for (const auto& r : j.at("rides"))
    t.rides.push_back(
        {.distance_km = r.at(0).get<double>(), .reached = r.at(1).get<bool>(), .fell = r.at(2).get<bool>()});
  t.summary = summarize_rides(t.rides);
  return t;
}

BicycleExperimentResult run_bicycle_experiment(const BicycleExperimentOptions& options,
                                               const BicycleExperimentHooks& hooks) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError(error);
  ThreadPool pool(options.threads);

  // The jobs in order: the PEGASUS trials, then each lesson on the first lesson_trials scenario sets.
  struct Job {
    std::string method;
    int trial;
  };
  std::vector<Job> jobs;
  for (int k = 0; k < options.trials; ++k) jobs.push_back({"pegasus", k});
  for (int k = 0; k < options.lesson_trials; ++k) jobs.push_back({"progress-bonus", k});
  for (int k = 0; k < options.lesson_trials; ++k) jobs.push_back({"montecarlo", k});

  BicycleExperimentResult result;
  std::optional<nlohmann::json> resume_optimizer;
  if (hooks.resume_from) {
    for (const auto& t : hooks.resume_from->at("trials")) result.trials.push_back(bicycle_trial_from_json(t));
    if (hooks.resume_from->contains("optimizer")) resume_optimizer = hooks.resume_from->at("optimizer");
  }
  auto checkpoint = [&](const std::optional<nlohmann::json>& optimizer) {
    if (!hooks.on_checkpoint) return;
    nlohmann::json state = {{"trials", nlohmann::json::array()}};
    for (const auto& t : result.trials) state["trials"].push_back(to_json(t));
    if (optimizer) state["optimizer"] = *optimizer;
    hooks.on_checkpoint(state);
  };

  for (std::size_t index = result.trials.size(); index < jobs.size(); ++index) {
    const Job& job = jobs[index];
    BicycleTrainingOptions training = options.training;
    training.seed = bicycle_training_seed(options.seed, job.trial);
    if (job.method == "progress-bonus") training.shaping = "progress-bonus";
    if (job.method == "montecarlo") training.estimator = "montecarlo";

    BicycleTrainingHooks training_hooks;
    training_hooks.checkpoint_every = hooks.checkpoint_every;
    if (hooks.on_checkpoint) training_hooks.on_checkpoint = [&](const nlohmann::json& c) { checkpoint(c); };
    training_hooks.resume_from = resume_optimizer;
    resume_optimizer.reset();
    const BicycleTrainingResult trained = train_bicycle(training, training_hooks, &pool);

    BicycleTrial trial;
    trial.method = job.method;
    trial.trial = job.trial;
    trial.theta = trained.theta;
    trial.initial_uhat = trained.summary.initial_value;
    trial.final_uhat = trained.summary.best_value;
    trial.iterations = trained.summary.iterations;
    trial.evaluations = trained.summary.evaluations;
    for (const auto& h : trained.summary.history) trial.curve.push_back(h.value);
    BicycleTrainingOptions yardstick = options.training;
    yardstick.seed = training.seed;
    trial.pegasus_uhat =
        job.method == "pegasus" ? trial.final_uhat : bicycle_uhat(yardstick, trial.theta, &pool);

    BicycleRideOptions riding = options.riding;
    riding.seed = bicycle_ride_seed(options.seed, job.trial);
    riding.path_every = 0;
    trial.rides = ride_bicycle(trial.theta, riding, &pool);
    trial.summary = summarize_rides(trial.rides);
    result.trials.push_back(std::move(trial));
    checkpoint(std::nullopt);
    if (hooks.on_trial) hooks.on_trial(result.trials.back());
  }

  std::vector<double> medians;
  for (const auto& t : result.trials)
    if (t.method == "pegasus") medians.push_back(t.summary.median_distance_km);
  result.median_of_medians_km = median(medians);
  return result;
}

// ---- Policy files -------------------------------------------------------------------------------------

nlohmann::json bicycle_policy_json(const Theta& theta) {
  const BicyclePolicy policy = make_bicycle_policy();
  nlohmann::json parameters = nlohmann::json::object();
  for (std::size_t k = 0; k < policy.parameters().size(); ++k)
    parameters[policy.parameters()[k].name] = theta.at(k);
  return parameter_policy_json("bicycle-sigmoid-15", std::move(parameters));
}

Theta bicycle_policy_from_json(const nlohmann::json& j, const std::string& source) {
  const BicyclePolicy policy = make_bicycle_policy();
  const auto& parameters =
      policy_parameters_json(j, source, "bicycle-sigmoid-15", policy.parameters(), "the bicycle policy");
  return named_parameters(parameters, source, policy.parameters(), policy.parameters().size());
}

Theta read_bicycle_policy(const std::filesystem::path& file) {
  return bicycle_policy_from_json(read_json_input(file, "bicycle policy"), file.string());
}

}  // namespace pegasus
