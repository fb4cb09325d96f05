#pragma once
// The hover task of thesis §5.3: the reward (Eqs 5.9-5.10), a model wrapper that adds a set point and the
// reward to any helicopter simulative model, and PEGASUS training of the hover policy on the identified
// model (30 scenarios of 35 s, gamma = 0.9995, gradient ascent and random-walk hill climbing).
//
// Reward of a transition from s under a (R(s) of the state left, plus R(a); Eq 4.3's convention):
//   R = -( sum_i alpha_pos_i (p_i - p*_i)^2 + sum_i alpha_vel_i v_i^2 + alpha_yaw wrap(yaw - yaw*)^2 )
//   (Eq 5.9)
//       -( sum_j alpha_att_j att_j^2 + sum_j alpha_rate_j rate_j^2 )  (not in the thesis; 0 by default)
//       -( sum_c alpha_a_c (a_c - centre_c)^2 ) (Eq 5.10)
//       + the model's own reward (the learned model's crash penalty, -50000, footnote 13).
// Positions and velocities are in W; the yaw error wraps about 2 pi (footnote 12). The weights follow the
// thesis's heuristic: alpha = 1 / typical^2 for a crude guess of each term's typical size, so every term is
// about 1 at its typical size. The action cost is taken about `centre`, the controls' mean in the pilot's
// logs (an estimate of the hover trim), not about 0: with a trim collective of ~0.18 a cost about 0 would
// pay the policy to hang ~alpha_a3 * 0.18 / alpha_z below its set point. Setting centre to 0 gives Eq 5.10
// literally. The attitude and rate terms (roll and pitch about level; the logged Euler-angle rates) let the
// reward match a cost that judges them too; a zero typical size leaves a term out (the action cost too).
#include <array>
#include <cstdint>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/core/number_setting.hpp"
#include "pegasus/heli/hover_policy.hpp"
#include "pegasus/models/model.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/sysid/learned_model.hpp"

namespace pegasus::heli {

// One of HoverReward's weights as a user sets it: by its term's typical size (alpha = 1 / size^2, the
// thesis's heuristic), described once in HoverReward::VisitFields. From it come `hover`'s option
// `reward.KEY` (default, help, the check that a size of 0 may leave the term out), a vehicle file's
// `[hover.reward] KEY` (allowed, read, checked), the reading of both into the weight, the refusal of
// `reward.KEY` beside `reward.judged_cost`, and the Python field; tests walk the list through each of them.
struct HoverRewardSize {
  const char* key;    // after `reward.` in a config (`--reward.KEY`), and in a vehicle file's [hover.reward]
  const char* field;  // the weight it sets (every element): HoverReward's member and Python's field
  double typical;     // the default size (0: the term is off unless set)
  bool may_be_zero;   // a size of 0 leaves the term out; else the size is at least kMinTypicalSize
  const char* unit;   // of the size
  const char* help;   // the option's one line
};

struct HoverReward {
  // The typical sizes the default weights stand for (alpha = 1 / typical^2, as from_typical computes them):
  // the one place `heli hover`'s defaults and every other user of HoverReward{} read them from.
  static constexpr double kTypicalPosition = 0.5;  // m
  static constexpr double kTypicalVelocity = 0.5;  // m/s
  static constexpr double kTypicalYaw = 0.1;       // rad
  static constexpr double kTypicalAction = 0.1;    // control units about the centre
  static constexpr double kPosition = 1 / (kTypicalPosition * kTypicalPosition);
  static constexpr double kVelocity = 1 / (kTypicalVelocity * kTypicalVelocity);
  static constexpr double kAction = 1 / (kTypicalAction * kTypicalAction);
  // The smallest typical size a weight is made from: below it, 1 / size^2 exceeds kMaxRewardWeight.
  static constexpr double kMinTypicalSize = 1e-6;

