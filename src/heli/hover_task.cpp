#include "pegasus/heli/hover_task.hpp"

#include <fmt/format.h>

#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/heli/frames.hpp"
#include "pegasus/optimizers/training.hpp"

namespace pegasus::heli {
namespace {

bool fail(std::string* error, std::string message) {
  if (error) *error = std::move(message);
  return false;
}

bool positive_finite(double x) { return x > 0 && std::isfinite(x); }
bool nonnegative_finite(double x) { return x >= 0 && std::isfinite(x); }

using Task = HoverTask<sysid::LearnedHeliModel>;

sysid::LearnedModelOptions learned_options(const HoverTrainingOptions& o,
                                           const sysid::IdentifiedModel& model) {
  sysid::LearnedModelOptions m;
  m.dt = 1 / o.control_rate_hz;
  m.refit_every = o.refit_steps(model);
  m.start = {o.target.x, o.target.y, o.target.z, 0, 0, o.target.yaw, 0, 0, 0, 0, 0, 0};
  m.start_pos_sigma = o.start_pos_sigma;
  m.start_vel_sigma = o.start_vel_sigma;
  return m;
}

}  // namespace

// ---- Reward -------------------------------------------------------------------------------------------

HoverReward HoverReward::from_typical(double position_m, double velocity_mps, double yaw_rad, double action,
                                      Controls centre) {
  HoverReward r;
  r.alpha_pos.fill(weight_of_typical(position_m));
  r.alpha_vel.fill(weight_of_typical(velocity_mps));
  r.alpha_yaw = weight_of_typical(yaw_rad);
  r.alpha_action.fill(weight_of_typical(action));
  r.centre = centre;
  return r;
}

bool HoverReward::IsValid(std::string* error) const {
  for (std::size_t i = 0; i < 3; ++i) {
    if (!nonnegative_finite(alpha_pos[i]))
      return fail(error, fmt::format("alpha_pos: expected finite numbers >= 0"));
    if (!nonnegative_finite(alpha_vel[i]))
      return fail(error, fmt::format("alpha_vel: expected finite numbers >= 0"));
  }
  if (!nonnegative_finite(alpha_yaw)) return fail(error, "alpha_yaw: expected a finite number >= 0");
  for (const double a : alpha_attitude)
    if (!nonnegative_finite(a)) return fail(error, "alpha_attitude: expected finite numbers >= 0");
  for (const double a : alpha_rate)
    if (!nonnegative_finite(a)) return fail(error, "alpha_rate: expected finite numbers >= 0");
  for (std::size_t c = 0; c < 4; ++c) {
    if (!nonnegative_finite(alpha_action[c]))
      return fail(error, "alpha_action: expected finite numbers >= 0");
    if (!(std::abs(centre[c]) <= 1)) return fail(error, "centre: expected controls in [-1, 1]");
  }
  return true;
}

double HoverReward::state_cost(const LoggedState& s, const SetPoint& t) const {
  const double ex = s[0] - t.x, ey = s[1] - t.y, ez = s[2] - t.z;
  const double eyaw = wrap_angle(s[5] - t.yaw);  // footnote 12: 2 pi - 0.01 vs 0.01 is 0.02 away
  double cost = alpha_pos[0] * ex * ex + alpha_pos[1] * ey * ey + alpha_pos[2] * ez * ez +
                alpha_vel[0] * s[6] * s[6] + alpha_vel[1] * s[7] * s[7] + alpha_vel[2] * s[8] * s[8] +
                alpha_yaw * eyaw * eyaw;
  // Added only when weighted, so that the thesis's reward is computed exactly as before.
  if (alpha_attitude[0] > 0 || alpha_attitude[1] > 0)
    cost += alpha_attitude[0] * s[3] * s[3] + alpha_attitude[1] * s[4] * s[4];
  if (alpha_rate[0] > 0 || alpha_rate[1] > 0 || alpha_rate[2] > 0)
    cost += alpha_rate[0] * s[9] * s[9] + alpha_rate[1] * s[10] * s[10] + alpha_rate[2] * s[11] * s[11];
  return cost;
}

double HoverReward::action_cost(const Controls& a) const {
  double c = 0;
  for (std::size_t k = 0; k < 4; ++k) c += alpha_action[k] * (a[k] - centre[k]) * (a[k] - centre[k]);
  return c;
}

// ---- Training -----------------------------------------------------------------------------------------

HoverPolicyInit hover_init_from_model(const sysid::IdentifiedModel& model) {
  const auto& x = model.data().x;
  HoverPolicyInit init;
  if (x.rows() == 0) return init;
  const auto mean = x.colwise().mean();
  for (int c = 0; c < 4; ++c)
    init.trim[static_cast<std::size_t>(c)] = std::clamp(mean(sysid::kA1 + c), -1.0, 1.0);
  init.trim_roll = mean(sysid::kRoll);
  init.trim_pitch = mean(sysid::kPitch);
  return init;
}

HoverPolicy hover_policy_for(const sysid::IdentifiedModel& model) {
  return HoverPolicy(hover_init_from_model(model));
}

HoverReward hover_reward_for(const sysid::IdentifiedModel& model, const HoverTrainingOptions& o) {
  HoverReward r = o.reward;
  if (o.centre_at_trim) r.centre = hover_init_from_model(model).trim;
  return r;
}

OptimizerOptions HoverTrainingOptions::default_optimizer() {
  OptimizerOptions o;
  o.method = "gradient";
  o.gradient.max_iterations = 20;
  o.gradient.relative_step = 0.05;
  o.gradient.initial_step = 1.0;
  o.gradient.max_step = 4.0;
  o.gradient.min_step = 1e-3;
  o.gradient.max_backtracks = 8;
  o.gradient.function_tolerance = 0.0;
  o.hill_climbing.max_iterations = 20;
  o.hill_climbing.proposals_per_iteration = 8;
  o.hill_climbing.initial_step = 0.3;
  o.hill_climbing.max_step = 2.0;
  o.hill_climbing.min_step = 1e-3;
  return o;
}

int HoverTrainingOptions::horizon() const {
  // seconds / 0.02 at 50 Hz exactly as before (the same bits as seconds * 50 need not be).
  const double steps = control_rate_hz == 50 ? seconds / 0.02 : seconds * control_rate_hz;
  return std::max(1, static_cast<int>(std::lround(steps)));
}

double HoverTrainingOptions::gamma_per_step() const {
  return control_rate_hz == 50 ? gamma : std::pow(gamma, 50 / control_rate_hz);
}

int HoverTrainingOptions::refit_steps(const sysid::IdentifiedModel& model) const {
  if (refit_every > 0) return refit_every;
  return std::max(1, static_cast<int>(std::lround(model.dt() * control_rate_hz)));
}

bool HoverTrainingOptions::IsValid(std::string* error) const {
  if (scenarios < 1)
    return fail(error, fmt::format("scenarios: expected an integer >= 1, got {}", scenarios));
  if (!(positive_finite(seconds) && seconds <= 3600))
    return fail(error, fmt::format("seconds: expected a number in (0, 3600], got {}", seconds));
  if (!(gamma > 0 && gamma <= 1))
    return fail(error, fmt::format("gamma: expected a number in (0, 1], got {}", gamma));
  if (refit_every < 0)
    return fail(error, fmt::format("refit_every: expected an integer >= 0 (0: at the model's rate), got {}",
                                   refit_every));
  if (!(positive_finite(control_rate_hz) && control_rate_hz <= 1000))
    return fail(error,
                fmt::format("control_rate_hz: expected a number in (0, 1000], got {}", control_rate_hz));
  if (!(max_start_crash_fraction >= 0 && max_start_crash_fraction <= 1))
    return fail(error, fmt::format("max_start_crash_fraction: expected a number in [0, 1], got {}",
                                   max_start_crash_fraction));
  if (!(nonnegative_finite(start_pos_sigma) && nonnegative_finite(start_vel_sigma)))
    return fail(error, "start_pos_sigma, start_vel_sigma: expected finite numbers >= 0");
  if (!(std::isfinite(target.x) && std::isfinite(target.y) && std::isfinite(target.z) &&
        std::isfinite(target.yaw)))
    return fail(error, "target: expected finite numbers");
  std::string inner;
  if (!reward.IsValid(&inner)) return fail(error, "reward." + inner);
  if (!optimizer.IsValid(&inner)) return fail(error, "optimizer." + inner);
  if (then_hill_climb && optimizer.method == "gradient") {
    OptimizerOptions hc = optimizer;
    hc.method = "hill-climb";
    if (!hc.IsValid(&inner)) return fail(error, "optimizer." + inner);
  }
  return true;
}

namespace {

PegasusEvaluator<Task, HoverPolicy> hover_evaluator(std::shared_ptr<const sysid::IdentifiedModel> model,
                                                    const HoverTrainingOptions& o) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("hover training: " + error);
  const HoverReward reward = hover_reward_for(*model, o);
  const HoverPolicy policy = hover_policy_for(*model);
  Task task(sysid::LearnedHeliModel(model, learned_options(o, *model)), o.target, reward);
  ScenarioSet scenarios({.seed = o.seed,
                         .count = o.scenarios,
                         .horizon = o.horizon(),
                         .noise_dim = task.noise_dim(),
                         .initial_noise_dim = task.initial_noise_dim()});
  const Discounting d{.gamma = o.gamma_per_step(), .horizon = o.horizon()};
  return PegasusEvaluator<Task, HoverPolicy>(std::move(task), policy, std::move(scenarios), d);
}

}  // namespace

