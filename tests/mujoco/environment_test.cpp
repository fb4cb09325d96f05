// The MuJoCo environment as a deterministic simulative model: rollouts are pure functions of (theta,
// scenario), a control step is frame_skip of MuJoCo's own steps, actions land inside the ctrl ranges, and
// instability ends a rollout as a counted crash.
#ifdef PEGASUS_HAVE_MUJOCO
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <utility>

#include "mujoco_test_support.hpp"
#include "pegasus/mujoco/mujoco_objective.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace pegasus {
namespace {

Theta wiggly_theta(const MujocoPolicy& policy) {
  Theta theta(policy.parameters().size());
  for (std::size_t k = 0; k < theta.size(); ++k)
    theta[k] = 0.3 * std::sin(1.7 * static_cast<double>(k) + 0.2);
  return theta;
}

TEST(MujocoEnvironment, AControlStepIsFrameSkipPlainMjStepsFromTheSameState) {
  const auto env = test_support::cartpole_environment();
  const mjModel* m = env->model().get();
  MujocoSlot slot(*env);
  const std::vector<double> p0(static_cast<std::size_t>(env->initial_noise_dim()), 0.8);
  env->reset(slot, p0);
  // The reference: MuJoCo's own mj_step loop from a copy of the start state, with the same ctrl.
  mjData* reference = mj_makeData(m);
  mju_copy(reference->qpos, slot.data->qpos, m->nq);
  mju_copy(reference->qvel, slot.data->qvel, m->nv);
  const std::vector<double> no_noise(static_cast<std::size_t>(env->noise_dim()), 0.5);  // 2u - 1 = 0
  for (int t = 0; t < 50; ++t) {
    const double a = std::sin(0.1 * t);
    env->step(slot, std::span<const double>(&a, 1), no_noise);
    reference->ctrl[0] = a;  // ctrlrange [-1, 1]: ctrl = a
    for (int k = 0; k < env->task().frame_skip; ++k) mj_step(m, reference);
  }
  for (int j = 0; j < m->nq; ++j) EXPECT_EQ(slot.data->qpos[j], reference->qpos[j]) << j;
  for (int j = 0; j < m->nv; ++j) EXPECT_EQ(slot.data->qvel[j], reference->qvel[j]) << j;
  EXPECT_DOUBLE_EQ(slot.data->time, 50 * env->task().frame_skip * m->opt.timestep);
  mj_deleteData(reference);
}

TEST(MujocoEnvironment, ActionsMapOntoTheActuatorsCtrlRangeAndAreClipped) {
  const auto env = test_support::cartpole_environment();
  MujocoSlot slot(*env);
  const std::vector<double> p0(static_cast<std::size_t>(env->initial_noise_dim()), 0.5);
  const std::vector<double> no_noise(static_cast<std::size_t>(env->noise_dim()), 0.5);
  for (const auto& [action, ctrl] :
       std::vector<std::pair<double, double>>{{1.0, 1.0}, {-3.0, -1.0}, {0.25, 0.25}}) {
    env->reset(slot, p0);
    env->step(slot, std::span<const double>(&action, 1), no_noise);
    EXPECT_EQ(slot.data->ctrl[0], ctrl);
  }
  // Actuator noise: u = 1 adds actuator * half-range (5 % of 1) on top of a full push, beyond the range.
  const std::vector<double> full_noise(static_cast<std::size_t>(env->noise_dim()), 1.0);
  env->reset(slot, p0);
  const double a = 1.0;
  env->step(slot, std::span<const double>(&a, 1), full_noise);
  EXPECT_DOUBLE_EQ(slot.data->ctrl[0], 1.05);
}

TEST(MujocoEnvironment, ARolloutDependsOnlyOnThetaAndTheScenarioNotOnWhatTheSlotRanBefore) {
  const auto env = test_support::cartpole_environment();
  const auto policy = make_mujoco_policy("mlp", env->observation_dim(), env->action_dim(), {6});
  const Theta theta = wiggly_theta(*policy);
  const ScenarioSet scenarios = env->scenarios(11, 4, ScenarioVariant::kPlain);
  const ObservationNormalizer normalizer(env->observation_dim());
  MujocoSlot fresh(*env), used(*env);
  env->rollout(*policy, theta, normalizer, scenarios, 3, used);
  env->rollout(*policy, theta, normalizer, scenarios, 1, used);
  const auto a = env->rollout(*policy, theta, normalizer, scenarios, 2, fresh);
  const auto b = env->rollout(*policy, theta, normalizer, scenarios, 2, used);
  EXPECT_EQ(a.discounted_return, b.discounted_return);
  EXPECT_EQ(a.steps, b.steps);
  // ... and different scenarios differ (the start and the actuator noise come from the scenario).
  EXPECT_NE(env->rollout(*policy, theta, normalizer, scenarios, 0, fresh).discounted_return,
            a.discounted_return);
}

TEST(MujocoObjective, UhatAndCountsAreBitIdenticalForOneAndThreeThreads) {
  const auto env = test_support::cartpole_environment();
  std::shared_ptr<const MujocoPolicy> policy = make_mujoco_policy("linear", env->observation_dim(), 1, {});
  const Theta theta = wiggly_theta(*policy);
  std::vector<Theta> batch = {theta, Theta(theta.size(), 0.0), Theta(theta.size(), 0.5)};
  ThreadPool one(1), three(3);
  MujocoObjective a(env, policy, env->scenarios(2, 6, ScenarioVariant::kPlain), &one);
  MujocoObjective b(env, policy, env->scenarios(2, 6, ScenarioVariant::kPlain), &three);
  std::vector<double> va(3), vb(3);
  a.evaluate_batch(batch, va);
  b.evaluate_batch(batch, vb);
  EXPECT_EQ(va, vb);
  EXPECT_EQ(a.EvaluateAndUpdateNormalizer(theta), b.EvaluateAndUpdateNormalizer(theta));
  EXPECT_EQ(a.normalizer().mean, b.normalizer().mean);
  EXPECT_EQ(a.normalizer().inverse_std, b.normalizer().inverse_std);
  EXPECT_EQ(a.control_steps(), b.control_steps());
  EXPECT_EQ(a.rollouts(), 4 * 6);
  // The statistics moved off the identity: the cart-pole's cos(angle) starts near -1, not 0.
  EXPECT_LT(a.normalizer().mean[1], -0.5);
  // evaluate is the batch's first value.
  EXPECT_EQ(a.evaluate(theta), b.evaluate(theta));
}

// Records each iteration's central U-hat (measured under the statistics frozen before it) and the statistics
// in force after it.
class CentralValues final : public IterationCallback {
 public:
  explicit CentralValues(MujocoObjective& objective) : objective_(objective) {}
  CallbackReturnType operator()(const IterationReport&) override {
    values.push_back(objective_.TakeCentralValue());
    last_mean = objective_.normalizer().mean;
    return CallbackReturnType::kContinue;
  }
  std::vector<double> values, last_mean;

