#include "pegasus/heli/maneuver_task.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "../core/validation.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/random/seed.hpp"
#include "pegasus/scenarios/scenario_set.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus::heli {
namespace {

using detail::fail;
using detail::nonnegative_finite;
using detail::reward_weight;

using Learned = sysid::LearnedHeliModel;
using ManeuverTaskOnModel = ManeuverTask<Learned>;

sysid::LearnedModelOptions learned_options(const ManeuverTrainingOptions& o, const Trajectory& t) {
  sysid::LearnedModelOptions m;
  m.refit_every = o.refit_every;
  const Vec3 p = t.start_W();
  m.start = {p.x(), p.y(), p.z(), 0, 0, wrap_angle(t.start_yaw()), 0, 0, 0, 0, 0, 0};
  m.start_pos_sigma = o.start_pos_sigma;
  m.start_vel_sigma = o.start_vel_sigma;
  m.disturbance = o.disturbance;
  return m;
}

}  // namespace

bool ManeuverReward::IsValid(std::string* error) const {
  const auto weight_error = [&](const std::string& name, double value) {
    return fail(error,
                fmt::format("{}: expected a number in [0, {}], got {}", name, kMaxRewardWeight, value));
  };
  if (!reward_weight(alpha_pos)) return weight_error("alpha_pos", alpha_pos);
  if (!reward_weight(alpha_yaw)) return weight_error("alpha_yaw", alpha_yaw);
  if (!reward_weight(alpha_vel)) return weight_error("alpha_vel", alpha_vel);
  for (std::size_t c = 0; c < 4; ++c) {
    if (!reward_weight(alpha_action[c]))
      return weight_error(fmt::format("alpha_action[{}]", c), alpha_action[c]);
    if (!(std::abs(centre[c]) <= 1))
      return fail(error, fmt::format("centre[{}]: expected a number in [-1, 1], got {}", c, centre[c]));
  }
  return true;
}

double ManeuverReward::state_cost(const LoggedState& s, const PathProjection& p) const {
  const double dx = s[logged::x] - p.p_W.x(), dy = s[logged::y] - p.p_W.y(), dz = s[logged::z] - p.p_W.z();
  const double dyaw = wrap_angle(s[logged::yaw] - p.yaw);
  const double vx = s[logged::xdot] - p.v_W.x(), vy = s[logged::ydot] - p.v_W.y(),
               vz = s[logged::zdot] - p.v_W.z();
  return alpha_pos * (dx * dx + dy * dy + dz * dz) + alpha_yaw * dyaw * dyaw +
         alpha_vel * (vx * vx + vy * vy + vz * vz);
}

double ManeuverReward::action_cost(const Controls& a) const {
  double c = 0;
  for (std::size_t k = 0; k < 4; ++k) c += alpha_action[k] * (a[k] - centre[k]) * (a[k] - centre[k]);
  return c;
}

OptimizerOptions ManeuverTrainingOptions::default_optimizer() {
  OptimizerOptions o;
  o.method = "gradient";
  o.gradient.max_iterations = 10;
  o.gradient.relative_step = 0.05;
  o.gradient.initial_step = 0.5;
  o.gradient.max_step = 2.0;
  o.gradient.min_step = 1e-3;
  o.gradient.max_backtracks = 6;
  o.gradient.function_tolerance = 0.0;
  o.hill_climbing.max_iterations = 10;
  o.hill_climbing.proposals_per_iteration = 8;
  o.hill_climbing.initial_step = 0.3;
  o.hill_climbing.max_step = 2.0;
  o.hill_climbing.min_step = 1e-3;
  return o;
}

bool ManeuverTrainingOptions::IsValid(std::string* error) const {
  if (std::find(kManeuverNames.begin(), kManeuverNames.end(), name) == kManeuverNames.end())
    return fail(error, fmt::format("name: expected {}, got \"{}\"", maneuver_name_list(), name));
  std::string inner;
  if (!size.IsValid(&inner)) return fail(error, inner);
  if (!limits.IsValid(&inner)) return fail(error, inner);
  if (!observer.IsValid(&inner)) return fail(error, "observer." + inner);
  if (const std::string out = numbers_out_of_bounds(*this); !out.empty()) return fail(error, out);
  if (!reward.IsValid(&inner)) return fail(error, "reward." + inner);
  if (!disturbance.IsValid(&inner)) return fail(error, inner);
  if (!optimizer.IsValid(&inner)) return fail(error, "optimizer." + inner);
  return true;
}