std::unique_ptr<Objective> hover_objective(std::shared_ptr<const sysid::IdentifiedModel> model,
                                           const HoverTrainingOptions& o, std::shared_ptr<ThreadPool> pool) {
  return std::make_unique<PegasusObjective<Task, HoverPolicy>>(hover_evaluator(std::move(model), o),
                                                               std::move(pool));
}

namespace {

// The starting weights on the evaluator's scenarios; `step_seconds` is the model's step.
StartingPolicyCheck check_starting_policy(const PegasusEvaluator<Task, HoverPolicy>& evaluator,
                                          double step_seconds, ThreadPool& pool) {
  const Theta theta = evaluator.policy().parameters().initial();
  std::vector<ScenarioOutcome> outcomes(static_cast<std::size_t>(evaluator.scenarios().size()));
  pool.parallel_for(outcomes.size(), [&](std::size_t i) {
    outcomes[i] = scenario_outcome(evaluator.model(), evaluator.policy(), theta, evaluator.scenarios(),
                                   static_cast<int>(i), evaluator.discounting());
  });
  StartingPolicyCheck check;
  check.scenarios = static_cast<int>(outcomes.size());
  std::vector<double> returns;
  double crash_steps = 0;
  for (const auto& outcome : outcomes) {
    returns.push_back(outcome.ret);
    if (!outcome.absorbed) continue;
    ++check.crashed;
    crash_steps += outcome.steps;
  }
  check.uhat = ordered_mean(returns);
  if (check.crashed > 0) check.mean_seconds_to_crash = step_seconds * crash_steps / check.crashed;
  return check;
}

}  // namespace

