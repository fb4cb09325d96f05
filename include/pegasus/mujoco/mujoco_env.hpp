#pragma once
// An MJCF model plus a task as a deterministic simulative model g(s, a, p) (thesis §4.2.1; issue 18).
//
// The parameters (mjModel, the resolved task) are immutable and shared by every thread. The state is an
// mjData, far too large to copy per step as the value-typed models of models/model.hpp do, so it lives in a
// MujocoSlot that one thread owns and steps in place: made once (the only allocation), reset at the start of
// every rollout to mj_resetData's state, so a rollout's result depends on nothing but (theta, scenario).
//
// A control step sets the ctrl and then takes `frame_skip` physics steps at the MJCF's timestep with the
// MJCF's integrator, its states bit for bit those of as many mj_step calls (issue 52). Every observation and
// reward sees the position- and velocity-dependent quantities (site positions, body velocities, sensors) of
// the current state: the reset and every control step end with mj_step1. Euler and implicit models pay no
// more than frame_skip mj_step calls for it (mj_step2, frame_skip - 1 mj_step calls, mj_step1: mj_step2
// integrates these two as mj_step does), and acceleration sensors lag one physics step. RK4 models (mj_step2
// would integrate them by Euler) take frame_skip mj_step calls and one mj_step1 more; their acceleration
// sensors hold RK4's last stage.
//
// Scenario numbers (§4.4: a scenario is the whole of a rollout's randomness):
//   start  (initial_noise_dim = nq + nv when the task perturbs the start, else 0): qpos_j += h_q (2u - 1),
//          qvel_j += h_v (2u - 1) after the task's initial qpos.
//   step   (noise_dim): nu uniforms when noise.actuator > 0: ctrl_k += actuator * halfrange_k (2u - 1),
//          then 4 per pushed body: u_0 < push_probability pushes that body for this control step with the
//          world-frame force push_force (2u_1 - 1, 2u_2 - 1, 2u_3 - 1) N through xfrc_applied.
//
// Crashes: MuJoCo flags bad (NaN or huge) qpos, qvel or qacc in mjData.warning and resets the state. A
// control step after which any of those counters is non-zero, or any qpos/qvel is not finite, ends the
// rollout with the task's crash_penalty as that step's reward, and is counted as a crash.
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "pegasus/mujoco/mujoco_policy.hpp"
#include "pegasus/mujoco/mujoco_task.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

struct mjData_;

namespace pegasus {

class MujocoEnvironment;

// One thread's simulation state and scratch, made once and reused by every rollout it runs.
class MujocoSlot {
 public:
  explicit MujocoSlot(const MujocoEnvironment& env);
  ~MujocoSlot();
  MujocoSlot(const MujocoSlot&) = delete;
  MujocoSlot& operator=(const MujocoSlot&) = delete;

  mjData_* data;
  std::vector<double> observation, normalized, action, scratch, initial_noise, step_noise;
  std::vector<double> displacement_before;  // the displacement terms' positions at the step's start
  std::vector<double> warmstart;            // RK4 with a contact cost: the solver's warm start kept aside
};

struct MujocoStepOutcome {
  double reward = 0.0;           // the task's reward
  double training_reward = 0.0;  // the same with its training-only terms (RewardTerm::training_only)
  bool terminal = false;         // a termination range was left, or the step crashed
  bool crashed = false;
};

struct MujocoRolloutResult {
  double discounted_return = 0.0;  // of the task's reward
  double training_return = 0.0;    // of the training reward (the same without training-only terms)
  int steps = 0;                   // control steps taken
  bool crashed = false;
  bool success = false;  // the task's success criterion (MujocoTask::success_return, success_ranges)
};

// Called after every control step of a recorded rollout (and once after the reset with t = 0, action empty).
using MujocoStepObserver =
    std::function<void(int t, const mjData_* data, std::span<const double> action, double reward)>;

class MujocoEnvironment {
 public:
  // A reward the task's terms do not cover, added to every control step's reward: (model, data after the
  // step, the action in [-1, 1]) -> reward. Must be deterministic and must not allocate.
  using RewardHook = std::function<double(const struct mjModel_* model, const mjData_* data,
                                          std::span<const double> action)>;