std::shared_ptr<const Trajectory> maneuver_trajectory_for(const ManeuverTrainingOptions& o) {
  return std::make_shared<const Trajectory>(maneuver_trajectory(o.name, o.size, o.limits));
}

int maneuver_horizon(const Trajectory& trajectory) {
  return std::max(1, static_cast<int>(std::ceil(trajectory.duration() / 0.02 - 1e-9)));
}

std::unique_ptr<Objective> maneuver_objective(std::shared_ptr<const sysid::IdentifiedModel> model,
                                              const ManeuverTrainingOptions& o, const ManeuverPolicy& policy,
                                              std::shared_ptr<ThreadPool> pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("manoeuvre training: " + error);
  auto observer = std::make_shared<const PathObserver>(policy.trajectory(), o.observer);
  const ManeuverTaskOnModel task(Learned(std::move(model), learned_options(o, policy.trajectory())), observer,
                                 o.reward);
  const int horizon = maneuver_horizon(policy.trajectory());
  const ScenarioSet scenarios({.seed = o.seed,
                               .count = o.scenarios,
                               .horizon = horizon,
                               .noise_dim = task.noise_dim(),
                               .initial_noise_dim = task.initial_noise_dim()});
  const Discounting d{.gamma = o.gamma, .horizon = horizon};
  if (o.shaping) {
    auto shaped = shape(task, PathProgressPotential{o.shaping_per_metre}, o.gamma);
    using Model = decltype(shaped);
    return std::make_unique<PegasusObjective<Model, ManeuverPolicy>>(
        PegasusEvaluator<Model, ManeuverPolicy>(std::move(shaped), policy, scenarios, d), std::move(pool));
  }
  return std::make_unique<PegasusObjective<ManeuverTaskOnModel, ManeuverPolicy>>(
      PegasusEvaluator<ManeuverTaskOnModel, ManeuverPolicy>(task, policy, scenarios, d), std::move(pool));
}

ManeuverTrainingResult train_maneuver(std::shared_ptr<const sysid::IdentifiedModel> model,
                                      const ManeuverTrainingOptions& o, const ManeuverPolicy& policy,
                                      const Theta& start, const ManeuverTrainingHooks& hooks,
                                      ThreadPool& pool) {
  auto objective = maneuver_objective(std::move(model), o, policy, borrow_pool(&pool, 1));
  TrainingPlan plan;
  plan.seed = o.seed;
  plan.stages = {{.name = o.optimizer.method, .optimizer = o.optimizer}};
  if (hooks.on_checkpoint && hooks.checkpoint_every > 0) {
    plan.checkpoint_every = hooks.checkpoint_every;
    plan.on_checkpoint = hooks.on_checkpoint;
    plan.resume_from = hooks.resume_from;
  }
  ManeuverTrainingResult result;
  result.theta = start;
  TrainingSummary summary;
  Train(plan, *objective, &result.theta, &summary);
  result.summary = std::move(summary.stages.front());
  return result;
}

// ---- Flights on the ground truth ------------------------------------------------------------------------

bool ManeuverFlightOptions::IsValid(std::string* error) const {
  if (std::string out = numbers_out_of_bounds(*this); !out.empty()) return fail(error, std::move(out));
  if (!(extra_seconds >= 0 && extra_seconds <= 600))
    return fail(error, fmt::format("extra_seconds: expected a number in [0, 600], got {}", extra_seconds));
  if (!(gust_sigma >= 0 && gust_sigma <= 10))
    return fail(error, fmt::format("gust_sigma: expected a number in [0, 10], got {}", gust_sigma));
  if (!nonnegative_finite(start_vel_sigma))
    return fail(error, fmt::format("start_vel_sigma: expected a number >= 0, got {}", start_vel_sigma));
  return true;
}