 private:
  MujocoObjective& objective_;
};

TEST(MujocoObjective, ArsReturnsItsBestCentralPolicyWithTheStatisticsThatMeasuredIt) {
  // V2 ARS on the cart-pole: the statistics move every iteration, and the result is the best central policy
  // with the statistics it was measured under, so that measuring it again (as policy.json's normaliser and
  // theta do) gives the U-hat that was seen, bit for bit.
  const auto env = test_support::cartpole_environment();
  std::shared_ptr<const MujocoPolicy> policy = make_mujoco_policy("linear", env->observation_dim(), 1, {});
  ThreadPool two(2);
  MujocoObjective objective(env, policy, env->scenarios(3, 2, ScenarioVariant::kPlain), &two);
  AugmentedRandomSearchOptions options;
  options.max_iterations = 12;
  options.directions = 2;
  options.top_directions = 1;
  options.step_size = 0.1;
  options.exploration_noise = 0.1;
  options.seed = 3;
  CentralValues central(objective);
  options.callbacks = {&central};
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_EQ(central.values.size(), 12u);
  const double best = *std::max_element(central.values.begin(), central.values.end());
  EXPECT_GT(best, summary.initial_value);  // the search improved on the start
  EXPECT_EQ(summary.best_value, best);
  EXPECT_EQ(objective.evaluate(theta), summary.best_value);
  // The statistics handed back are not those in force when the run ended (they include the best's own
  // rollouts and any after it).
  EXPECT_NE(objective.normalizer().mean, central.last_mean);
}

class MujocoFloatingBody : public test_support::TempDirTest {};

TEST_F(MujocoFloatingBody, FreeAndBallJointsAreObservedWithAllTheirCoordinates) {
  // A floating torso (free joint) with an arm on a ball joint: the policy sees the torso's 7 position numbers
  // and 6 velocities, and the ball's 4 and 3, in MuJoCo's own order.
  const auto xml = test_support::write_file(dir_ / "floating.xml", R"(
<mujoco><worldbody><geom type="plane" size="5 5 0.1"/>
  <body name="torso" pos="0 0 1"><freejoint name="root"/><geom type="sphere" size="0.1" mass="1"/>
    <body name="arm"><joint name="shoulder" type="ball"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="0.2"/>
      <body name="forearm" pos="0.3 0 0"><joint name="elbow" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="0.1"/></body></body></body></worldbody>
  <actuator><motor joint="elbow" ctrllimited="true" ctrlrange="-1 1"/></actuator></mujoco>)");
  const auto toml = test_support::write_file(dir_ / "task.toml", R"(
horizon = 3
[initial]
qpos_noise = 0.05
qvel_noise = 0.5
[observation]
qpos = ["root", "shoulder", "elbow"]
qvel = ["root", "shoulder"]
[[reward]]
term = "healthy"
)");
  const auto env = test_support::environment_of(xml, toml);
  ASSERT_EQ(env->observation_dim(), 7 + 4 + 1 + 6 + 3);
  const mjModel* m = env->model().get();
  ASSERT_EQ(m->nq, 12);
  ASSERT_EQ(m->nv, 10);
  MujocoSlot slot(*env);
  std::vector<double> p0(static_cast<std::size_t>(env->initial_noise_dim()));
  env->scenarios(2, 1, ScenarioVariant::kPlain).initial_noise(0, p0);
  env->reset(slot, p0);
  const double a = 0.3;
  env->step(slot, std::span<const double>(&a, 1), {});
  std::vector<double> observed(static_cast<std::size_t>(env->observation_dim()));
  env->observe(slot, observed);
  const mjData* d = slot.data;
  std::vector<double> expected(d->qpos, d->qpos + m->nq);  // root 7, shoulder 4, elbow 1
  expected.insert(expected.end(), d->qvel, d->qvel + 9);   // root 6, shoulder 3
  EXPECT_EQ(observed, expected);
  EXPECT_GT(d->qpos[2], 0.5);  // the torso's height: the observation holds the root's position
  // A free joint has no single angle to take the sine and cosine of.
  const auto bad = test_support::write_file(dir_ / "bad.toml",
                                            "[observation]\nqpos_sincos = [\"root\"]\n"
                                            "[[reward]]\nterm = \"healthy\"\n");
  EXPECT_THAT(
      test_support::input_error_message([&] { test_support::environment_of(xml, bad); }),
      ::testing::HasSubstr("observation.qpos_sincos[0]: joint \"root\" is not a hinge or slide joint"));
}

class MujocoLargeModel : public test_support::TempDirTest {};

TEST_F(MujocoLargeModel, StartsAndStepsDrawAsManyScenarioNumbersAsTheModelNeeds) {
  // A chain of 40 hinges, each with a motor: the start draws nq + nv = 80 numbers, a step 40 for the
  // actuators plus 4 for each of 8 pushed links (72): more than the generic models' 64, and every one is
  // used.
  constexpr int kLinks = 40;
  std::string bodies, closing, motors;
  for (int k = 0; k < kLinks; ++k) {
    bodies += fmt::format(
        R"(<body name="b{0}" pos="0 0 -0.1"><joint name="j{0}" type="hinge" axis="0 1 0" damping="0.1"/>
<geom type="capsule" fromto="0 0 0 0 0 -0.1" size="0.02" mass="0.1"/>)",
        k);
    closing += "</body>";
    motors += fmt::format(R"(<motor joint="j{0}" ctrllimited="true" ctrlrange="-1 1"/>)", k);
  }
  const auto xml = test_support::write_file(
      dir_ / "chain.xml",
      "<mujoco><worldbody>" + bodies + closing + "</worldbody><actuator>" + motors + "</actuator></mujoco>");
  const auto toml = test_support::write_file(dir_ / "task.toml", R"(
horizon = 5
[initial]
qpos_noise = 0.01
qvel_noise = 0.02
[noise]
actuator = 0.1
push_bodies = ["b0", "b5", "b10", "b15", "b20", "b25", "b30", "b39"]
push_force = 1.0
push_probability = 0.5
[observation]
qpos = ["j0", "j39"]
[[reward]]
term = "healthy"
)");
  const auto env = test_support::environment_of(xml, toml);
  ASSERT_EQ(env->initial_noise_dim(), 80);
  ASSERT_EQ(env->noise_dim(), 72);
  const ScenarioSet scenarios = env->scenarios(3, 2, ScenarioVariant::kPlain);
  std::vector<double> p0(80), p1(72);
  scenarios.initial_noise(1, p0);
  scenarios.step_noise(1, 0, p1);