  std::array<double, 3> alpha_pos{kPosition, kPosition, kPosition};        // per m^2
  std::array<double, 3> alpha_vel{kVelocity, kVelocity, kVelocity};        // per (m/s)^2
  double alpha_yaw = 1 / (kTypicalYaw * kTypicalYaw);                      // per rad^2
  std::array<double, 4> alpha_action{kAction, kAction, kAction, kAction};  // per unit^2 about centre
  Controls centre{0, 0, 0, 0};
  std::array<double, 2> alpha_attitude{0, 0};  // per rad^2 of roll and pitch (about level)
  std::array<double, 3> alpha_rate{0, 0, 0};   // per (rad/s)^2 of the roll, pitch and yaw rates
  // A judged cost's terms (vehicle/vehicle.hpp's [cost]; 0 by default): per (rad/s)^2 of the body rates p, q,
  // r (FRD), and per unit^2 of the vector part of the attitude's rotation from the set point's attitude
  // (level, at the set point's yaw) in body axes: (x, y, z) of the quaternion of R_z(yaw*)^T R, which is
  // quaternion_from_euler(roll, pitch, wrap(yaw - yaw*)) (the sign of a quaternion does not change its
  // squares).
  std::array<double, 3> alpha_body_rate{0, 0, 0};
  std::array<double, 3> alpha_quaternion{0, 0, 0};

  // Every field above, once, in the order Python lists them: a visitor offers
  //   size(HoverRewardSize, &HoverReward::field, doc)  // a weight the user sets by a typical size
  //   weight(name, &HoverReward::field, doc)           // a weight set otherwise (the judged cost's terms)
  //   field(name, &HoverReward::field, doc)            // not a weight (the centre)
  // with `doc` the field's one line (Python's docstring). IsValid checks every weight. A new term: its field,
  // its entry here, its use in state_cost or action_cost and its part of terms(), and a test.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using R = HoverReward;
    v.size({"position_m", "alpha_pos", kTypicalPosition, false, "m",
            "typical position error: alpha_x,y,z = 1 / this^2 (Eq 5.9)"},
           &R::alpha_pos, "Per m^2, x y z.");
    v.size({"velocity_mps", "alpha_vel", kTypicalVelocity, false, "m/s",
            "typical velocity: alpha_xdot,ydot,zdot = 1 / this^2 (Eq 5.9)"},
           &R::alpha_vel, "Per (m/s)^2.");
    v.size({"yaw_rad", "alpha_yaw", kTypicalYaw, false, "rad",
            "typical yaw error: alpha_yaw = 1 / this^2 (Eq 5.9)"},
           &R::alpha_yaw, "Per rad^2.");
    v.size({"action", "alpha_action", kTypicalAction, true, "control units",
            "typical control departure: alpha_a = 1 / this^2 (Eq 5.10); 0: no action cost"},
           &R::alpha_action, "Per unit^2 about centre.");
    v.field("centre", &R::centre, "The controls the action cost is taken about.");
    v.size({"attitude_rad", "alpha_attitude", 0, true, "rad",
            "typical roll and pitch (about level): alpha = 1 / this^2; 0: no attitude term (as Eq 5.9)"},
           &R::alpha_attitude, "Per rad^2 of roll and pitch (about level).");
    v.size({"rate_radps", "alpha_rate", 0, true, "rad/s",
            "typical roll, pitch and yaw rate: alpha = 1 / this^2; 0: no rate term (as Eq 5.9)"},
           &R::alpha_rate, "Per (rad/s)^2 of the roll, pitch and yaw rates.");
    v.weight("alpha_body_rate", &R::alpha_body_rate,
             "Per (rad/s)^2 of the body rates p, q, r (FRD): a judged cost's term (0 by default).");
    v.weight("alpha_quaternion", &R::alpha_quaternion,
             "Per unit^2 of x, y, z of the attitude's rotation from the set point's (level, at its yaw), in "
             "body axes: a judged cost's term (0 by default).");
  }
  // The weights set by typical sizes, in VisitFields's order (that of `hover`'s reward.* options).
  static const std::vector<HoverRewardSize>& sizes();
  // Every field's name, in VisitFields's order (Python's _fields).
  static const std::vector<std::string>& field_names();
  // Sets every element of the weight `size` names to weight_of_typical(typical).
  void set_typical(const HoverRewardSize& size, double typical);