namespace {

// Flights along `traj` on the options' ground truth: make_controller(i) gives flight i's controller, called
// as controller(estimate, time) -> controls; target(time) is the set point recorded for each row.
template <class MakeController, class Target>
std::vector<ManeuverFlight> fly_along(const Trajectory& traj, const PathObserver& observer,
                                      const ManeuverFlightOptions& o, ThreadPool* pool,
                                      MakeController&& make_controller, Target&& target) {
  GroundTruthSettings settings;
  settings.gust_sigma = o.gust_sigma;
  settings.set_start = true;
  settings.start_p_W = traj.start_W();
  settings.start_yaw = wrap_angle(traj.start_yaw());
  settings.start_pos_sigma = o.start_pos_sigma;
  settings.start_vel_sigma = o.start_vel_sigma;
  std::unique_ptr<GroundTruth> aircraft;
  try {
    aircraft = make_ground_truth(o.simulator, settings);
  } catch (const std::invalid_argument& e) {
    throw InputError(std::string("manoeuvre flights: ") + e.what());
  }
  const double dt = aircraft->step_seconds();
  const int steps = static_cast<int>(std::ceil((traj.duration() + o.extra_seconds) / dt - 1e-9));
  const ScenarioSet noise({.seed = o.seed,
                           .count = o.flights,
                           .horizon = std::max(1, steps),
                           .noise_dim = aircraft->step_noise_dim(),
                           .initial_noise_dim = aircraft->initial_noise_dim()});
  std::vector<ManeuverFlight> flights(static_cast<std::size_t>(o.flights));
  auto fly = [&](std::size_t i) {
    ManeuverFlight& f = flights[i];
    f.truth.reserve(static_cast<std::size_t>(steps) + 1);
    std::vector<double> p(static_cast<std::size_t>(aircraft->initial_noise_dim()));
    noise.initial_noise(static_cast<int>(i), p);
    const std::unique_ptr<SimulatedFlight> s = aircraft->start_flight(p);
    p.resize(static_cast<std::size_t>(aircraft->step_noise_dim()));
    auto controller = make_controller(i, *aircraft);
    PathProjection path = observer.start();
    auto record = [&](const LoggedState& truth, double t) {
      path = observer.update(path, position_of(truth), truth[logged::yaw]);
      f.truth.push_back(truth);
      f.targets.push_back(target(t));
      f.deviation.push_back((position_of(truth) - path.p_W).norm());
      f.progress.push_back(path.progress);
    };
    record(s->truth(), 0.0);
    for (int t = 0; t < steps; ++t) {
      const double time = t * dt;
      const Controls a = controller(s->observe(), time);
      f.controls.push_back(a);
      noise.step_noise(static_cast<int>(i), t, p);
      s->step(a, p);
      if (s->crash() != CrashReason::kNone) {
        f.crash = s->crash();
        f.crash_time = (t + 1) * dt;
        break;
      }
      record(s->truth(), (t + 1) * dt);
    }
    f.controls.push_back(f.controls.empty() ? Controls{} : f.controls.back());
    f.controls.resize(f.truth.size());
    f.final_progress = path.progress;
  };
  if (pool) {
    pool->parallel_for(flights.size(), fly, 1);
  } else {
    for (std::size_t i = 0; i < flights.size(); ++i) fly(i);
  }
  return flights;
}

}  // namespace

std::vector<ManeuverFlight> fly_maneuver(const ManeuverPolicy& policy, std::span<const double> theta,
                                         const PathObserver& observer, const ManeuverFlightOptions& o,
                                         ThreadPool* pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("manoeuvre flights: " + error);
  if (theta.size() != policy.parameters().size())
    throw InputError(fmt::format("manoeuvre flights: expected {} policy parameters, got {}",
                                 policy.parameters().size(), theta.size()));
  return fly_along(
      policy.trajectory(), observer, o, pool,
      [&](std::size_t, const GroundTruth&) {
        return [&](const LoggedState& estimate, double time) {
          return policy.act(theta, ManeuverObservation{estimate, time});
        };
      },
      [&](double t) { return policy.target(theta, t); });
}