  MujocoEnvironment(MujocoModel model, MujocoTask task, RewardHook hook = {});

  const MujocoModel& model() const { return model_; }
  const MujocoTask& task() const { return task_; }
  int observation_dim() const { return observation_dim_; }
  int action_dim() const;
  int noise_dim() const { return noise_dim_; }
  int initial_noise_dim() const { return initial_noise_dim_; }
  // The MJCF's integrator as MJCF writes it: "Euler", "RK4", "implicit".
  const char* integrator() const;

  void reset(MujocoSlot& slot, std::span<const double> p0) const;
  // One control step from `action` (size nu, entries in [-1, 1]) with step noise p.
  MujocoStepOutcome step(MujocoSlot& slot, std::span<const double> action, std::span<const double> p) const;
  void observe(const MujocoSlot& slot, std::span<double> out) const;
  // Inside every termination range.
  bool healthy(const mjData_* data) const;
  // Inside every one of `ranges`.
  static bool inside(std::span<const TerminationRange> ranges, const mjData_* data);

  // Scenario i of `scenarios` (horizon and discount of the task) under the policy; when `moments` is given,
  // every observation the policy sees is added to it; `observer` sees every step.
  MujocoRolloutResult rollout(const MujocoPolicy& policy, std::span<const double> theta,
                              const ObservationNormalizer& normalizer, const ScenarioSet& scenarios, int i,
                              MujocoSlot& slot, ObservationMoments* moments = nullptr,
                              const MujocoStepObserver* observer = nullptr) const;

  // Scenarios of this environment's noise dimensions and horizon.
  ScenarioSet scenarios(std::uint64_t seed, int count, ScenarioVariant variant) const;

 private:
  // What a rollout's RK4 step computes of the new state beyond qpos and qvel: nothing, the kinematics
  // (body and site positions), or all of mj_step1; what the task's terms, observation and ranges read.
  enum class AfterRk4Step { kNothing, kKinematics, kStep1 };
  static AfterRk4Step after_rk4_step_needs(const MujocoTask& task, bool has_hook);
  // step, with `complete` false letting an RK4 model skip the position and velocity stages of the new state
  // that nothing of the task reads (a rollout without an observer).
  // The parts of a step: the controls and pushes set, the physics stepped, one reward term's value.
  void apply_controls(MujocoSlot& slot, std::span<const double> action, std::span<const double> p) const;
  double integrate(MujocoSlot& slot, bool complete) const;
  double term_value(const RewardTerm& term, const MujocoSlot& slot, std::span<const double> action,
                    double contact_cost, bool is_healthy) const;
  MujocoStepOutcome step_to(MujocoSlot& slot, std::span<const double> action, std::span<const double> p,
                            bool complete) const;
  // reset, by mj_resetData when `complete`, else by restoring only what a rollout's steps read of it (the
  // same rollout bit for bit; an observer may read anything, so a rollout with one resets completely).
  void reset_to(MujocoSlot& slot, std::span<const double> p0, bool complete) const;

  MujocoModel model_;
  MujocoTask task_;
  RewardHook hook_;
  int observation_dim_ = 0, noise_dim_ = 0, initial_noise_dim_ = 0;
  std::vector<double> ctrl_mid_, ctrl_half_;  // ctrl = mid + half * a
  bool contact_cost_ = false;                 // a reward term needs the contact forces
  bool split_step_ = true;                    // mj_step2 integrates as mj_step does (not RK4)
  AfterRk4Step after_rk4_step_ = AfterRk4Step::kStep1;
  double control_dt_ = 0.0;  // frame_skip * timestep, s
};

// MuJoCo's mjtIntegrator as MJCF writes it.
const char* integrator_name(int integrator);

}  // namespace pegasus