  // alpha = 1 / typical^2 for each term; a typical size of 0 gives alpha = 0 (no term).
  static double weight_of_typical(double typical) { return typical > 0 ? 1 / (typical * typical) : 0.0; }
  static HoverReward from_typical(double position_m, double velocity_mps, double yaw_rad, double action,
                                  Controls centre);
  bool IsValid(std::string* error) const;
  // Eq 5.9 without the sign: >= 0, 0 exactly at the set point at rest.
  double state_cost(const LoggedState& s, const SetPoint& target) const;
  // Eq 5.10 without the sign: >= 0.
  double action_cost(const Controls& a) const;
  // One line naming the terms in the reward and their weights (those of 0 left out), and the crash penalty.
  std::string terms(double crash_penalty) const;
};

// A helicopter model M (LearnedHeliModel for training; Observation = the 12 logged states) with a fixed set
// point and the hover reward. Satisfies SimulativeModel; the policy sees HeliObservation. With an
// ErrorIntegrator on, the task's state carries the error integral beside the model's (the integral term's
// memory, advanced after every step exactly as a flown controller advances it).
template <SimulativeModel M>
class HoverTask {
 public:
  struct State {
    typename M::State model;
    std::array<double, 4> integral{};
  };
  using Action = Controls;
  using Observation = HeliObservation;

  HoverTask(M model, SetPoint target, HoverReward reward, ErrorIntegrator integrator = {})
      : model_(std::move(model)), target_(target), reward_(reward), integrator_(integrator) {}

  int state_dim() const { return model_.state_dim(); }
  int noise_dim() const { return model_.noise_dim(); }
  int initial_noise_dim() const { return model_.initial_noise_dim(); }
  ActionSpace action_space() const { return model_.action_space(); }
  State initial_state(std::span<const double> p0) const { return {model_.initial_state(p0), {}}; }
  State step(const State& s, const Action& a, std::span<const double> p) const {
    State next{model_.step(s.model, a, p), s.integral};
    if (integrator_.on())
      next.integral = integrator_.advanced(s.integral, model_.observe(next.model), target_);
    return next;
  }
  bool terminal(const State& s) const { return model_.terminal(s.model); }
  Observation observe(const State& s) const { return {model_.observe(s.model), target_, s.integral}; }
  double reward(const State& s, const Action& a, const State& next) const {
    return transition_reward(model_, s.model, a, next.model) -
           reward_.state_cost(model_.observe(s.model), target_) - reward_.action_cost(a);
  }

  const M& model() const { return model_; }
  const SetPoint& target() const { return target_; }
  const HoverReward& hover_reward() const { return reward_; }
  const ErrorIntegrator& integrator() const { return integrator_; }

 private:
  M model_;
  SetPoint target_;
  HoverReward reward_;
  ErrorIntegrator integrator_;
};

// Trim estimate from the pilot's logs, as the identified model holds them: the mean controls, roll and
// pitch of the training data (the pilot hovers, and the sweeps are symmetric about the hover).
HoverPolicyInit hover_init_from_model(const sysid::IdentifiedModel& model);

