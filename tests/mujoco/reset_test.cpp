// A rollout resets its slot to mj_resetData's state without mj_resetData's cost (it restores only what the
// steps read): a run of rollouts on one reused slot returns, bit for bit, what each returns on a fresh slot
// (mj_makeData, which calls mj_resetData), after rollouts that moved, terminated and crashed, on models with
// contacts, activations, muscles, a mocap body and an acceleration sensor in the observation.
#ifdef PEGASUS_HAVE_MUJOCO
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "mujoco_test_support.hpp"
#include "support/cli_runner.hpp"

namespace pegasus {
namespace {

// A cart on a rail with a pole and an accelerometer on the pole's tip (an acceleration-stage sensor, which
// the reset's mj_step1 does not compute: mj_resetData leaves it 0), a mocap target, a filtered actuator
// (act), and a motor strong enough at full control to make MuJoCo flag a bad acceleration (a crash).
constexpr const char* kCartXml = R"(
<mujoco><option timestep="0.005"/>
  <worldbody><geom type="plane" size="5 5 0.1"/>
    <body name="target" mocap="true" pos="0.3 0.2 1"><geom type="sphere" size="0.05" contype="0" conaffinity="0"/></body>
    <body name="cart" pos="0 0 0.1"><joint name="rail" type="slide" axis="1 0 0" damping="0.3"/>
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
      <body name="pole"><joint name="hinge" type="hinge" axis="0 1 0" damping="0.05"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.6" size="0.03" mass="0.2"/>
        <site name="tip" pos="0 0 0.6"/></body></body></worldbody>
  <actuator><motor joint="rail" ctrllimited="true" ctrlrange="-1 1" gear="20"/>
    <motor name="blast" joint="rail" ctrllimited="true" ctrlrange="0 1" gear="1e13"/>
    <general joint="hinge" dyntype="filter" dynprm="0.05" gainprm="1" ctrllimited="true" ctrlrange="-1 1"/>
  </actuator>
  <sensor><accelerometer name="tip_acc" site="tip"/></sensor></mujoco>)";

constexpr const char* kCartTask = R"(
horizon = 50
frame_skip = 2
[initial]
qpos_noise = 0.1
qvel_noise = 0.1
[observation]
qpos = ["rail", "hinge"]
qvel = ["rail", "hinge"]
sensors = ["tip_acc"]
[[reward]]
term = "site_distance"
site = "tip"
target = [0.0, 0.0, 0.7]
weight = -1.0
[[reward]]
term = "healthy"
[[termination]]
quantity = "qpos"
name = "hinge"
min = -1.0
max = 1.0
)";

struct Outcome {
  MujocoRolloutResult result;
  std::vector<double> end;  // time, qpos, qvel, act, sensordata after the last step
};

Outcome run(const MujocoEnvironment& env, const MujocoPolicy& policy, const Theta& theta,
            const ScenarioSet& scenarios, int i, MujocoSlot& slot) {
  const mjModel* m = env.model().get();
  const mjData* d = slot.data;
  Outcome out{env.rollout(policy, theta, ObservationNormalizer(env.observation_dim()), scenarios, i, slot),
              {}};
  out.end = {d->time};
  for (const auto& [array, size] : {std::pair{d->qpos, m->nq}, std::pair{d->qvel, m->nv},
                                    std::pair{d->act, m->na}, std::pair{d->sensordata, m->nsensordata}})
    out.end.insert(out.end.end(), array, array + size);
  return out;
}

// Rollouts of every theta on every scenario, in turn on one slot, each against the same on a fresh slot;
// returns how many crashed and how many ended before the horizon.
std::pair<int, int> expect_reused_slot_matches_fresh(const MujocoEnvironment& env,
                                                     const std::vector<Theta>& thetas) {
  const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
  const ScenarioSet scenarios = env.scenarios(7, 3, ScenarioVariant::kPlain);
  MujocoSlot reused(env);
  int crashed = 0, terminated = 0;
  for (std::size_t k = 0; k < thetas.size(); ++k) {
    for (int i = 0; i < scenarios.size(); ++i) {
      SCOPED_TRACE(testing::Message() << "theta " << k << ", scenario " << i);
      MujocoSlot fresh(env);
      const Outcome want = run(env, *policy, thetas[k], scenarios, i, fresh);
      const Outcome got = run(env, *policy, thetas[k], scenarios, i, reused);
      EXPECT_EQ(got.result.discounted_return, want.result.discounted_return);
      EXPECT_EQ(got.result.training_return, want.result.training_return);
      EXPECT_EQ(got.result.steps, want.result.steps);
      EXPECT_EQ(got.result.crashed, want.result.crashed);
      EXPECT_EQ(got.result.success, want.result.success);
      EXPECT_EQ(got.end, want.end);
      crashed += want.result.crashed ? 1 : 0;
      terminated += want.result.steps < env.task().horizon ? 1 : 0;
    }
  }
  return {crashed, terminated};
}

// Thetas of a linear policy (rows (W_k, b_k) of d + 1): `weights` times a fixed wiggle, and, when
// `blast` is not 0, the blast motor's (actuator 1's) row zero but for its bias `blast`.
Theta wiggle(const MujocoEnvironment& env, double weights, double blast) {
  const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
  Theta theta(policy->parameters().size());
  for (std::size_t j = 0; j < theta.size(); ++j)
    theta[j] = weights * std::sin(1.7 * static_cast<double>(j) + 0.3);
  if (blast != 0.0) {
    const std::size_t row = static_cast<std::size_t>(env.observation_dim()) + 1;
    std::fill_n(theta.begin() + static_cast<std::ptrdiff_t>(row), row, 0.0);
    theta[2 * row - 1] = blast;
  }
  return theta;
}

class MujocoReset : public test_support::TempDirTest {};

TEST_F(MujocoReset, AReusedSlotAfterMovingTerminatedAndCrashedRolloutsReturnsWhatAFreshSlotReturns) {
  const auto xml = test_support::write_file(dir_ / "cart.xml", kCartXml);
  const auto toml = test_support::write_file(dir_ / "cart.toml", kCartTask);
  const auto env = test_support::environment_of(xml, toml);
  ASSERT_EQ(env->model().get()->nmocap, 1);
  ASSERT_EQ(env->model().get()->na, 1);
  // Still, moving, a crash (the blast motor at full control, then the observation's accelerometer and the
  // warning counters hold what it left), moving again.
  const std::vector<Theta> thetas = {wiggle(*env, 0.0, -1.0), wiggle(*env, 0.8, -1.0), wiggle(*env, 0.0, 1.0),
                                     wiggle(*env, 0.5, -1.0)};
  const auto [crashed, terminated] = expect_reused_slot_matches_fresh(*env, thetas);
  EXPECT_EQ(crashed, 3);  // every scenario of the blasting theta
  EXPECT_GE(terminated, 4);
}

TEST_F(MujocoReset, ShippedModelsWithContactsAndMusclesReturnWhatAFreshSlotReturns) {
  const auto dir = test_support::mujoco_experiments();
  for (const auto& [xml, task] : {std::pair<std::string, std::string>{"hopper.xml", "hopper_forward.toml"},
                                  {"cartpole.xml", "cartpole_swingup.toml"},
                                  {"/usr/share/mujoco/model/tendon_arm/arm26.xml", "arm26_posture.toml"}}) {
    SCOPED_TRACE(xml);
    const auto env = test_support::environment_of(dir / xml, dir / task);
    expect_reused_slot_matches_fresh(*env, {wiggle(*env, 0.6, 0.0), wiggle(*env, -0.3, 0.0)});
  }
}

}  // namespace
}  // namespace pegasus
#endif
