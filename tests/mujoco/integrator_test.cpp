// The rollout steps as the MJCF asks (issue 52): for each of MuJoCo's integrators a rollout's states are bit
// for bit those of MuJoCo's own mj_step loop with the same ctrl, with zero and with nonzero actions,
// contacts, activation dynamics and frame_skip > 1.
#ifdef PEGASUS_HAVE_MUJOCO
#include <fmt/format.h>
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

// A box that falls onto the floor (contacts) and slides on it, pushed by a motor, with an arm on a damped
// hinge driven through a first-order activation (act). Gravity, friction, damping and a filter: every part of
// the step that the integrators treat differently.
std::string sled_xml(const std::string& integrator) {
  return fmt::format(R"(
<mujoco><option timestep="0.004" integrator="{}"/>
  <worldbody><geom type="plane" size="5 5 0.1"/>
    <body name="sled" pos="0 0 0.25"><joint name="slide" type="slide" axis="1 0 0" damping="0.5"/>
      <joint name="lift" type="slide" axis="0 0 1"/>
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
      <body name="arm" pos="0 0 0.1"><joint name="hinge" type="hinge" axis="0 1 0" damping="0.2"/>
        <geom type="capsule" fromto="0 0 0 0 0 0.5" size="0.03" mass="0.3"/>
        <site name="tip" pos="0 0 0.5"/></body></body></worldbody>
  <actuator><motor joint="slide" ctrllimited="true" ctrlrange="-5 5"/>
    <general joint="hinge" dyntype="filter" dynprm="0.05" gainprm="2" ctrllimited="true" ctrlrange="-1 1"/>
  </actuator></mujoco>)",
                     integrator);
}

constexpr const char* kSledTask = R"(
horizon = 60
frame_skip = 3
[observation]
qpos = ["slide", "lift", "hinge"]
qvel = ["slide", "lift", "hinge"]
[[reward]]
term = "displacement"
body = "sled"
[[reward]]
term = "contact_cost"
weight = -1e-4
[[reward]]
term = "body_velocity"
body = "arm"
point = "site:tip"
)";

struct Trajectory {
  std::vector<std::vector<double>> states;  // (time, qpos, qvel, act) after the reset and every control step
  std::vector<std::vector<double>> actions;
  std::vector<double> rewards;
};

std::vector<double> state_of(const mjModel* m, const mjData* d) {
  std::vector<double> s = {d->time};
  s.insert(s.end(), d->qpos, d->qpos + m->nq);
  s.insert(s.end(), d->qvel, d->qvel + m->nv);
  s.insert(s.end(), d->act, d->act + m->na);
  return s;
}

Trajectory rollout(const MujocoEnvironment& env, const Theta& theta) {
  const mjModel* m = env.model().get();
  const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
  Trajectory out;
  const MujocoStepObserver record = [&](int t, const mjData* d, std::span<const double> action,
                                        double reward) {
    out.states.push_back(state_of(m, d));
    if (t > 0) {
      out.actions.emplace_back(action.begin(), action.end());
      out.rewards.push_back(reward);
    }
  };
  MujocoSlot slot(env);
  env.rollout(*policy, theta, ObservationNormalizer(env.observation_dim()),
              env.scenarios(1, 1, ScenarioVariant::kPlain), 0, slot, nullptr, &record);
  return out;
}

// MuJoCo's own loop: from mj_resetData, each control step sets the ctrl the environment would and calls
// mj_step frame_skip times.
std::vector<std::vector<double>> reference(const MujocoEnvironment& env,
                                           const std::vector<std::vector<double>>& actions) {
  const mjModel* m = env.model().get();
  mjData* d = mj_makeData(m);
  mj_resetData(m, d);
  std::vector<std::vector<double>> states = {state_of(m, d)};
  for (const auto& action : actions) {
    for (int k = 0; k < m->nu; ++k) {
      const double lo = m->actuator_ctrlrange[2 * k], hi = m->actuator_ctrlrange[2 * k + 1];
      d->ctrl[k] =
          0.5 * (lo + hi) + 0.5 * (hi - lo) * std::clamp(action[static_cast<std::size_t>(k)], -1.0, 1.0);
    }
    for (int k = 0; k < env.task().frame_skip; ++k) mj_step(m, d);
    states.push_back(state_of(m, d));
  }
  mj_deleteData(d);
  return states;
}