// Starting gains from the identified model instead of the X-Cell's constants (issue 15): the model's mean
// step linearised at the hover (the set point at the logs' trim attitude and controls, the extra states at
// their equilibrium; the local fit there held), a discounted LQR on it with the reward's weights (Q:
// positions, velocities, yaw, and the attitude and rate terms when set; R: the action weights, 1 per unit^2
// where the action cost is off) and the task's discount per model step, and the gains of the wiring the hover
// class has (each channel's position error, velocity and attitude; HoverPolicy) taken from the full LQR gain.
// The result is used only when that decoupled controller is stable on the linear model; else the constants
// stay and `reason` says why.
struct LqrStart {
  HoverPolicyInit init;  // the gains used (the constants when !used), trim from the logs
  bool used = false;
  std::string reason;           // why not used (empty when used)
  double spectral_radius = 0;   // of the linear model under the hover class's gains, per model step
  double open_loop_radius = 0;  // of the linear model with the controls held
  // With the integral term: the integral_seconds the start uses (options' doubled until stable) and the
  // spectral radius with the integral states.
  double integral_seconds = 0;
  double integral_radius = 0;
};
struct HoverTrainingOptions;
LqrStart lqr_hover_init(const sysid::IdentifiedModel& model, const HoverTrainingOptions& options);

