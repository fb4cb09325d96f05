#pragma once
// The manoeuvre task of thesis §5.4: reward, model wrapper, shaping potential, PEGASUS training on the
// identified model, and flights of a trained policy on the ground-truth aircraft.
//
// Reward of a transition from s under a (R(s) of the state left plus R(a), as the hover task):
//   R = -( alpha_pos |p - p_p|^2 + alpha_yaw wrap(yaw - yaw_p)^2 + alpha_vel |v - v_p|^2 )
//       -( sum_c alpha_a_c (a_c - centre_c)^2 )              (Eq 5.10 about the trim, as hover_task.hpp)
//       + the model's own reward (the learned model's crash penalty, footnote 13)
// where (p_p, yaw_p) is the observer's projection of the helicopter onto the ideal path (path_observer.hpp)
// and v_p the ideal set-point velocity there: deviation from the path is paid, lagging behind the moving set
// point is not (§5.4's argument against Eq 5.9 with a moving (x*, y*, z*, omega*)).
//
// Shaping (§5.4 with chapter 3): the model is wrapped in ShapedModel (shaping/potential_shaping.hpp) with
// Phi(s) = per_metre * progress(s), progress the observer's arc length along the path, so F = gamma Phi(s') -
// Phi(s) pays forward progress. Theorem 1's episodic condition holds: Phi is 0 at the absorbing states (the
// crash; ShapedModel's zero_at_terminal) and at the start of the path. Over a PEGASUS rollout of H steps the
// shaping telescopes to gamma^H Phi(s_H) - Phi(s_0): a crashed flight keeps nothing, and a flight that is
// further along the path when the horizon ends keeps more.
//
// Time: the wrapper counts 50 Hz steps; the policy sees the time since the manoeuvre began.
#include <array>
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pegasus/core/number_setting.hpp"
#include "pegasus/core/reward_limits.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/maneuver_policy.hpp"
#include "pegasus/heli/path_observer.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/models/model.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/sysid/learned_model.hpp"

namespace pegasus::heli {

struct ManeuverReward {
  double alpha_pos = 4;  // per m^2 of distance to the projection (typical 0.5 m)
  double alpha_yaw = 4;  // per rad^2 of wrapped yaw error to the projection (typical 0.5 rad in pirouettes)
  double alpha_vel = 1;  // per (m/s)^2 of velocity minus the ideal velocity at the projection (typical 1 m/s)
  std::array<double, 4> alpha_action{4, 4, 4, 4};  // per unit^2 about centre (typical 0.5)
  Controls centre{0, 0, 0, 0};
  bool IsValid(std::string* error) const;
  // The state part without the sign (>= 0).
  double state_cost(const LoggedState& s, const PathProjection& p) const;
  double action_cost(const Controls& a) const;
};

// A helicopter model M (observation = the 12 logged states) flying a path: the state carries the observer's
// projection and the step count. Satisfies SimulativeModel; the policy sees ManeuverObservation.
template <SimulativeModel M>
class ManeuverTask {
 public:
  struct State {
    typename M::State base{};
    PathProjection path{};
    int step = 0;
  };
  using Action = Controls;
  using Observation = ManeuverObservation;

  ManeuverTask(M model, std::shared_ptr<const PathObserver> observer, ManeuverReward reward, double dt = 0.02)
      : model_(std::move(model)), observer_(std::move(observer)), reward_(reward), dt_(dt) {}

  int state_dim() const { return model_.state_dim(); }
  int noise_dim() const { return model_.noise_dim(); }
  int initial_noise_dim() const { return model_.initial_noise_dim(); }
  ActionSpace action_space() const { return model_.action_space(); }
  State initial_state(std::span<const double> p0) const {
    State s{.base = model_.initial_state(p0)};
    s.path = project(observer_->start(), s.base);
    return s;
  }
  State step(const State& s, const Action& a, std::span<const double> p) const {
    State next{.base = model_.step(s.base, a, p), .path = s.path, .step = s.step + 1};
    if (!model_.terminal(next.base)) next.path = project(s.path, next.base);
    return next;
  }
  bool terminal(const State& s) const { return model_.terminal(s.base); }
  Observation observe(const State& s) const { return {model_.observe(s.base), s.step * dt_}; }
  double reward(const State& s, const Action& a, const State& next) const {
    return transition_reward(model_, s.base, a, next.base) -
           reward_.state_cost(model_.observe(s.base), s.path) - reward_.action_cost(a);
  }