  // The start: qpos0 = 0 moved by 0.01 (2u - 1), qvel by 0.02 (2u - 1), for the last joint too.
  MujocoSlot slot(*env);
  env->reset(slot, p0);
  const mjData* d = slot.data;
  for (int j : {0, kLinks - 1}) {
    EXPECT_DOUBLE_EQ(d->qpos[j], 0.01 * (2.0 * p0[static_cast<std::size_t>(j)] - 1.0)) << j;
    EXPECT_DOUBLE_EQ(d->qvel[j], 0.02 * (2.0 * p0[static_cast<std::size_t>(kLinks + j)] - 1.0)) << j;
  }
  // A step: the last numbers (the last pushed link's) decide whether it is pushed, so the step with them
  // changed to the other side of 1 - push_probability moves the chain otherwise.
  const std::vector<double> zero_action(kLinks, 0.0);
  env->step(slot, zero_action, p1);
  const double tip_pushed_or_not = slot.data->qvel[kLinks - 1];
  std::vector<double> flipped = p1;
  flipped[68] = p1[68] < 0.5 ? 0.9 : 0.1;
  env->reset(slot, p0);
  env->step(slot, zero_action, flipped);
  EXPECT_NE(slot.data->qvel[kLinks - 1], tip_pushed_or_not);
  // A whole rollout runs its horizon with them, and ends where the same scenario ends after another one.
  std::shared_ptr<const MujocoPolicy> policy = make_mujoco_policy("linear", 2, kLinks, {});
  const Theta theta = wiggly_theta(*policy);
  std::vector<double> tip;
  const MujocoStepObserver record = [&](int, const mjData* data, std::span<const double>, double) {
    tip.push_back(data->qpos[kLinks - 1]);
  };
  const auto a = env->rollout(*policy, theta, ObservationNormalizer(2), scenarios, 1, slot, nullptr, &record);
  const std::vector<double> first = std::exchange(tip, {});
  env->rollout(*policy, theta, ObservationNormalizer(2), scenarios, 0, slot);
  env->rollout(*policy, theta, ObservationNormalizer(2), scenarios, 1, slot, nullptr, &record);
  EXPECT_EQ(a.steps, 5);
  EXPECT_EQ(first, tip);
}

