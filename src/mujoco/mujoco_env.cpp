#include "pegasus/mujoco/mujoco_env.hpp"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pegasus/core/error.hpp"

namespace pegasus {

MujocoSlot::MujocoSlot(const MujocoEnvironment& env)
    : data(mj_makeData(env.model().get())),
      observation(static_cast<std::size_t>(env.observation_dim())),
      normalized(static_cast<std::size_t>(env.observation_dim())),
      action(static_cast<std::size_t>(env.action_dim())),
      initial_noise(static_cast<std::size_t>(env.initial_noise_dim())),
      step_noise(static_cast<std::size_t>(env.noise_dim())),
      displacement_before(static_cast<std::size_t>(env.task().displacement_terms)),
      warmstart(static_cast<std::size_t>(env.model().get()->nv)) {
  if (!data) throw std::runtime_error("mujoco: mj_makeData failed");
}

MujocoSlot::~MujocoSlot() { mj_deleteData(data); }

namespace {

bool reads_positions(const TerminationRange& range) {
  return range.kind == QuantityKind::kBodyHeight || range.kind == QuantityKind::kSiteHeight;
}

}  // namespace

// After an RK4 step mjData holds the last stage's quantities, not the new state's, and the next mj_step
// computes the new state's itself: a rollout needs only what the task reads of them. Body and site
// positions (displacement, site distance, heights, site observations) need the kinematics; velocities of
// bodies, energy, contacts, sensors and a hook (which may read anything) the whole mj_step1; qpos and qvel
// nothing. Gymnasium's RK4 models read only qpos, qvel and the torso's position: the mj_step1 their steps
// skip was 3-5% of a control step (bench/mujoco_bench.cpp, BM_MujocoOverhead_Gym*).
MujocoEnvironment::AfterRk4Step MujocoEnvironment::after_rk4_step_needs(const MujocoTask& task,
                                                                        bool has_hook) {
  if (has_hook) return AfterRk4Step::kStep1;
  bool kinematics = false;
  for (const auto& term : task.reward) {
    switch (term.kind) {
      case RewardKind::kBodyVelocity:
      case RewardKind::kEnergy:
      case RewardKind::kContactCost:
        return AfterRk4Step::kStep1;
      case RewardKind::kDisplacement:
      case RewardKind::kSiteDistance:
        kinematics = true;
        break;
      case RewardKind::kInRange:
        kinematics = kinematics || reads_positions(term.range);
        break;
      case RewardKind::kHealthy:
      case RewardKind::kJointTarget:
      case RewardKind::kJointSpeed:
      case RewardKind::kJointVelocity:
      case RewardKind::kControlCost:
        break;
    }
  }
  for (const auto& item : task.observation) {
    switch (item.kind) {
      case ObservationKind::kSensor:
      case ObservationKind::kBodyLinearVelocity:
        return AfterRk4Step::kStep1;
      case ObservationKind::kSitePos:
        kinematics = true;
        break;
      case ObservationKind::kQpos:
      case ObservationKind::kQposSinCos:
      case ObservationKind::kQvel:
        break;
    }
  }
  for (const auto& range : task.termination) kinematics = kinematics || reads_positions(range);
  for (const auto& range : task.success_ranges) kinematics = kinematics || reads_positions(range);
  return kinematics ? AfterRk4Step::kKinematics : AfterRk4Step::kNothing;
}

MujocoEnvironment::MujocoEnvironment(MujocoModel model, MujocoTask task, RewardHook hook)
    : model_(std::move(model)), task_(std::move(task)), hook_(std::move(hook)) {
  const mjModel* m = model_.get();
  observation_dim_ = task_.observation_dim();
  const bool perturb = task_.initial_qpos_noise > 0.0 || task_.initial_qvel_noise > 0.0;
  initial_noise_dim_ = perturb ? m->nq + m->nv : 0;
  noise_dim_ = (task_.actuator_noise > 0.0 ? m->nu : 0) + 4 * static_cast<int>(task_.push_bodies.size());
  for (const auto& term : task_.reward)
    contact_cost_ = contact_cost_ || term.kind == RewardKind::kContactCost;
  // mj_step2 integrates as mj_step does for Euler and implicit, but RK4 by Euler (MuJoCo's engine_forward.c).
  split_step_ = m->opt.integrator != mjINT_RK4;
  for (int k = 0; k < m->nu; ++k) {
    // An unlimited actuator takes a in [-1, 1] as its ctrl directly.
    const bool limited = m->actuator_ctrllimited[k] != 0;
    const double lo = limited ? m->actuator_ctrlrange[2 * k] : -1.0;
    const double hi = limited ? m->actuator_ctrlrange[2 * k + 1] : 1.0;
    ctrl_mid_.push_back(0.5 * (lo + hi));
    ctrl_half_.push_back(0.5 * (hi - lo));
  }
  control_dt_ = task_.frame_skip * m->opt.timestep;
  after_rk4_step_ = after_rk4_step_needs(task_, static_cast<bool>(hook_));
}

int MujocoEnvironment::action_dim() const { return model_.get()->nu; }

const char* MujocoEnvironment::integrator() const { return integrator_name(model_.get()->opt.integrator); }

const char* integrator_name(int integrator) {
  switch (integrator) {
    case mjINT_EULER:
      return "Euler";
    case mjINT_RK4:
      return "RK4";
    case mjINT_IMPLICIT:
      return "implicit";
    default:
      return "unknown";
  }
}

ScenarioSet MujocoEnvironment::scenarios(std::uint64_t seed, int count, ScenarioVariant variant) const {
  return ScenarioSet(ScenarioOptions{.seed = seed,
                                     .count = count,
                                     .horizon = task_.horizon,
                                     .noise_dim = noise_dim_,
                                     .initial_noise_dim = initial_noise_dim_,
                                     .variant = variant});
}

namespace {

// mj_resetData's state without its cost: MuJoCo 2.2's mj_resetData zeroes the whole mjData buffer (3 MB for
// the cart-pole, mostly constraint arrays sized by njmax: 46 us, 3% of a 400-step rollout). A state that
// went through mj_resetData once (mj_makeData does) needs only what the next mj_step reads before writing:
// the integration state (time, qpos = qpos0, qvel, act, the warm start, ctrl, applied forces, mocap, user
// data; MuJoCo 3's mjSTATE_INTEGRATION), the warning counters the crash check reads, and the quantities
// computed only when a sensor asks (acceleration-stage sensors, subtree velocities, com accelerations and
// forces), zero as mj_resetData leaves them. tests/mujoco/integrator_test.cpp compares rollouts after this
// and after mj_resetData bit for bit; MuJoCo 3, whose buffer layout differs, keeps mj_resetData.
void restore_reset_state(const mjModel* m, mjData* d) {
#if mjVERSION_HEADER < 300
  d->pstack = 0;
  std::fill(std::begin(d->warning), std::end(d->warning), mjWarningStat{});
  std::fill(std::begin(d->timer), std::end(d->timer), mjTimerStat{});
  std::fill(std::begin(d->solver), std::end(d->solver), mjSolverStat{});
  d->solver_iter = 0;
  d->solver_nnz = 0;
  mju_zero(d->solver_fwdinv, 2);
  d->ne = d->nf = d->nefc = d->ncon = 0;
  d->time = 0;
  mju_zero(d->energy, 2);
  mju_copy(d->qpos, m->qpos0, m->nq);
  for (mjtNum* zeroed : {d->qvel, d->qacc_warmstart, d->qfrc_applied, d->qacc, d->qfrc_inverse})
    mju_zero(zeroed, m->nv);
  mju_zero(d->act, m->na);
  mju_zero(d->act_dot, m->na);
  mju_zero(d->ctrl, m->nu);
  mju_zero(d->userdata, m->nuserdata);
  mju_zero(d->sensordata, m->nsensordata);
  for (mjtNum* zeroed : {d->xfrc_applied, d->cacc, d->cfrc_int, d->cfrc_ext}) mju_zero(zeroed, 6 * m->nbody);
  mju_zero(d->subtree_linvel, 3 * m->nbody);
  mju_zero(d->subtree_angmom, 3 * m->nbody);
  for (int body = 0; body < m->nbody; ++body) {
    const int mocap = m->body_mocapid[body];
    if (mocap < 0) continue;
    mju_copy3(d->mocap_pos + 3 * mocap, m->body_pos + 3 * body);
    mju_copy4(d->mocap_quat + 4 * mocap, m->body_quat + 4 * body);
  }
#else
  mj_resetData(m, d);
#endif
}

}  // namespace

void MujocoEnvironment::reset(MujocoSlot& slot, std::span<const double> p0) const {
  reset_to(slot, p0, true);
}

void MujocoEnvironment::reset_to(MujocoSlot& slot, std::span<const double> p0, bool complete) const {
  const mjModel* m = model_.get();
  mjData* d = slot.data;
  if (complete)
    mj_resetData(m, d);
  else
    restore_reset_state(m, d);
  for (const auto& [adr, value] : task_.initial_qpos) d->qpos[adr] = value;
  if (initial_noise_dim_ > 0) {
    for (int j = 0; j < m->nq; ++j)
      d->qpos[j] += task_.initial_qpos_noise * (2.0 * p0[static_cast<std::size_t>(j)] - 1.0);
    for (int j = 0; j < m->nv; ++j)
      d->qvel[j] += task_.initial_qvel_noise * (2.0 * p0[static_cast<std::size_t>(m->nq + j)] - 1.0);
  }
  mj_step1(m, d);
}

bool MujocoEnvironment::healthy(const mjData* d) const { return inside(task_.termination, d); }

bool MujocoEnvironment::inside(std::span<const TerminationRange> ranges, const mjData* d) {
  for (const auto& range : ranges) {
    double x = 0.0;
    switch (range.kind) {
      case QuantityKind::kQpos:
        x = d->qpos[range.adr];
        break;
      case QuantityKind::kQvel:
        x = d->qvel[range.adr];
        break;
      case QuantityKind::kBodyHeight:
        x = d->xpos[3 * range.id + 2];
        break;
      case QuantityKind::kSiteHeight:
        x = d->site_xpos[3 * range.id + 2];
        break;
    }
    if (!range.contains(x)) return false;
  }
  return true;
}

namespace {

bool unstable(const mjModel* m, const mjData* d) {
  if (d->warning[mjWARN_BADQPOS].number > 0 || d->warning[mjWARN_BADQVEL].number > 0 ||
      d->warning[mjWARN_BADQACC].number > 0)
    return true;
  for (int j = 0; j < m->nq; ++j)
    if (!std::isfinite(d->qpos[j])) return true;
  for (int j = 0; j < m->nv; ++j)
    if (!std::isfinite(d->qvel[j])) return true;
  return false;
}

// The world-frame linear velocity of the body's centre of mass (mjOBJ_BODY is the inertial frame, xipos).
double body_linear_velocity(const mjModel* m, const mjData* d, int body, int axis) {
  mjtNum velocity[6];  // (angular, linear), world orientation, at the body's centre of mass
  mj_objectVelocity(m, d, mjOBJ_BODY, body, velocity, 0);
  return velocity[3 + axis];
}

// The velocity of the term's point of its body (BodyPoint), world frame, along its axis.
double point_velocity(const mjModel* m, const mjData* d, const RewardTerm& term) {
  mjtNum velocity[6];  // (angular, linear), world orientation, at the point
  switch (term.point) {
    case BodyPoint::kCom:
      mj_objectVelocity(m, d, mjOBJ_BODY, term.id, velocity, 0);
      break;
    case BodyPoint::kOrigin:
      mj_objectVelocity(m, d, mjOBJ_XBODY, term.id, velocity, 0);
      break;
    case BodyPoint::kSite:
      mj_objectVelocity(m, d, mjOBJ_SITE, term.site, velocity, 0);
      break;
  }
  return velocity[3 + term.axis];
}

// The world-frame position of the term's point along its axis.
double point_position(const mjData* d, const RewardTerm& term) {
  switch (term.point) {
    case BodyPoint::kCom:
      return d->xipos[3 * term.id + term.axis];
    case BodyPoint::kOrigin:
      return d->xpos[3 * term.id + term.axis];
    case BodyPoint::kSite:
      return d->site_xpos[3 * term.site + term.axis];
  }
  return 0.0;
}

double contact_force_squared(const mjModel* m, const mjData* d) {
  double sum = 0.0;
  for (int c = 0; c < d->ncon; ++c) {
    mjtNum force[6];
    mj_contactForce(m, d, c, force);
    sum += force[0] * force[0] + force[1] * force[1] + force[2] * force[2];
  }
  return sum;
}

}  // namespace

MujocoStepOutcome MujocoEnvironment::step(MujocoSlot& slot, std::span<const double> action,
                                          std::span<const double> p) const {
  return step_to(slot, action, p, true);
}

// The step's parts are inlined into it: a rollout's per-step overhead is what the throughput bar measures.
[[gnu::always_inline]] inline void MujocoEnvironment::apply_controls(MujocoSlot& slot,
                                                                     std::span<const double> action,
                                                                     std::span<const double> p) const {
  const mjModel* m = model_.get();
  mjData* d = slot.data;
  std::size_t next = 0;
  for (int k = 0; k < m->nu; ++k) {
    const auto ku = static_cast<std::size_t>(k);
    double ctrl = ctrl_mid_[ku] + ctrl_half_[ku] * std::clamp(action[ku], -1.0, 1.0);
    if (task_.actuator_noise > 0.0) ctrl += task_.actuator_noise * ctrl_half_[ku] * (2.0 * p[next++] - 1.0);
    d->ctrl[k] = ctrl;
  }
  for (const int body : task_.push_bodies) {
    const bool push = p[next] < task_.push_probability;
    for (int axis = 0; axis < 3; ++axis)
      d->xfrc_applied[6 * body + axis] =
          push ? task_.push_force * (2.0 * p[next + 1 + static_cast<std::size_t>(axis)] - 1.0) : 0.0;
    next += 4;
  }
}

// frame_skip physics steps by the model's integrator; the contact cost of the step when a term needs it.
[[gnu::always_inline]] inline double MujocoEnvironment::integrate(MujocoSlot& slot, bool complete) const {
  const mjModel* m = model_.get();
  mjData* d = slot.data;
  double contact_cost = 0.0;
  if (split_step_) {
    // Euler and implicit: the state already went through mj_step1 (the reset, or the end of the last control
    // step) and the ctrl is set, so mj_step2 finishes the first mj_step; then frame_skip - 1 whole mj_step
    // calls; then mj_step1 computes the position- and velocity-dependent quantities of the new state for the
    // observation and the reward, which the next mj_step2 uses. The states are bit for bit those of
    // frame_skip mj_step calls (tests/mujoco/integrator_test.cpp) at the cost of frame_skip of them.
    mj_step2(m, d);
    for (int k = 1; k < task_.frame_skip; ++k) mj_step(m, d);
    // Contact forces of the step just integrated, before mj_step1 rebuilds the contacts of the new state.
    if (contact_cost_) contact_cost = contact_force_squared(m, d);
    mj_step1(m, d);
  } else {
    // RK4: mj_step2 would integrate by Euler, so whole mj_step calls; RK4 leaves its last stage's
    // quantities in mjData, so mj_step1 computes the new state's (it changes no state: the next mj_step
    // recomputes them from it). Contact forces: those of the new state under this step's ctrl.
    for (int k = 0; k < task_.frame_skip; ++k) mj_step(m, d);
    if (complete || after_rk4_step_ == AfterRk4Step::kStep1)
      mj_step1(m, d);
    else if (after_rk4_step_ == AfterRk4Step::kKinematics)
      mj_kinematics(m, d);
    if (contact_cost_) {
      // The constraint solver leaves its result as the next solve's warm start: the next mj_step must
      // start from RK4's, as in a plain mj_step loop.
      mju_copy(slot.warmstart.data(), d->qacc_warmstart, m->nv);
      mj_forwardSkip(m, d, mjSTAGE_VEL, 0);
      contact_cost = contact_force_squared(m, d);
      mju_copy(d->qacc_warmstart, slot.warmstart.data(), m->nv);
    }
  }
  return contact_cost;
}

// One reward term's value at the new state (before its weight and cap).
[[gnu::always_inline]] inline double MujocoEnvironment::term_value(const RewardTerm& term,
                                                                   const MujocoSlot& slot,
                                                                   std::span<const double> action,
                                                                   double contact_cost,
                                                                   bool is_healthy) const {
  const mjModel* m = model_.get();
  mjData* d = slot.data;  // mj_energyPos and mj_energyVel write d->energy
  double value = 0.0;
  switch (term.kind) {
    case RewardKind::kBodyVelocity:
      value = point_velocity(m, d, term);
      break;
    case RewardKind::kDisplacement:
      value = (point_position(d, term) - slot.displacement_before[static_cast<std::size_t>(term.slot)]) /
              control_dt_;
      break;
    case RewardKind::kJointVelocity:
      value = d->qvel[term.adr];
      break;
    case RewardKind::kHealthy:
      value = is_healthy ? 1.0 : 0.0;
      break;
    case RewardKind::kSiteDistance: {
      const double* x = d->site_xpos + 3 * term.id;
      const double dx = x[0] - term.target[0], dy = x[1] - term.target[1], dz = x[2] - term.target[2];
      value = std::sqrt(dx * dx + dy * dy + dz * dz);
      break;
    }
    case RewardKind::kJointTarget:
      value = std::abs(d->qpos[term.adr] - term.target[0]);
      break;
    case RewardKind::kJointSpeed:
      value = std::abs(d->qvel[term.adr]);
      break;
    case RewardKind::kInRange:
      value = inside(std::span<const TerminationRange>(&term.range, 1), d) ? 1.0 : 0.0;
      break;
    case RewardKind::kEnergy:
      // mj_step1 left the mass matrix and positions of this state in d.
      mj_energyPos(m, d);
      mj_energyVel(m, d);
      value = std::abs(d->energy[0] + d->energy[1] - term.target[0]);
      break;
    case RewardKind::kControlCost:
      for (const double a : action) value += std::clamp(a, -1.0, 1.0) * std::clamp(a, -1.0, 1.0);
      break;
    case RewardKind::kContactCost:
      value = contact_cost;
      break;
  }
  return value;
}

MujocoStepOutcome MujocoEnvironment::step_to(MujocoSlot& slot, std::span<const double> action,
                                             std::span<const double> p, bool complete) const {
  const mjModel* m = model_.get();
  mjData* d = slot.data;
  apply_controls(slot, action, p);

  // The positions displacement terms start from: those of the current state (the reset's mj_step1, or what
  // the last step computed of its new state, which includes the kinematics wherever a displacement is read).
  if (task_.displacement_terms > 0)
    for (const auto& term : task_.reward)
      if (term.kind == RewardKind::kDisplacement)
        slot.displacement_before[static_cast<std::size_t>(term.slot)] = point_position(d, term);

  const double contact_cost = integrate(slot, complete);

  MujocoStepOutcome out;
  if (unstable(m, d)) {
    out.reward = out.training_reward = task_.crash_penalty;
    out.terminal = out.crashed = true;
    return out;
  }
  const bool is_healthy = healthy(d);
  double reward = 0.0, training_only = 0.0;
  for (const auto& term : task_.reward) {
    const double value = term_value(term, slot, action, contact_cost, is_healthy);
    (term.training_only ? training_only : reward) += term.weight * std::min(value, term.cap);
  }
  if (hook_) reward += hook_(m, d, action);
  out.reward = is_healthy ? reward : reward + task_.termination_penalty;
  out.training_reward = out.reward + training_only;
  out.terminal = !is_healthy;
  return out;
}

void MujocoEnvironment::observe(const MujocoSlot& slot, std::span<double> out) const {
  const mjModel* m = model_.get();
  const mjData* d = slot.data;
  std::size_t k = 0;
  for (const auto& item : task_.observation) {
    switch (item.kind) {
      case ObservationKind::kQpos:
        for (int j = 0; j < item.dim; ++j) out[k++] = d->qpos[item.adr + j];
        break;
      case ObservationKind::kQposSinCos: {
        // glibc's sincos gives exactly std::sin and std::cos in one call (checked on 5e7 angles): about a
        // per cent of the cart-pole's step.
        double sine = 0.0, cosine = 0.0;
        ::sincos(d->qpos[item.adr], &sine, &cosine);
        out[k++] = cosine;
        out[k++] = sine;
        break;
      }
      case ObservationKind::kQvel:
        for (int j = 0; j < item.dim; ++j) out[k++] = d->qvel[item.adr + j];
        break;
      case ObservationKind::kSensor:
        for (int j = 0; j < item.dim; ++j) out[k++] = d->sensordata[item.adr + j];
        break;
      case ObservationKind::kSitePos:
        for (int j = 0; j < 3; ++j) out[k++] = d->site_xpos[3 * item.id + j];
        break;
      case ObservationKind::kBodyLinearVelocity:
        for (int j = 0; j < 3; ++j) out[k++] = body_linear_velocity(m, d, item.id, j);
        break;
    }
    if (item.raw_clip < std::numeric_limits<double>::infinity())
      for (std::size_t j = k - static_cast<std::size_t>(item.dim); j < k; ++j)
        out[j] = std::clamp(out[j], -item.raw_clip, item.raw_clip);
  }
}

MujocoRolloutResult MujocoEnvironment::rollout(const MujocoPolicy& policy, std::span<const double> theta,
                                               const ObservationNormalizer& normalizer,
                                               const ScenarioSet& scenarios, int i, MujocoSlot& slot,
                                               ObservationMoments* moments,
                                               const MujocoStepObserver* observer) const {
  if (slot.scratch.size() < static_cast<std::size_t>(policy.scratch_size()))
    slot.scratch.resize(static_cast<std::size_t>(policy.scratch_size()));  // once per slot and policy class
  scenarios.initial_noise(i, slot.initial_noise);
  reset_to(slot, slot.initial_noise, observer != nullptr);
  if (observer) (*observer)(0, slot.data, {}, 0.0);
  MujocoRolloutResult result;
  double weight = 1.0;
  int held = 0;          // trailing control steps that ended inside every success range
  bool reached = false;  // held reached success_hold_steps at some step
  for (int t = 0; t < task_.horizon; ++t) {
    observe(slot, slot.observation);
    if (moments) moments->add(slot.observation);
    normalizer.apply(slot.observation, slot.normalized);
    policy.act(theta, slot.observation, slot.normalized, slot.action, slot.scratch);
    scenarios.step_noise(i, t, slot.step_noise);
    const MujocoStepOutcome outcome = step_to(slot, slot.action, slot.step_noise, observer != nullptr);
    result.discounted_return += weight * outcome.reward;
    result.training_return += weight * outcome.training_reward;
    weight *= task_.discount;
    ++result.steps;
    if (observer) (*observer)(t + 1, slot.data, slot.action, outcome.reward);
    if (outcome.terminal) {
      result.crashed = outcome.crashed;
      break;
    }
    if (!task_.success_ranges.empty()) {
      held = inside(task_.success_ranges, slot.data) ? held + 1 : 0;
      reached = reached || held >= task_.success_hold_steps;
    }
  }
  // NaN (no bar on the return) compares false: without [success] ranges nothing succeeds.
  result.success = result.discounted_return >= task_.success_return;
  if (!task_.success_ranges.empty())
    result.success =
        result.success && !result.crashed &&
        (task_.success_anywhere ? reached
                                : result.steps == task_.horizon && held >= task_.success_hold_steps);
  // The bonus joins the last step's reward after the bar on the return was checked without it.
  if (result.success && task_.success_bonus != 0.0) {
    const double bonus = std::pow(task_.discount, result.steps - 1) * task_.success_bonus;
    result.discounted_return += bonus;
    result.training_return += bonus;
  }
  return result;
}

}  // namespace pegasus