std::vector<ManeuverFlight> fly_pilot_maneuver(const Trajectory& trajectory, const PilotOptions& pilot,
                                               const PathObserver& observer, const ManeuverFlightOptions& o,
                                               ThreadPool* pool) {
  std::string error;
  if (!o.IsValid(&error)) throw InputError("manoeuvre flights: " + error);
  PilotOptions plain = pilot;
  plain.sweeps = false;
  auto set_point = [&](double t) {
    const TrajectoryPoint sp = trajectory.at(t);
    return SetPoint{sp.p_W.x(), sp.p_W.y(), sp.p_W.z(), wrap_angle(sp.yaw)};
  };
  return fly_along(
      trajectory, observer, o, pool,
      [&](std::size_t i, const GroundTruth& aircraft) {
        // The pilot's own noise from stream 2 of the flight's seed, as in fly_pilot_hover.
        auto flyer = std::make_shared<ScriptedPilot>(aircraft, plain, mix_seed(o.seed, i), 2);
        flyer->set_total_seconds(trajectory.duration() + o.extra_seconds);
        return [flyer, &set_point](const LoggedState& estimate, double time) {
          const SetPoint sp = set_point(time);
          flyer->set_hold(sp.x, sp.y, sp.z, sp.yaw);
          return flyer->act(estimate, time);
        };
      },
      set_point);
}

ManeuverFlightSummary summarize_maneuver_flights(const std::vector<ManeuverFlight>& flights,
                                                 double path_length) {
  ManeuverFlightSummary s;
  s.flights = static_cast<int>(flights.size());
  double sum2 = 0;
  std::size_t n = 0;
  for (const auto& f : flights) {
    if (f.crash != CrashReason::kNone)
      ++s.crashes;
    else if (f.final_progress >= path_length - 1.0)
      ++s.completed;
    for (double d : f.deviation) {
      sum2 += d * d;
      s.max_path_deviation_m = std::max(s.max_path_deviation_m, d);
    }
    n += f.deviation.size();
  }
  s.rms_path_deviation_m = n > 0 ? std::sqrt(sum2 / static_cast<double>(n)) : 0.0;
  return s;
}

// ---- Identification data for manoeuvres ------------------------------------------------------------------

PilotFlight fly_pilot_maneuvers(const GroundTruth& aircraft, const PilotOptions& options,
                                double sweep_seconds, const std::vector<Trajectory>& trajectories,
                                std::uint64_t seed) {
  const double dt = aircraft.step_seconds();
  const auto sweep_steps = static_cast<std::size_t>(std::llround(sweep_seconds / dt));
  std::size_t steps = sweep_steps;
  for (const auto& t : trajectories) steps += static_cast<std::size_t>(std::ceil(t.duration() / dt));
  // Counter families as fly_pilot: stream 0 the initial state, 1 the aircraft's noise, 2 and 3 the two
  // pilots.
  UniformStream init(seed, 0), noise(seed, 1);
  std::vector<double> p(static_cast<std::size_t>(aircraft.initial_noise_dim()));
  for (double& u : p) u = init.next();
  const std::unique_ptr<SimulatedFlight> s = aircraft.start_flight(p);
  p.resize(static_cast<std::size_t>(aircraft.step_noise_dim()));
  ScriptedPilot sweeper(aircraft, options, seed, 2);
  sweeper.set_total_seconds(sweep_seconds);
  PilotOptions plain = options;
  plain.sweeps = false;
  ScriptedPilot flyer(aircraft, plain, seed, 3);
  PilotFlight f;
  f.log.time.reserve(steps);
  f.log.states.reserve(steps);
  f.log.controls.reserve(steps);
  f.truth.reserve(steps);
  std::size_t leg = 0;
  double leg_start = sweep_seconds;
  for (std::size_t t = 0; t < steps; ++t) {
    const double time = static_cast<double>(t) * dt;
    const LoggedState est = s->observe();
    Controls a;
    if (t < sweep_steps) {
      a = sweeper.act(est, time);
    } else {
      while (leg + 1 < trajectories.size() && time >= leg_start + trajectories[leg].duration()) {
        leg_start += trajectories[leg].duration();
        ++leg;
      }
      const Trajectory& traj = trajectories[leg];
      const TrajectoryPoint sp = traj.at(time - leg_start);
      flyer.set_hold(sp.p_W.x(), sp.p_W.y(), sp.p_W.z(), wrap_angle(sp.yaw));
      a = flyer.act(est, time);
    }
    f.log.time.push_back(time);
    f.log.states.push_back(est);
    f.log.controls.push_back(a);
    f.truth.push_back(s->truth());
    for (double& u : p) u = noise.next();
    s->step(a, p);
    if (s->crash() != CrashReason::kNone) {
      f.crash = s->crash();
      f.crash_time = time + dt;
      break;
    }
  }
  return f;
}

}  // namespace pegasus::heli
