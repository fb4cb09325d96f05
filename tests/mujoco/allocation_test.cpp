// A MuJoCo rollout allocates nothing once its slot exists (STYLE.md; issue 18): neither C++ allocations
// (counted by replacing operator new in this executable) nor MuJoCo's own (counted through mju_user_malloc).
#ifdef PEGASUS_HAVE_MUJOCO
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <string>

#include "mujoco_test_support.hpp"

namespace {
std::atomic<long> g_allocations{0};

void* counting_mujoco_malloc(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::aligned_alloc(64, (n + 63) / 64 * 64);
}
void mujoco_free(void* p) { std::free(p); }
}  // namespace

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
// libstdc++'s temporary buffers (std::stable_sort's) come from the nothrow form: replaced too, so that each
// allocation and its release go through one pair (the sanitizer's new with this file's delete is a mismatch).
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n == 0 ? 1 : n);
}
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace pegasus {
namespace {

TEST(MujocoAllocation, RolloutsAllocateNothingAfterTheSlotIsMade) {
  mju_user_malloc = counting_mujoco_malloc;
  mju_user_free = mujoco_free;
  for (const std::string policy_class : {"linear", "mlp"}) {
    SCOPED_TRACE(policy_class);
    const auto env = test_support::cartpole_environment();
    const auto policy = make_mujoco_policy(policy_class, env->observation_dim(), env->action_dim(), {8, 8});
    const ScenarioSet scenarios = env->scenarios(5, 3, ScenarioVariant::kPlain);
    Theta theta(policy->parameters().size());
    for (std::size_t k = 0; k < theta.size(); ++k) theta[k] = 0.1 * std::sin(static_cast<double>(k));
    const ObservationNormalizer normalizer(env->observation_dim());
    ObservationMoments moments(env->observation_dim());
    MujocoSlot slot(*env);
    env->rollout(*policy, theta, normalizer, scenarios, 0, slot);  // sizes the policy's scratch once
    const long before = g_allocations.load();
    int steps = 0;
    for (int i = 0; i < scenarios.size(); ++i)
      steps += env->rollout(*policy, theta, normalizer, scenarios, i, slot, &moments).steps;
    EXPECT_EQ(g_allocations.load(), before);
    EXPECT_GT(steps, 3 * 10);  // the rollouts ran
  }
  mju_user_malloc = nullptr;
  mju_user_free = nullptr;
}

TEST(MujocoAllocation, AnRk4RolloutWithEveryNewKindOfTermAllocatesNothing) {
  // issue 52's paths: whole mj_step calls and mj_step1 (RK4), the contact forces of the new state with the
  // warm start kept aside, displacement and point velocities, raw clips, a training-only term, open ranges.
  const auto dir = std::filesystem::temp_directory_path() / ("pegasus-alloc-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto xml = test_support::write_file(dir / "sled.xml", R"(
<mujoco><option timestep="0.004" integrator="RK4"/>
  <worldbody><geom type="plane" size="5 5 0.1"/>
    <body name="sled" pos="0 0 0.15"><joint name="slide" type="slide" axis="1 0 0"/>
      <joint name="lift" type="slide" axis="0 0 1"/><geom type="box" size="0.1 0.1 0.1" mass="1"/>
      <site name="nose" pos="0.1 0 0"/></body></worldbody>
  <actuator><motor joint="slide" ctrllimited="true" ctrlrange="-5 5"/></actuator></mujoco>)");
  const auto toml = test_support::write_file(dir / "task.toml", R"toml(
horizon = 50
frame_skip = 2
[observation]
qpos = ["slide", "lift"]
qvel = ["slide", "lift"]
raw_clip = { qvel = 0.5 }
[[reward]]
term = "displacement"
body = "sled"
point = "origin"
[[reward]]
term = "body_velocity"
body = "sled"
point = "site:nose"
[[reward]]
term = "joint_velocity"
joint = "slide"
[[reward]]
term = "contact_cost"
weight = -1e-4
[[reward]]
term = "healthy"
weight = -1.0
training_only = true
[[termination]]
quantity = "qpos"
name = "lift"
min = -1.0
max = inf
bounds = "()"
)toml");
  const auto env = test_support::environment_of(xml, toml);
  std::filesystem::remove_all(dir);
  mju_user_malloc = counting_mujoco_malloc;
  mju_user_free = mujoco_free;
  const auto policy = make_mujoco_policy("linear", env->observation_dim(), env->action_dim(), {});
  const ScenarioSet scenarios = env->scenarios(5, 3, ScenarioVariant::kPlain);
  const Theta theta(policy->parameters().size(), 0.3);
  const ObservationNormalizer normalizer(env->observation_dim());
  MujocoSlot slot(*env);
  env->rollout(*policy, theta, normalizer, scenarios, 0, slot);
  const long before = g_allocations.load();
  int steps = 0;
  for (int i = 0; i < scenarios.size(); ++i)
    steps += env->rollout(*policy, theta, normalizer, scenarios, i, slot).steps;
  EXPECT_EQ(g_allocations.load(), before);
  EXPECT_EQ(steps, 3 * 50);
  mju_user_malloc = nullptr;
  mju_user_free = nullptr;
}

}  // namespace
}  // namespace pegasus
#endif
