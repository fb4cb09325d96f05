#include "pegasus/heli/hover_task.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "../core/validation.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {
namespace {

using detail::fail;
using detail::reward_weight;

using HoverTaskOnModel = HoverTask<sysid::LearnedHeliModel>;

sysid::LearnedModelOptions learned_options(const HoverTrainingOptions& o,
                                           const sysid::IdentifiedModel& model) {
  sysid::LearnedModelOptions m;
  m.dt = 1 / o.control_rate_hz;
  m.refit_every = o.refit_steps(model);
  m.start = {o.target.x, o.target.y, o.target.z, 0, 0, o.target.yaw, 0, 0, 0, 0, 0, 0};
  m.start_pos_sigma = o.start_pos_sigma;
  m.start_vel_sigma = o.start_vel_sigma;
  m.max_tilt_rad = o.max_tilt_rad;
  m.max_position_error_m = o.max_position_error_m;
  m.max_speed_mps = o.max_speed_mps;
  m.max_rate_radps = o.max_rate_radps;
  m.crash_reward = -o.crash_penalty;
  m.disturbance = o.disturbance;
  return m;
}

// HoverReward::VisitFields's sizes and field names, in its order.
struct RewardDescription {
  std::vector<HoverRewardSize> sizes;
  std::vector<std::string> names;
  template <class T>
  void size(const HoverRewardSize& s, T HoverReward::*, const char*) {
    sizes.push_back(s);
    names.emplace_back(s.field);
  }
  template <class T>
  void weight(const char* name, T HoverReward::*, const char*) {
    names.emplace_back(name);
  }
  template <class T>
  void field(const char* name, T HoverReward::*, const char*) {
    names.emplace_back(name);
  }
};

// The first weight VisitFields lists with an element outside [0, kMaxRewardWeight], and that element.
struct WeightCheck {
  const HoverReward& reward;
  const char* bad = nullptr;
  double value = 0;
  void check(const char* name, double w) {
    if (bad || reward_weight(w)) return;
    bad = name;
    value = w;
  }
  template <std::size_t N>
  void check(const char* name, const std::array<double, N>& w) {
    for (const double x : w) check(name, x);
  }
  template <class T>
  void size(const HoverRewardSize& s, T HoverReward::*member, const char*) {
    check(s.field, reward.*member);
  }
  template <class T>
  void weight(const char* name, T HoverReward::*member, const char*) {
    check(name, reward.*member);
  }
  template <class T>
  void field(const char*, T HoverReward::*, const char*) {}
};
const RewardDescription& reward_description() {
  static const RewardDescription d = [] {
    RewardDescription out;
    HoverReward::VisitFields(out);
    return out;
  }();
  return d;
}

// Sets every element of the weight that `key`'s size names.
struct WeightSetter {
  HoverReward& reward;
  std::string_view key;
  double value;
  bool found = false;
  void set(double& w) { w = value; }
  template <std::size_t N>
  void set(std::array<double, N>& w) {
    w.fill(value);
  }
  template <class T>
  void size(const HoverRewardSize& s, T HoverReward::*member, const char*) {
    if (key != s.key) return;
    set(reward.*member);
    found = true;
  }
  template <class T>
  void weight(const char*, T HoverReward::*, const char*) {}
  template <class T>
  void field(const char*, T HoverReward::*, const char*) {}
};

}  // namespace

// ---- Reward -------------------------------------------------------------------------------------------

const std::vector<HoverRewardSize>& HoverReward::sizes() { return reward_description().sizes; }
const std::vector<std::string>& HoverReward::field_names() { return reward_description().names; }

void HoverReward::set_typical(const HoverRewardSize& size, double typical) {
  WeightSetter setter{*this, size.key, weight_of_typical(typical)};
  VisitFields(setter);
  if (!setter.found) throw std::invalid_argument(fmt::format("no hover reward size '{}'", size.key));
}

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
  WeightCheck weights{*this};
  VisitFields(weights);
  if (weights.bad)
    return fail(error, fmt::format("{}: expected numbers in [0, {}], got {}", weights.bad, kMaxRewardWeight,
                                   weights.value));
  for (const double c : centre)
    if (!(std::abs(c) <= 1)) return fail(error, "centre: expected controls in [-1, 1]");
  return true;
}