class MujocoCrash : public test_support::TempDirTest {};

TEST_F(MujocoCrash, InstabilityEndsTheRolloutAsACrashWithThePenalty) {
  const auto& dir = dir_;
  // A stiff joint at a huge timestep: explicit Euler blows up within a few steps.
  const auto xml = test_support::write_file(dir / "unstable.xml", R"(
<mujoco><option timestep="0.5"/>
  <worldbody><body><joint name="j" type="hinge" stiffness="1e9" damping="0"/>
    <geom type="capsule" fromto="0 0 0 1 0 0" size="0.05" mass="1"/></body></worldbody>
  <actuator><motor name="m" joint="j" ctrllimited="true" ctrlrange="-1 1"/></actuator></mujoco>)");
  const auto toml = test_support::write_file(dir / "task.toml", R"(
horizon = 1000
crash_penalty = -7.5
[initial]
qpos = { j = 0.3 }
[observation]
qpos = ["j"]
qvel = ["j"]
[[reward]]
term = "healthy"
)");
  const auto env = test_support::environment_of(xml, toml);
  std::shared_ptr<const MujocoPolicy> policy = make_mujoco_policy("linear", 2, 1, {});
  const Theta theta(policy->parameters().size(), 0.0);
  MujocoSlot slot(*env);
  const auto r = env->rollout(*policy, theta, ObservationNormalizer(2),
                              env->scenarios(1, 1, ScenarioVariant::kPlain), 0, slot);
  EXPECT_TRUE(r.crashed);
  EXPECT_LT(r.steps, 1000);
  EXPECT_EQ(r.discounted_return, (r.steps - 1) * 1.0 - 7.5);  // 1 per healthy step, then the penalty
  MujocoObjective objective(env, policy, env->scenarios(1, 3, ScenarioVariant::kPlain), nullptr);
  objective.evaluate(theta);
  EXPECT_EQ(objective.crashes(), 3);
}

}  // namespace
}  // namespace pegasus
#endif