  const M& model() const { return model_; }
  const PathObserver& observer() const { return *observer_; }
  const ManeuverReward& maneuver_reward() const { return reward_; }

 private:
  PathProjection project(const PathProjection& last, const typename M::State& b) const {
    const auto o = model_.observe(b);
    return observer_->update(last, Vec3(o[0], o[1], o[2]), o[5]);
  }
  M model_;
  std::shared_ptr<const PathObserver> observer_;
  ManeuverReward reward_;
  double dt_;
};

// Phi(s) = per_metre * progress along the path (m).
struct PathProgressPotential {
  double per_metre = 1;
  template <class S>
  double operator()(const S& s) const {
    return per_metre * s.path.progress;
  }
};

struct ManeuverTrainingOptions {
  std::string name = "III.1";
  ManeuverSize size{};
  TrajectoryLimits limits{};
  PathObserverOptions observer{};
  ManeuverPolicyOptions policy{};
  int scenarios = 30;            // PEGASUS scenarios m (§5.3's 30)
  double gamma = 0.9995;         // per 50 Hz step (§5.3)
  int refit_every = 5;           // learned model: steps between refits (§5.2.2)
  double start_pos_sigma = 0.5;  // start position perturbation per axis, m
  double start_vel_sigma = 0.2;  // start velocity perturbation per axis, m/s
  ManeuverReward reward{};
  bool centre_at_trim = true;  // replace reward.centre by the trim estimate of the logs
  // Wind in the scenarios (sysid::Disturbance, as the hover's: a steady wind, its per-scenario spread and
  // AR(1) gusts acting on the learned model through the airspeed); calm by default, as the thesis trains.
  sysid::Disturbance disturbance{};
  bool shaping = true;           // potential-based shaping on progress (false: the ablation)
  double shaping_per_metre = 5;  // Phi per m of progress
  // On a global linear model, the policy's commands stay within each control's logged range widened by this
  // fraction of it per side, as hover training's (HoverTrainingOptions::command_margin, issue 48).
  double command_margin = kDefaultCommandMargin;
  OptimizerOptions optimizer = default_optimizer();
  std::uint64_t seed = 1;

  // Every number `maneuver` takes as an option, once (issue 49 item 1; as HoverTrainingOptions::VisitFields):
  // the visitor's `setting(NumberSetting, &ManeuverTrainingOptions::member)`, the key the member's name. From
  // it come the options (default, help, bounds), their reading and IsValid's bounds.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = ManeuverTrainingOptions;
    v.setting({"scenarios", 1, 100000, false, "", "PEGASUS scenarios m"}, &O::scenarios);
    v.setting({"gamma", 0, 1, true, "", "discount per 50 Hz step"}, &O::gamma);
    v.setting({"refit_every", 1, 1000, false, "steps",
               "learned model: 50 Hz steps between local-regression refits"},
              &O::refit_every);
    v.setting({"start_pos_sigma", 0, 10, false, "m", "start position perturbation per axis, m"},
              &O::start_pos_sigma);
    v.setting({"start_vel_sigma", 0, 10, false, "m/s", "start velocity perturbation per axis, m/s"},
              &O::start_vel_sigma);
    v.setting({"shaping_per_metre", 0, kMaxRewardWeight, false, "per m",
               "shaping potential per m of progress along the path"},
              &O::shaping_per_metre);
    v.setting(kCommandMarginSetting, &O::command_margin);
  }

  static OptimizerOptions default_optimizer();
  bool IsValid(std::string* error) const;
};

// The trajectory, observer and policy class the options describe (init: the hover weights' starting point and
// trim, hover_init_from_model).
std::shared_ptr<const Trajectory> maneuver_trajectory_for(const ManeuverTrainingOptions& o);
// Rollout length: the trajectory's duration in 50 Hz steps.
int maneuver_horizon(const Trajectory& trajectory);

// U-hat(theta) of the manoeuvre task on the learned model (PegasusObjective; shaped when options.shaping).
std::unique_ptr<Objective> maneuver_objective(std::shared_ptr<const sysid::IdentifiedModel> model,
                                              const ManeuverTrainingOptions& options,
                                              const ManeuverPolicy& policy, std::shared_ptr<ThreadPool> pool);