double HoverReward::state_cost(const LoggedState& s, const SetPoint& t) const {
  const double ex = s[logged::x] - t.x, ey = s[logged::y] - t.y, ez = s[logged::z] - t.z;
  const double eyaw = wrap_angle(s[logged::yaw] - t.yaw);  // footnote 12: 2 pi - 0.01 vs 0.01 is 0.02 away
  double cost = alpha_pos[0] * ex * ex + alpha_pos[1] * ey * ey + alpha_pos[2] * ez * ez +
                alpha_vel[0] * s[logged::xdot] * s[logged::xdot] +
                alpha_vel[1] * s[logged::ydot] * s[logged::ydot] +
                alpha_vel[2] * s[logged::zdot] * s[logged::zdot] + alpha_yaw * eyaw * eyaw;
  // Added only when weighted, so that the thesis's reward is computed exactly as before.
  if (alpha_attitude[0] > 0 || alpha_attitude[1] > 0)
    cost += alpha_attitude[0] * s[logged::roll] * s[logged::roll] +
            alpha_attitude[1] * s[logged::pitch] * s[logged::pitch];
  if (alpha_rate[0] > 0 || alpha_rate[1] > 0 || alpha_rate[2] > 0)
    cost += alpha_rate[0] * s[logged::roll_rate] * s[logged::roll_rate] +
            alpha_rate[1] * s[logged::pitch_rate] * s[logged::pitch_rate] +
            alpha_rate[2] * s[logged::yaw_rate] * s[logged::yaw_rate];
  const auto any = [](const std::array<double, 3>& w) { return w[0] > 0 || w[1] > 0 || w[2] > 0; };
  if (any(alpha_body_rate)) {
    const Vec3 w_B = body_rates_from_euler_rates(attitude_of(s), euler_rates_of(s));
    for (int i = 0; i < 3; ++i) cost += alpha_body_rate[static_cast<std::size_t>(i)] * w_B[i] * w_B[i];
  }
  if (any(alpha_quaternion)) {
    const auto q = quaternion_from_euler({s[logged::roll], s[logged::pitch], eyaw});
    for (std::size_t i = 0; i < 3; ++i) cost += alpha_quaternion[i] * q[i + 1] * q[i + 1];
  }
  return cost;
}

double HoverReward::action_cost(const Controls& a) const {
  double c = 0;
  for (std::size_t k = 0; k < 4; ++k) c += alpha_action[k] * (a[k] - centre[k]) * (a[k] - centre[k]);
  return c;
}