struct HoverTrainingOptions {
  int scenarios = 30;     // PEGASUS scenarios m (§5.3: 30)
  double seconds = 35;    // flight per scenario, s (§5.3: 35)
  double gamma = 0.9995;  // discount per 1/50 s (§5.3's per-step gamma at 50 Hz)
  // The controller's rate: the learned model steps at it and the policy is trained for it (§5.1: 50 Hz; an
  // aircraft whose flight computer runs its controller at 10 Hz trains at 10 Hz). The discount per step is
  // gamma^(50 / control_rate_hz), so the horizon in seconds stays the same.
  double control_rate_hz = 50;
  // Learned model: steps between local-regression refits (§5.2.2: 5 at 50 Hz from a 10 Hz model); 0 refits
  // every sysid::kRefitSeconds (0.1 s, the thesis's 10 Hz) whatever the model's rate: sysid::refit_steps_at.
  int refit_every = 0;
  // The default budget on a locally weighted model (issues 48, 53), in nominal CPU seconds of its refits:
  // training stops after the U-hat evaluations whose refits would cost about this at kRefitSecondsPerRow per
  // training row per refit (measured on the project's 2-core machine; a constant, so the budget and every
  // result depend only on the inputs, never on the clock). It binds only where it is below what the
  // default optimizer's own limits would spend (evaluation_budget). 0: no such limit.
  double cpu_budget_s = 240;
  static constexpr double kRefitSecondsPerRow = 6e-9;
  SetPoint target{0, 0, -10, 0};  // where to hover (the model's start is the target plus the perturbation)
  double start_pos_sigma = 1.0;   // start position perturbation per axis, m
  double start_vel_sigma = 0.3;   // start velocity perturbation per axis, m/s
  double max_tilt_rad = 1.0;      // |roll| or |pitch| beyond this crashes the learned model (the envelope)
  // The rest of the envelope (a judged cost's; off by default): the distance from the set point (m), the
  // speed (m/s) and any Euler-angle rate (rad/s) beyond which the learned model crashes.
  double max_position_error_m = std::numeric_limits<double>::infinity();
  double max_speed_mps = std::numeric_limits<double>::infinity();
  double max_rate_radps = std::numeric_limits<double>::infinity();
  double crash_penalty = 50000;  // what a crash costs (footnote 13: 50000; the learned model's crash_reward)
  // Wind in the scenarios (sysid::Disturbance: a steady wind, its per-scenario spread and an AR(1) gust
  // process, acting on the learned model through the airspeed); calm by default, as the thesis trains.
  sysid::Disturbance disturbance{};
  HoverReward reward{};        // with centre = the trim estimate unless set
  bool centre_at_trim = true;  // replace reward.centre by the trim estimate of the logs
  OptimizerOptions optimizer = default_optimizer();
  // Run hill climbing after gradient ascent from its result (the thesis tried both; §5.3). Used when
  // optimizer.method is "gradient".
  bool then_hill_climb = true;
  std::uint64_t seed = 1;  // scenarios (and hill climbing's stream)
  // Training stops before it starts (InputError naming this option) when the starting policy crashes the
  // learned model in more than this fraction of the scenarios: from there no optimizer gets a useful
  // gradient, and the weights it returns mean nothing (an outside aircraft's model crashed 3 of 10 starts
  // within 0.2 s and gave a U-hat of -3.8e7; the X-Cell's shipped configs crash none). 1 never stops.
  double max_start_crash_fraction = 0.1;
  // Starting gains: the X-Cell's constants of HoverPolicyInit (false) or LQR on the identified model (true;
  // lqr_hover_init). An aircraft with other control signs or strengths needs the second.
  bool lqr_start = false;
  // The LQR's action weights (R) are the reward's times this. train_hover raises it by factors of 10 (up to
  // kMaxLqrActionFactor) while the starting policy crashes the learned model in more than
  // max_start_crash_fraction of the scenarios: gentler gains keep the controls near the logs' (an LQR with
  // the reward's weights moved an aircraft's controls 0.5 away from the pilot's for a 3 m start error, off
  // the data, and crashed 22 of 30 starts), and says so in HoverTrainingResult::lqr_action_factor.
  double lqr_action_factor = 1;
  static constexpr double kMaxLqrActionFactor = 1000;
  // The LQR's action weight per control is at least this, for the gains only (the reward keeps its own): the
  // default reward's (typical departure HoverReward::kTypicalAction, 0.1). With no action cost (reward.action
  // 0, as a judged cost may have) the Riccati equation still has a positive definite R, and gains of the size
  // the default gives: with a weight of 1 the X-Cell's hover class did not hold its linear model (spectral
  // radius 1.33, tests/heli/hover_task_test.cpp), and the start fell back to the constants.
  static constexpr double kLqrMinActionWeight =
      1 / (HoverReward::kTypicalAction * HoverReward::kTypicalAction);
  // Compute the LQR gains on the class identify did not choose (sysid::IdentifiedModel::alternative, on the
  // same data) while training runs on the chosen model: train_hover's second try when the chosen model's
  // gains crash too often (issue 48).
  bool lqr_gains_from_alternative = false;
  // The integral term (HoverPolicy, ErrorIntegrator; not in the thesis): 0 leaves it out (the thesis's
  // class); else the policy gets a1.int .. a4.int, each starting at its channel's error gain /
  // integral_seconds (with the LQR start: doubled until the gains with the integral hold the linear model),
  // and the integrator runs at the control rate within these limits.
  double integral_seconds = 0;
  double integral_limit_position = ErrorIntegrator{}.limit_position;  // m s
  double integral_limit_yaw = ErrorIntegrator{}.limit_yaw;            // rad s
  // A global linear model extrapolates without bound, and its training rewards any command that would help
  // there: the policy's command limits (HoverPolicyInit) are then the range of each control the logs held,
  // widened by this fraction of its width per side (hover_command_limits; a locally weighted model crashes
  // off its data instead, and keeps [-1, 1]). On an outside-like helicopter trained on the global model, one
  // flight in 20 overloaded the rotor with a collective the logs never came near; a crash in the model there
  // instead of a limit flew a 4 m/s wind at 0.66x the baseline's judged cost, the limits at 1.34x
  // (docs/results/baselines.md).
  double command_margin = kDefaultCommandMargin;