struct ManeuverTrainingHooks {
  std::int64_t checkpoint_every = 1;
  CheckpointCallback on_checkpoint;           // the training layer's checkpoint; write it atomically
  std::optional<nlohmann::json> resume_from;  // continue exactly from such a checkpoint
};

struct ManeuverTrainingResult {
  Theta theta;
  OptimizerSummary summary;
};

// PEGASUS training from `start` (empty: the policy's initial values).
ManeuverTrainingResult train_maneuver(std::shared_ptr<const sysid::IdentifiedModel> model,
                                      const ManeuverTrainingOptions& options, const ManeuverPolicy& policy,
                                      const Theta& start, const ManeuverTrainingHooks& hooks,
                                      ThreadPool& pool);

// ---- Flights on the ground truth ------------------------------------------------------------------------

struct ManeuverFlightOptions {
  int flights = 20;
  double extra_seconds = 0;      // flown after the trajectory's end
  double gust_sigma = 0.5;       // turbulence per axis, m/s (AircraftParams)
  double start_pos_sigma = 0.5;  // start perturbation, m
  double start_vel_sigma = 0.2;  // m/s
  std::uint64_t seed = 1;
  std::string simulator = "xcell";  // the ground truth flown (heli/simulators.hpp)
  bool IsValid(std::string* error) const;

  // The numbers a user sets, once (issue 49 item 1): `heli maneuver`'s flights and flight_start_sigma, with
  // their bounds, help and reading, and IsValid's bounds. The gusts are declare_gust_sigma's, as every
  // command's; the rest is set by the run, not the user.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = ManeuverFlightOptions;
    v.setting({"flights", 1, 100000, false, "", "flights on the ground-truth aircraft per policy"},
              &O::flights);
    v.setting({"flight_start_sigma", 0, 10, false, "m", "start position perturbation of the flights, m"},
              &O::start_pos_sigma);
  }
};

struct ManeuverFlight {
  std::vector<LoggedState> truth;  // true states, one per 50 Hz step (row 0 = the start)
  std::vector<Controls> controls;  // the controls applied at each row (the last row repeats the one before)
  std::vector<SetPoint> targets;   // the set point of each row
  std::vector<double> deviation;   // distance of the true position to its projection on the path, m
  std::vector<double> progress;    // the observer's progress along the path, m
  double final_progress = 0;       // m along the path at the end
  CrashReason crash = CrashReason::kNone;
  double crash_time = -1;
};

struct ManeuverFlightSummary {
  int flights = 0, crashes = 0, completed = 0;  // completed: ended within 1 m of the path's end, no crash
  double rms_path_deviation_m = 0, max_path_deviation_m = 0;
};

// Flies the policy on the ground-truth aircraft (gusts and state-estimate noise on) from perturbed starts at
// the trajectory's start. The policy sees the state estimate; the deviation is measured on the true state.
std::vector<ManeuverFlight> fly_maneuver(const ManeuverPolicy& policy, std::span<const double> theta,
                                         const PathObserver& observer, const ManeuverFlightOptions& options,
                                         ThreadPool* pool = nullptr);
// The scripted pilot flying the same trajectory's set points (no sweeps; its delay, lag and noise) from the
// same starts and gusts: what the learned policy is compared with.
std::vector<ManeuverFlight> fly_pilot_maneuver(const Trajectory& trajectory, const PilotOptions& pilot,
                                               const PathObserver& observer,
                                               const ManeuverFlightOptions& options,
                                               ThreadPool* pool = nullptr);
ManeuverFlightSummary summarize_maneuver_flights(const std::vector<ManeuverFlight>& flights,
                                                 double path_length);

// ---- Identification data for manoeuvres ------------------------------------------------------------------

// The identified model is only good where the pilot flew (§5.2): hover and small sweeps do not cover 2.5 m/s
// backwards flight, 1.8 m/s climbs or 1 rad/s pirouettes, and the learned model leaves its data's support
// there. This flight gives the scripted pilot (pilot.hpp) `sweep_seconds` of its usual plan (hover, then a
// sweep in each channel), then has it fly the set points of each trajectory in turn, as a pilot practising
// the manoeuvres would (no sweeps, its own delay and noise). One continuous 50 Hz log; everything drawn from
// `seed`.
PilotFlight fly_pilot_maneuvers(const GroundTruth& aircraft, const PilotOptions& options,
                                double sweep_seconds, const std::vector<Trajectory>& trajectories,
                                std::uint64_t seed);

}  // namespace pegasus::heli