StartingPolicyCheck check_starting_policy(std::shared_ptr<const sysid::IdentifiedModel> model,
                                          const HoverTrainingOptions& o, ThreadPool& pool) {
  return check_starting_policy(hover_evaluator(model, o), 1 / o.control_rate_hz, pool);
}

HoverTrainingResult train_hover(std::shared_ptr<const sysid::IdentifiedModel> model,
                                const HoverTrainingOptions& o, const HoverTrainingHooks& hooks,
                                ThreadPool& pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("hover training: " + error);
  // One evaluator: the check flies the starting weights on the scenarios training then uses.
  PegasusEvaluator<Task, HoverPolicy> evaluator = hover_evaluator(model, o);
  const StartingPolicyCheck start = check_starting_policy(evaluator, 1 / o.control_rate_hz, pool);
  if (start.crashed > o.max_start_crash_fraction * start.scenarios)
    throw InputError(fmt::format(
        "hover training: the starting policy crashes the learned model in {} of {} scenarios (after {:.2f} s "
        "on average), more than max_start_crash_fraction = {}: the model does not hold the aircraft from "
        "these starts (try heli identify --local=false, smaller start_pos_sigma and start_vel_sigma, or "
        "max_start_crash_fraction = 1 to train anyway)",
        start.crashed, start.scenarios, start.mean_seconds_to_crash, o.max_start_crash_fraction));
  auto objective = std::make_unique<PegasusObjective<Task, HoverPolicy>>(
      std::move(evaluator), std::shared_ptr<ThreadPool>(std::shared_ptr<ThreadPool>(), &pool));
  // §5.3: gradient ascent, then random-walk hill climbing from its result. Both stages draw hill climbing's
  // stream from the first stage's seed domain, as this task always has.
  TrainingPlan plan;
  plan.seed = o.seed;
  plan.stages.push_back({.name = o.optimizer.method, .optimizer = o.optimizer});
  if (o.optimizer.method == "gradient" && o.then_hill_climb) {
    OptimizerOptions refine = o.optimizer;
    refine.method = "hill-climb";
    plan.stages.push_back({.name = "hill-climb", .optimizer = refine});
  }
  if (hooks.on_checkpoint && hooks.checkpoint_every > 0) {
    plan.checkpoint_every = hooks.checkpoint_every;
    plan.on_checkpoint = hooks.on_checkpoint;
  }
  plan.resume_from = hooks.resume_from;
  plan.callbacks = hooks.callbacks;
  Theta theta;  // the spec's initial values
  TrainingSummary summary;
  Train(plan, *objective, &theta, &summary);

  HoverTrainingResult result;
  result.gradient = summary.stages[0];
  if (summary.stages.size() > 1) result.hill_climb = summary.stages[1];
  result.progress = std::move(summary.history);
  result.theta = summary.best_theta;
  result.initial_uhat = summary.initial_value;
  result.final_uhat = summary.best_value;
  result.start = start;
  return result;
}

}  // namespace pegasus::heli