  // Every number `hover` takes as an option, once (issue 49 item 1): the visitor's `setting(NumberSetting,
  // &HoverTrainingOptions::member)`, member an int or a double, the key its name. From it come `hover`'s
  // option KEY (default, help, bounds) and its reading, IsValid's bounds and the Python field with its doc.
  // A new number: its member, its entry here, its use.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = HoverTrainingOptions;
    v.setting({"scenarios", 1, 100000, false, "", "PEGASUS scenarios m (thesis 5.3: 30)"}, &O::scenarios);
    v.setting({"seconds", 0, 3600, true, "s", "flight per scenario, s (thesis 5.3: 35)"}, &O::seconds);
    v.setting({"control_rate_hz", 0.1, 1000, false, "Hz",
               "the controller's rate, Hz: the learned model steps at it and the policy is trained for it "
               "(thesis 5.1: 50; a flight computer that runs its controller at 10 Hz: 10)"},
              &O::control_rate_hz);
    v.setting(
        {"integral_seconds", 0, 3600, false, "s",
         "the hover class's integral term against steady offsets (wind): each channel's int weight "
         "starts at its error gain / this (LQR start: doubled until stable on the linear model); 0: none "
         "(the thesis's class)"},
        &O::integral_seconds);
    v.setting(kCommandMarginSetting, &O::command_margin);
    v.setting({"integral_limit_position", 0, 1e6, true, "m s",
               "anti-windup: the position error integral's limit per axis, m s"},
              &O::integral_limit_position);
    v.setting(
        {"integral_limit_yaw", 0, 1e6, true, "rad s", "anti-windup: the yaw error integral's limit, rad s"},
        &O::integral_limit_yaw);
    v.setting({"gamma", 0, 1, true, "",
               "discount per 1/50 s (thesis 5.3: 0.9995 per 50 Hz step); per step it is gamma^(50 / "
               "control_rate_hz)"},
              &O::gamma);
    v.setting({"refit_every", 0, 1000, false, "steps",
               "learned model: steps between local-regression refits; 0: every 0.1 s, the thesis's 10 Hz, at "
               "any model rate (thesis 5.2.2: 5 steps at 50 Hz)"},
              &O::refit_every);
    v.setting(
        {"cpu_budget_s", 0, 1e9, false, "s",
         "on a locally weighted model, gradient ascent and hill climbing stop after the U-hat "
         "evaluations whose refits take about this many CPU seconds (nominal: 6 ns per training row per "
         "refit, the project's 2-core machine; from the model's size, never the clock); binds only below "
         "the optimizer's own limits (evaluation_budget in summary.json); 0: none"},
        &O::cpu_budget_s);
    v.setting({"start_pos_sigma", 0, 100, false, "m", "start position perturbation per axis, m"},
              &O::start_pos_sigma);
    v.setting({"start_vel_sigma", 0, 100, false, "m/s", "start velocity perturbation per axis, m/s"},
              &O::start_vel_sigma);
    v.setting({"max_tilt_rad", 0, 1.5, true, "rad",
               "the envelope: |roll| or |pitch| beyond this crashes the learned model, rad"},
              &O::max_tilt_rad);
    v.setting({"max_start_crash_fraction", 0, 1, false, "",
               "stop before training when the starting policy crashes the learned model in more than this "
               "fraction of the scenarios (1: never stop)"},
              &O::max_start_crash_fraction);
  }
  // The numbers in VisitFields's order; the one named `key` (std::logic_error for another name).
  static const std::vector<NumberSetting>& settings();
  static const NumberSetting& setting(std::string_view key);

  static OptimizerOptions default_optimizer();
  int horizon() const;            // steps of 1 / control_rate_hz
  double gamma_per_step() const;  // gamma^(50 / control_rate_hz)
  // refit_every, or every 0.1 s when 0 (the model is not used: kept for callers that pass it).
  int refit_steps(const sysid::IdentifiedModel& model) const;
  ErrorIntegrator integrator() const;  // off when integral_seconds is 0
  // The U-hat evaluations cpu_budget_s allows training on `model` when it binds, else 0: a global linear
  // model (no refits), a method other than the default gradient ascent (the user's own budget), or a budget
  // above the stages' own (the gradient's iterations x (2 n + 2) evaluations for n parameters, and hill
  // climbing's iterations x proposals). train_hover gives hill climbing up to a quarter of it.
  std::int64_t evaluation_budget(const sysid::IdentifiedModel& model, int parameters) const;
  bool IsValid(std::string* error) const;
};