class MujocoIntegrator : public test_support::TempDirTest, public ::testing::WithParamInterface<const char*> {
 protected:
  std::shared_ptr<const MujocoEnvironment> sled(const std::string& integrator) {
    const auto xml = test_support::write_file(dir_ / ("sled_" + integrator + ".xml"), sled_xml(integrator));
    const auto toml = test_support::write_file(dir_ / "sled.toml", kSledTask);
    return test_support::environment_of(xml, toml);
  }
};

TEST_P(MujocoIntegrator, ARolloutIsBitForBitMujocosOwnMjStepLoopWithZeroAndNonzeroActions) {
  const auto env = sled(GetParam());
  ASSERT_STREQ(env->integrator(), GetParam());
  const auto policy = make_mujoco_policy("linear", env->observation_dim(), env->action_dim(), {});
  Theta wiggly(policy->parameters().size());
  for (std::size_t k = 0; k < wiggly.size(); ++k)
    wiggly[k] = 0.7 * std::sin(1.3 * static_cast<double>(k) + 0.4);
  for (const bool moving : {false, true}) {
    SCOPED_TRACE(moving ? "nonzero actions" : "zero actions");
    const Trajectory ours = rollout(*env, moving ? wiggly : Theta(wiggly.size(), 0.0));
    ASSERT_EQ(ours.actions.size(), 60u);
    const auto theirs = reference(*env, ours.actions);
    ASSERT_EQ(ours.states.size(), theirs.size());
    for (std::size_t t = 0; t < theirs.size(); ++t)
      ASSERT_EQ(ours.states[t], theirs[t]) << "control step " << t;
    double largest = 0.0;
    for (const auto& a : ours.actions) largest = std::max({largest, std::abs(a[0]), std::abs(a[1])});
    EXPECT_EQ(largest > 0.1, moving);
  }
}

INSTANTIATE_TEST_SUITE_P(EveryIntegrator, MujocoIntegrator, ::testing::Values("Euler", "RK4", "implicit"));

TEST_F(MujocoIntegrator, TheIntegratorsGiveDifferentTrajectoriesSoTheModelsChoiceIsFollowed) {
  // The same model by Euler, RK4 and implicit: three different end states (Euler for all would make the
  // bit-for-bit comparisons above pass for one integrator only).
  std::vector<std::vector<double>> ends;
  for (const char* integrator : {"Euler", "RK4", "implicit"}) {
    const auto env = sled(integrator);
    const auto policy = make_mujoco_policy("linear", env->observation_dim(), env->action_dim(), {});
    ends.push_back(rollout(*env, Theta(policy->parameters().size(), 0.1)).states.back());
  }
  EXPECT_NE(ends[0], ends[1]);
  EXPECT_NE(ends[0], ends[2]);
  EXPECT_NE(ends[1], ends[2]);
}