std::string HoverReward::terms(double crash_penalty) const {
  std::string out;
  const auto add = [&](const char* name, std::span<const double> w, const char* unit) {
    if (std::all_of(w.begin(), w.end(), [](double x) { return x == 0; })) return;
    out += fmt::format("{}{} {:.4g} {}", out.empty() ? "" : "; ", name, fmt::join(w, " "), unit);
  };
  add("position x y z", alpha_pos, "/m^2");
  add("velocity x y z", alpha_vel, "/(m/s)^2");
  add("yaw", std::span<const double>(&alpha_yaw, 1), "/rad^2");
  add("roll pitch", alpha_attitude, "/rad^2");
  add("Euler-angle rates", alpha_rate, "/(rad/s)^2");
  add("body rates p q r", alpha_body_rate, "/(rad/s)^2");
  add("attitude quaternion x y z", alpha_quaternion, "");
  add("actions a1..a4", alpha_action, fmt::format("about [{:.4g}]", fmt::join(centre, ", ")).c_str());
  return fmt::format("{}; crash {:.6g} (NED, FRD, rad, per control step)", out.empty() ? "nothing" : out,
                     crash_penalty);
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

HoverPolicyInit hover_command_limits(const sysid::IdentifiedModel& model, double margin) {
  HoverPolicyInit init;
  const auto& x = model.data().x;
  if (!model.is_global() || x.rows() == 0) return init;
  for (std::size_t c = 0; c < 4; ++c) {
    const auto column = x.col(sysid::kA1 + static_cast<int>(c));
    const double lo = column.minCoeff(), hi = column.maxCoeff(), widen = margin * (hi - lo);
    if (!(hi > lo)) continue;
    init.command_lower[c] = std::clamp(lo - widen, -1.0, 1.0);
    init.command_upper[c] = std::clamp(hi + widen, -1.0, 1.0);
  }
  return init;
}

HoverPolicy hover_policy_for(const sysid::IdentifiedModel& model, const HoverTrainingOptions& options) {
  HoverPolicyInit init =
      options.lqr_start ? lqr_hover_init(model, options).init : hover_init_from_model(model);
  if (!options.lqr_start) init.integral_seconds = options.integral_seconds;
  const HoverPolicyInit limits = hover_command_limits(model, options.command_margin);
  init.command_lower = limits.command_lower;
  init.command_upper = limits.command_upper;
  return HoverPolicy(init);
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

std::int64_t HoverTrainingOptions::evaluation_budget(const sysid::IdentifiedModel& model,
                                                     int parameters) const {
  if (!(cpu_budget_s > 0) || model.regression().is_global()) return 0;
  const double refits = std::ceil(static_cast<double>(horizon()) / refit_steps(model)) * scenarios;
  const double per_evaluation = refits * static_cast<double>(model.data().x.rows()) * kRefitSecondsPerRow;
  const auto budget = std::max<std::int64_t>(1, static_cast<std::int64_t>(cpu_budget_s / per_evaluation));
  if (optimizer.method != "gradient") return 0;  // the default method's budget; another's is the user's
  std::int64_t planned = optimizer.gradient.max_iterations * (2 * std::int64_t{parameters} + 2);
  if (then_hill_climb)
    planned += optimizer.hill_climbing.max_iterations * optimizer.hill_climbing.proposals_per_iteration;
  return budget < planned ? budget : 0;
}

ErrorIntegrator HoverTrainingOptions::integrator() const {
  return {.dt = integral_seconds > 0 ? 1 / control_rate_hz : 0.0,
          .limit_position = integral_limit_position,
          .limit_yaw = integral_limit_yaw};
}

int HoverTrainingOptions::refit_steps([[maybe_unused]] const sysid::IdentifiedModel& model) const {
  if (refit_every > 0) return refit_every;
  return sysid::refit_steps_at(control_rate_hz);
}

const std::vector<NumberSetting>& HoverTrainingOptions::settings() {
  static const std::vector<NumberSetting> list = number_settings<HoverTrainingOptions>();
  return list;
}

const NumberSetting& HoverTrainingOptions::setting(std::string_view key) {
  return number_setting<HoverTrainingOptions>(key);
}

bool HoverTrainingOptions::IsValid(std::string* error) const {
  std::string inner;
  if (const std::string out = numbers_out_of_bounds(*this); !out.empty()) return fail(error, out);
  if (!(lqr_action_factor > 0 && lqr_action_factor <= 1e12))
    return fail(error,
                fmt::format("lqr_action_factor: expected a number in (0, 1e12], got {}", lqr_action_factor));
  if (!(max_position_error_m > 0 && max_speed_mps > 0 && max_rate_radps > 0))
    return fail(error, "max_position_error_m, max_speed_mps, max_rate_radps: expected positive numbers");
  if (!(crash_penalty >= 0 && crash_penalty <= kMaxRewardWeight))
    return fail(error, fmt::format("crash_penalty: expected a number in [0, {}], got {}", kMaxRewardWeight,
                                   crash_penalty));
  if (!disturbance.IsValid(&inner)) return fail(error, inner);
  // A scenario shorter than one control step scores the start alone: nothing the policy does counts.
  if (seconds * control_rate_hz < 1)
    return fail(error,
                fmt::format("seconds: expected at least one control step (1 / control_rate_hz = {:g} s), "
                            "got {:g}",
                            1 / control_rate_hz, seconds));
  // The int weights start at gain / integral_seconds: a time below one control step is no integral term a
  // controller can run (1e-320 made them infinite).
  if (integral_seconds != 0 && integral_seconds * control_rate_hz < 1)
    return fail(error, fmt::format("integral_seconds: expected 0 (no integral term) or a number in [{:g}, "
                                   "3600] (at least one control step, 1 / control_rate_hz), got {}",
                                   1 / control_rate_hz, integral_seconds));
  if (!integrator().IsValid(&inner)) return fail(error, "integral_" + inner);
  if (!(std::isfinite(target.x) && std::isfinite(target.y) && std::isfinite(target.z) &&
        std::isfinite(target.yaw)))
    return fail(error, "target: expected finite numbers");
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

PegasusEvaluator<HoverTaskOnModel, HoverPolicy> hover_evaluator(
    const std::shared_ptr<const sysid::IdentifiedModel>& model, const HoverTrainingOptions& o) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("hover training: " + error);
  const HoverReward reward = hover_reward_for(*model, o);
  const HoverPolicy policy = hover_policy_for(*model, o);
  HoverTaskOnModel task(sysid::LearnedHeliModel(model, learned_options(o, *model)), o.target, reward,
                        o.integrator());
  ScenarioSet scenarios({.seed = o.seed,
                         .count = o.scenarios,
                         .horizon = o.horizon(),
                         .noise_dim = task.noise_dim(),
                         .initial_noise_dim = task.initial_noise_dim()});
  const Discounting d{.gamma = o.gamma_per_step(), .horizon = o.horizon()};
  return PegasusEvaluator<HoverTaskOnModel, HoverPolicy>(std::move(task), policy, std::move(scenarios), d);
}

}  // namespace

std::unique_ptr<Objective> hover_objective(const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                           const HoverTrainingOptions& o, std::shared_ptr<ThreadPool> pool) {
  return std::make_unique<PegasusObjective<HoverTaskOnModel, HoverPolicy>>(hover_evaluator(model, o),
                                                                           std::move(pool));
}

namespace {

// The starting weights on the evaluator's scenarios; `step_seconds` is the model's step.
StartingPolicyCheck check_starting_policy(const PegasusEvaluator<HoverTaskOnModel, HoverPolicy>& evaluator,
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

// The LQR starts train_hover tries, in order until one crashes the learned model in no more than
// max_start_crash_fraction of the scenarios (issue 48): the chosen model's gains, then the other model
// class's (when identify recorded one), each with the action weights of the options and then 10, 100 and 1000
// times them. The first that survives is the strongest that does; `settled` gets its options. None taken:
// `settled` keeps the options' start, and the caller refuses or trains from it.
std::vector<StartTry> try_lqr_starts(const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                     const HoverTrainingOptions& o, ThreadPool& pool,
                                     HoverTrainingOptions* settled) {
  std::vector<StartTry> tries;
  std::string other;  // the class not chosen, by its name in model_choice
  if (model->alternative_inv_bandwidth()) other = model->is_global() ? "locally weighted" : "global linear";
  for (double factor = o.lqr_action_factor;
       factor <= HoverTrainingOptions::kMaxLqrActionFactor * o.lqr_action_factor; factor *= 10) {
    for (const bool alternative : {false, true}) {
      if (alternative && other.empty()) continue;
      HoverTrainingOptions t = o;
      t.lqr_action_factor = factor;
      t.lqr_gains_from_alternative = alternative;
      const LqrStart lqr = lqr_hover_init(*model, t);
      StartTry attempt{.gains = alternative ? other : "chosen model",
                       .action_factor = factor / o.lqr_action_factor,
                       .lqr_used = lqr.used,
                       .reason = lqr.reason,
                       .check = {},
                       .taken = false};
      if (lqr.used) {
        attempt.check = check_starting_policy(hover_evaluator(model, t), 1 / o.control_rate_hz, pool);
        attempt.taken = attempt.check.crashed <= o.max_start_crash_fraction * attempt.check.scenarios;
      }
      tries.push_back(attempt);
      if (attempt.taken) {
        *settled = t;
        return tries;
      }
    }
  }
  return tries;
}

}  // namespace

StartingPolicyCheck check_starting_policy(const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                          const HoverTrainingOptions& o, ThreadPool& pool) {
  return check_starting_policy(hover_evaluator(model, o), 1 / o.control_rate_hz, pool);
}

namespace {

// At most `budget` evaluations in all (HoverTrainingOptions::evaluation_budget): hill climbing (the second
// stage) gets up to a quarter, its own plan at most, and gradient ascent the rest.
void limit_evaluations(TrainingPlan& plan, std::int64_t budget) {
  std::int64_t first = budget;
  if (plan.stages.size() > 1) {
    auto& hill = plan.stages[1].optimizer.hill_climbing;
    const std::int64_t share = std::max<std::int64_t>(
        1, std::min<std::int64_t>(budget / 4, hill.max_iterations * hill.proposals_per_iteration));
    hill.max_evaluations = std::min(hill.max_evaluations, share);
    first = std::max<std::int64_t>(1, budget - share);
  }
  auto& gradient = plan.stages[0].optimizer.gradient;
  gradient.max_evaluations = std::min(gradient.max_evaluations, first);
}

}  // namespace

HoverTrainingResult train_hover(const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                const HoverTrainingOptions& o, const HoverTrainingHooks& hooks,
                                ThreadPool& pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("hover training: " + error);
  // One evaluator: the check flies the starting weights on the scenarios training then uses.
  HoverTrainingOptions settled = o;
  std::optional<PegasusEvaluator<HoverTaskOnModel, HoverPolicy>> evaluator;
  StartingPolicyCheck start;
  std::vector<StartTry> tries;
  if (o.lqr_start) {
    tries = try_lqr_starts(model, o, pool, &settled);
    const auto taken = std::find_if(tries.begin(), tries.end(), [](const StartTry& t) { return t.taken; });
    const bool any_gains =
        std::any_of(tries.begin(), tries.end(), [](const StartTry& t) { return t.lqr_used; });
    // The X-Cell's constants are no start for another vehicle (issue 48): its signs and strengths differ.
    if (!any_gains && !model->vehicle().empty())
      throw InputError(fmt::format(
          "hover training: the LQR gave no starting gains on the model of vehicle '{}' ({}), and the "
          "X-Cell's "
          "constant gains are not this aircraft's: check the vehicle file's control signs and the logs' "
          "excitation, or identify with --local=false",
          model->vehicle(), tries.front().reason));
    if (taken != tries.end()) start = taken->check;
    evaluator.emplace(hover_evaluator(model, settled));
    if (taken == tries.end()) start = check_starting_policy(*evaluator, 1 / o.control_rate_hz, pool);
  } else {
    evaluator.emplace(hover_evaluator(model, settled));
    start = check_starting_policy(*evaluator, 1 / o.control_rate_hz, pool);
  }
  if (start.crashed > o.max_start_crash_fraction * start.scenarios)
    throw InputError(fmt::format(
        "hover training: the starting policy crashes the learned model in {} of {} scenarios (after {:.2f} s "
        "on average), more than max_start_crash_fraction = {}: the model does not hold the aircraft from "
        "these starts ({}heli identify --local=false, smaller start_pos_sigma and start_vel_sigma, or "
        "max_start_crash_fraction = 1 to train anyway)",
        start.crashed, start.scenarios, start.mean_seconds_to_crash, o.max_start_crash_fraction,
        o.lqr_start ? fmt::format("every LQR start tried crashed as often, the other model class's gains and "
                                  "action weights up to {}x included; try ",
                                  HoverTrainingOptions::kMaxLqrActionFactor)
                    : "try starting_gains = \"lqr\", "));
  auto objective = std::make_unique<PegasusObjective<HoverTaskOnModel, HoverPolicy>>(std::move(*evaluator),
                                                                                     borrow_pool(&pool, 1));
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
  const std::int64_t budget = o.evaluation_budget(*model, static_cast<int>(objective->parameters().size()));
  if (budget > 0) limit_evaluations(plan, budget);
  if (hooks.on_checkpoint && hooks.checkpoint_every > 0) {
    plan.checkpoint_every = hooks.checkpoint_every;
    plan.on_checkpoint = hooks.on_checkpoint;
  }
  plan.resume_from = hooks.resume_from;
  plan.callbacks = hooks.callbacks;
  Theta theta;  // the spec's initial values
  TrainingSummary summary;
  ObservedObjective observed(*objective, hooks.on_evaluations);
  Train(plan, observed, &theta, &summary);

  HoverTrainingResult result;
  result.gradient = summary.stages[0];
  if (summary.stages.size() > 1) result.hill_climb = summary.stages[1];
  result.progress = std::move(summary.history);
  result.theta = summary.best_theta;
  result.initial_uhat = summary.initial_value;
  result.final_uhat = summary.best_value;
  result.start = start;
  result.lqr_action_factor = settled.lqr_action_factor;
  result.lqr_gains_from_alternative = settled.lqr_gains_from_alternative;
  result.start_tries = std::move(tries);
  return result;
}

}  // namespace pegasus::heli