// The objective U-hat(theta) of the hover task on the learned model: PegasusObjective over a HoverTask.
std::unique_ptr<Objective> hover_objective(const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                           const HoverTrainingOptions& options,
                                           std::shared_ptr<ThreadPool> pool);
// The policy class with starting weights from the model's logs (and its LQR gains when options.lqr_start and
// they are stable).
HoverPolicy hover_policy_for(const sysid::IdentifiedModel& model);
// The command limits training gives the policy on `model` (HoverTrainingOptions::command_margin): on a global
// linear model, per control, [min - margin w, max + margin w] of the logs' values (w = max - min) within
// [-1, 1], and [-1, 1] for a control the logs never moved; on a locally weighted model [-1, 1]. Set in the
// returned init's command_lower and command_upper.
HoverPolicyInit hover_command_limits(const sysid::IdentifiedModel& model, double margin);
HoverPolicy hover_policy_for(const sysid::IdentifiedModel& model, const HoverTrainingOptions& options);
// The reward with centre from the model's logs when options.centre_at_trim.
HoverReward hover_reward_for(const sysid::IdentifiedModel& model, const HoverTrainingOptions& options);

// The starting weights flown on the training scenarios of the learned model (the check train_hover makes
// before it trains).
struct StartingPolicyCheck {
  int scenarios = 0;
  int crashed = 0;                   // scenarios whose rollout ended in the model's crash state
  double mean_seconds_to_crash = 0;  // over the crashed ones; 0 when none crashed
  double uhat = 0;                   // the starting policy's U-hat
};
StartingPolicyCheck check_starting_policy(const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                          const HoverTrainingOptions& options, ThreadPool& pool);

struct HoverTrainingHooks {
  std::int64_t checkpoint_every = 1;  // optimizer iterations between checkpoints (0: none)
  // Receives the training plan's checkpoints (optimizers/training.hpp: the stage, the finished stages and the
  // running optimizer's checkpoint); write it atomically.
  CheckpointCallback on_checkpoint;
  std::optional<nlohmann::json> resume_from;  // a checkpoint from on_checkpoint: the run continues exactly
  IterationCallbacks callbacks;               // told after every optimizer iteration (progress, early stops)
  // Told the U-hats of every evaluation (or parallel batch) of training, as they come (progress lines; an
  // iteration can take minutes). Never changes what training does.
  ObservedObjective::Observer on_evaluations;
};

// One starting policy train_hover tried: where its LQR gains came from, their action weight factor, and how
// often it crashed the learned model (not flown when the LQR gave no gains: `reason` says why).
struct StartTry {
  std::string gains;  // "chosen model" or the other class's name ("global linear", "locally weighted")
  double action_factor = 1;
  bool lqr_used = false;
  std::string reason;  // why the LQR gave no gains (empty when it did)
  StartingPolicyCheck check;
  bool taken = false;  // the start training ran from
};

struct HoverTrainingResult {
  Theta theta;  // the best weights
  double initial_uhat = 0, final_uhat = 0;
  OptimizerSummary gradient, hill_climb;  // the phases run (method empty when not run)
  std::vector<IterationRecord> progress;  // both phases, iterations and evaluations counted on
  StartingPolicyCheck start;              // of the starting weights, before training
  double lqr_action_factor = 1;           // the LQR start's, after train_hover raised it (options' otherwise)
  bool lqr_gains_from_alternative = false;  // the start's gains come from the class identify did not choose
  std::vector<StartTry> start_tries;        // with the LQR start, every start tried, in order
};

HoverTrainingResult train_hover(const std::shared_ptr<const sysid::IdentifiedModel>& model,
                                const HoverTrainingOptions& options, const HoverTrainingHooks& hooks,
                                ThreadPool& pool);

}  // namespace pegasus::heli