TEST_F(MujocoIntegrator, EveryStepsObservationAndRewardSeeTheNewStateUnderRk4) {
  // RK4 leaves its last stage's kinematics in mjData; the observation's site position and the reward's site
  // velocity must be the new state's, as mj_forward computes them from (qpos, qvel, act).
  const auto xml = test_support::write_file(dir_ / "sled.xml", sled_xml("RK4"));
  const auto toml = test_support::write_file(dir_ / "tip.toml", R"(
frame_skip = 2
[observation]
site_pos = ["tip"]
[[reward]]
term = "body_velocity"
body = "arm"
point = "site:tip"
)");
  const auto env = test_support::environment_of(xml, toml);
  const mjModel* m = env->model().get();
  const int tip = mj_name2id(m, mjOBJ_SITE, "tip");
  MujocoSlot slot(*env);
  env->reset(slot, {});
  mjData* check = mj_makeData(m);
  const std::vector<double> action = {0.8, -0.6};
  std::vector<double> observed(3);
  for (int t = 0; t < 20; ++t) {
    const MujocoStepOutcome step = env->step(slot, action, {});
    mju_copy(check->qpos, slot.data->qpos, m->nq);
    mju_copy(check->qvel, slot.data->qvel, m->nv);
    mju_copy(check->act, slot.data->act, m->na);
    mju_copy(check->ctrl, slot.data->ctrl, m->nu);
    mj_forward(m, check);
    env->observe(slot, observed);
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(observed[static_cast<std::size_t>(k)], check->site_xpos[3 * tip + k]);
    mjtNum v[6];
    mj_objectVelocity(m, check, mjOBJ_SITE, tip, v, 0);
    ASSERT_EQ(step.reward, v[3]) << t;
  }
  EXPECT_GT(std::abs(slot.data->qvel[2]), 0.1);  // the arm swings: the velocities checked are not all zero
  mj_deleteData(check);
}

// A rollout without an observer lets an RK4 step skip what the task does not read of the new state (all of
// mj_step1 when the task reads qpos and qvel only, all but the kinematics when it reads positions): its
// returns, steps and success are bit for bit those of a rollout that computes everything (with an observer).
TEST_F(MujocoIntegrator, AnRk4RolloutThatSkipsWhatTheTaskDoesNotReadReturnsWhatOneComputingItReturns) {
  const auto xml = test_support::write_file(dir_ / "sled.xml", sled_xml("RK4"));
  const std::vector<std::string> tasks = {
      // qpos and qvel only, with a termination on a qpos (the hopper's kind)
      R"(horizon = 80
frame_skip = 3
[observation]
qpos = ["slide", "hinge"]
qvel = ["slide", "lift", "hinge"]
[[reward]]
term = "joint_speed"
joint = "hinge"
weight = -0.5
[[reward]]
term = "healthy"
[[termination]]
quantity = "qpos"
name = "hinge"
min = -0.6
max = 0.6
)",
      // positions: Gymnasium's displacement of a body's origin, a site in the observation, a site's height
      R"(horizon = 80
frame_skip = 3
[observation]
qpos = ["slide"]
site_pos = ["tip"]
[[reward]]
term = "displacement"
body = "sled"
point = "origin"
axis = 0
[[reward]]
term = "site_distance"
site = "tip"
target = [0.5, 0.0, 0.4]
weight = -1.0
[[termination]]
quantity = "site_height"
name = "tip"
min = 0.3
max = inf
)",
      kSledTask};
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    SCOPED_TRACE(tasks[k]);
    const auto toml = test_support::write_file(dir_ / fmt::format("task{}.toml", k), tasks[k]);
    const auto env = test_support::environment_of(xml, toml);
    const auto policy = make_mujoco_policy("linear", env->observation_dim(), env->action_dim(), {});
    Theta theta(policy->parameters().size());
    for (std::size_t j = 0; j < theta.size(); ++j)
      theta[j] = 0.9 * std::sin(0.7 * static_cast<double>(j) + 1.1);
    const ObservationNormalizer normalizer(env->observation_dim());
    const ScenarioSet scenarios = env->scenarios(3, 1, ScenarioVariant::kPlain);
    MujocoSlot slot(*env);
    const MujocoStepObserver watch = [](int, const mjData*, std::span<const double>, double) {};
    const auto computed = env->rollout(*policy, theta, normalizer, scenarios, 0, slot, nullptr, &watch);
    const auto skipped = env->rollout(*policy, theta, normalizer, scenarios, 0, slot);
    EXPECT_EQ(skipped.discounted_return, computed.discounted_return);
    EXPECT_EQ(skipped.training_return, computed.training_return);
    EXPECT_EQ(skipped.steps, computed.steps);
    EXPECT_EQ(skipped.crashed, computed.crashed);
  }
}

}  // namespace
}  // namespace pegasus
#endif
