// The Gymnasium task library (experiments/mujoco/gymnasium/, issue 52 item 4) on models written for these
// tests (tests/mujoco/gymnasium/: Gymnasium's joint, body, site and actuator names, this project's masses and
// sizes): every task file loads; its observation is Gymnasium's (qpos less the excluded positions, then qvel,
// clipped where Gymnasium clips it); the reward of a control step equals Gymnasium's formula computed here
// from MuJoCo's own mj_step on a copy of the state; the healthy ranges end where Gymnasium's do, open or
// closed.
#ifdef PEGASUS_HAVE_MUJOCO
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "mujoco_test_support.hpp"

namespace pegasus {
namespace {

std::filesystem::path gym_tasks() { return test_support::mujoco_experiments() / "gymnasium"; }
std::filesystem::path gym_models() {
  return std::filesystem::path(PEGASUS_SOURCE_DIR) / "tests" / "mujoco" / "gymnasium";
}
std::shared_ptr<const MujocoEnvironment> gym_env(const std::string& name) {
  return test_support::environment_of(gym_models() / (name + ".xml"), gym_tasks() / (name + ".toml"));
}

// Gymnasium v5's defaults for the tasks whose reward is forward progress less a control cost (and, for those
// with is_healthy, plus the healthy reward): what the step of each *_v5.py computes.
struct Locomotion {
  std::string name;
  int frame_skip;
  int skipped_qpos;  // exclude_current_positions_from_observation (the free joint's x and y stay in for Ant)
  double ctrl_cost_weight;
  bool clips_qvel;  // np.clip(qvel, -10, 10) in _get_obs
  bool healthy_reward;
};
const std::vector<Locomotion> kLocomotion = {
    {"swimmer", 4, 2, 1e-4, false, false},     {"hopper", 4, 1, 1e-3, true, true},
    {"half_cheetah", 5, 1, 0.1, false, false}, {"walker2d", 4, 1, 1e-3, true, true},
    {"ant", 5, 0, 0.5, false, true},
};

// A reset whose start perturbation is the uniform numbers `u` (0.5: none) for every qpos and qvel.
void reset_with(const MujocoEnvironment& env, MujocoSlot& slot, double u) {
  env.reset(slot, std::vector<double>(static_cast<std::size_t>(env.initial_noise_dim()), u));
}

// Gymnasium's is_healthy, written from hopper_v5.py, walker2d_v5.py and ant_v5.py.
bool gymnasium_healthy(const std::string& name, const mjModel* m, const mjData* d) {
  if (name == "hopper") {
    bool ok = d->qpos[1] > 0.7 && d->qpos[2] > -0.2 && d->qpos[2] < 0.2;
    for (int i = 2; i < m->nq; ++i) ok = ok && d->qpos[i] > -100 && d->qpos[i] < 100;
    for (int i = 0; i < m->nv; ++i) ok = ok && d->qvel[i] > -100 && d->qvel[i] < 100;
    return ok;
  }
  if (name == "walker2d") return d->qpos[1] > 0.8 && d->qpos[1] < 2.0 && d->qpos[2] > -1 && d->qpos[2] < 1;
  if (name == "ant") return d->qpos[2] >= 0.2 && d->qpos[2] <= 1.0;
  return true;
}

TEST(GymnasiumTasks, EveryShippedTaskFileLoadsOnAModelWithGymnasiumsNames) {
  // Gymnasium's observation sizes; Ant keeps x and y of its free joint (+2) and leaves out cfrc_ext
  // (include_cfrc_ext_in_observation = False), InvertedDoublePendulum leaves out its constraint force (-1).
  const std::vector<std::pair<std::string, int>> sizes = {
      {"swimmer", 8},
      {"hopper", 11},
      {"half_cheetah", 17},
      {"walker2d", 17},
      {"ant", 27 + 2},
      {"inverted_pendulum", 4},
      {"inverted_double_pendulum", 9 - 1},
  };
  std::set<std::string> tested;
  for (const auto& [name, size] : sizes) {
    SCOPED_TRACE(name);
    EXPECT_EQ(gym_env(name)->observation_dim(), size);
    tested.insert(name);
  }
  // No task file is shipped untested, and every recipe names a shipped task file.
  for (const auto& entry : std::filesystem::directory_iterator(gym_tasks())) {
    const std::string stem = entry.path().stem().string();
    if (entry.path().extension() != ".toml") continue;
    if (stem.size() > 6 && stem.substr(stem.size() - 6) == "-train") {
      const std::string task = stem.substr(0, stem.size() - 6);
      EXPECT_TRUE(tested.count(task)) << entry.path();
      std::ifstream in(entry.path());
      std::stringstream text;
      text << in.rdbuf();
      EXPECT_NE(text.str().find("task = \"experiments/mujoco/gymnasium/" + task + ".toml\""),
                std::string::npos)
          << entry.path();
    } else {
      EXPECT_TRUE(tested.count(stem)) << entry.path() << " has no test model";
    }
  }
}

TEST(GymnasiumTasks, ObservationIsGymnasiumsQposLessTheExcludedPositionsThenQvel) {
  for (const auto& task : kLocomotion) {
    SCOPED_TRACE(task.name);
    const auto env = gym_env(task.name);
    MujocoSlot slot(*env);
    reset_with(*env, slot, 0.9);
    const mjModel* m = env->model().get();
    std::vector<double> action(static_cast<std::size_t>(m->nu));
    for (int t = 0; t < 30; ++t) {
      for (int k = 0; k < m->nu; ++k) action[static_cast<std::size_t>(k)] = std::sin(0.3 * t + k);
      if (env->step(slot, action, {}).terminal) break;
    }
    std::vector<double> observed(static_cast<std::size_t>(env->observation_dim()));
    env->observe(slot, observed);
    std::vector<double> expected;
    for (int i = task.skipped_qpos; i < m->nq; ++i) expected.push_back(slot.data->qpos[i]);
    for (int i = 0; i < m->nv; ++i)
      expected.push_back(task.clips_qvel ? std::clamp(slot.data->qvel[i], -10.0, 10.0) : slot.data->qvel[i]);
    EXPECT_EQ(observed, expected);
  }
}

TEST(GymnasiumTasks, RewardOfAStepIsGymnasiumsFormulaOnMujocosOwnSteps) {
  for (const auto& task : kLocomotion) {
    SCOPED_TRACE(task.name);
    const auto env = gym_env(task.name);
    const mjModel* m = env->model().get();
    MujocoSlot slot(*env);
    reset_with(*env, slot, 0.2);
    mjData* copy = mj_makeData(m);
    const int torso = mj_name2id(m, mjOBJ_BODY, "torso");
    const double dt = task.frame_skip * m->opt.timestep;
    std::vector<double> action(static_cast<std::size_t>(m->nu));
    int steps = 0;
    for (int t = 0; t < 40; ++t) {
      double squares = 0.0;
      for (int k = 0; k < m->nu; ++k) {
        const double a = 0.8 * std::sin(0.5 * t + 1.3 * k);
        action[static_cast<std::size_t>(k)] = a;
        squares += a * a;
      }
      mj_copyData(copy, m, slot.data);
      const double before = slot.data->xpos[3 * torso];
      const auto outcome = env->step(slot, action, {});
      // Gymnasium's step on the copy: ctrl = action (ctrlrange [-1, 1]), frame_skip mj_step calls.
      for (int k = 0; k < m->nu; ++k) copy->ctrl[k] = slot.data->ctrl[k];
      for (int s = 0; s < task.frame_skip; ++s) mj_step(m, copy);
      ASSERT_EQ(copy->qpos[0], slot.data->qpos[0]) << t;  // the same physics, bit for bit
      // mj_step leaves xpos at the state before its last integration: the positions of the new state.
      mj_kinematics(m, copy);
      const double x_velocity = (copy->xpos[3 * torso] - before) / dt;
      if (task.name != "ant") {
        EXPECT_NEAR(copy->xpos[3 * torso], copy->qpos[0], 1e-12);  // Gymnasium reads qpos[0]
      }
      const bool healthy = gymnasium_healthy(task.name, m, copy);
      const double alive = task.healthy_reward && healthy ? 1.0 : 0.0;
      EXPECT_NEAR(outcome.reward, x_velocity + alive - task.ctrl_cost_weight * squares, 1e-9) << t;
      // ARS's shift: the search's reward is the task's less the alive bonus (training_only term).
      const double shift = task.healthy_reward ? alive : 0.0;
      EXPECT_NEAR(outcome.training_reward, outcome.reward - shift, 1e-12) << t;
      EXPECT_EQ(outcome.terminal, !healthy) << t;
      ++steps;
      if (outcome.terminal) break;
    }
    EXPECT_GE(steps, 5);
    mj_deleteData(copy);
  }
}

// Sets one qpos or qvel of the slot's state (after a reset) and asks the task whether it is healthy.
bool healthy_with(const MujocoEnvironment& env, MujocoSlot& slot, const char* joint, bool velocity,
                  double value) {
  const mjModel* m = env.model().get();
  mj_resetData(m, slot.data);
  const int j = mj_name2id(m, mjOBJ_JOINT, joint);
  (velocity ? slot.data->qvel[m->jnt_dofadr[j]] : slot.data->qpos[m->jnt_qposadr[j]]) = value;
  mj_forward(m, slot.data);
  return env.healthy(slot.data);
}

TEST(GymnasiumTasks, HealthyRangesEndWhereGymnasiumsDoOpenOrClosed) {
  const auto hopper = gym_env("hopper");
  MujocoSlot h(*hopper);
  EXPECT_FALSE(healthy_with(*hopper, h, "rootz", false, 0.7));  // (0.7, inf): open
  EXPECT_TRUE(healthy_with(*hopper, h, "rootz", false, std::nextafter(0.7, 1.0)));
  EXPECT_TRUE(healthy_with(*hopper, h, "rootz", false, 1e9));
  EXPECT_FALSE(healthy_with(*hopper, h, "rooty", false, 0.2));
  EXPECT_FALSE(healthy_with(*hopper, h, "rooty", false, -0.2));
  EXPECT_TRUE(healthy_with(*hopper, h, "rooty", false, 0.199));
  EXPECT_FALSE(healthy_with(*hopper, h, "thigh_joint", false, -100.0));  // healthy_state_range
  EXPECT_TRUE(healthy_with(*hopper, h, "thigh_joint", false, -99.9));
  EXPECT_FALSE(healthy_with(*hopper, h, "rootx", true, 100.0));  // the unclipped qvel
  EXPECT_TRUE(healthy_with(*hopper, h, "rootx", true, 99.9));
  EXPECT_TRUE(healthy_with(*hopper, h, "rootx", false, 1e9));  // qpos[0] is not in state_vector()[2:]

  const auto walker = gym_env("walker2d");
  MujocoSlot w(*walker);
  EXPECT_FALSE(healthy_with(*walker, w, "rootz", false, 0.8));
  EXPECT_FALSE(healthy_with(*walker, w, "rootz", false, 2.0));
  EXPECT_TRUE(healthy_with(*walker, w, "rootz", false, 1.999));
  EXPECT_FALSE(healthy_with(*walker, w, "rooty", false, 1.0));
  EXPECT_TRUE(healthy_with(*walker, w, "rooty", false, -0.999));

  // Ant: the torso's height (the free joint's z, qpos[2]) in [0.2, 1.0], closed.
  const auto ant = gym_env("ant");
  MujocoSlot a(*ant);
  const mjModel* am = ant->model().get();
  for (const double z : {0.2, 1.0, std::nextafter(0.2, 0.0), std::nextafter(1.0, 2.0), 0.55}) {
    mj_resetData(am, a.data);
    a.data->qpos[2] = z;
    mj_forward(am, a.data);
    EXPECT_EQ(ant->healthy(a.data), z >= 0.2 && z <= 1.0) << z;
  }

  // InvertedPendulum ends when |hinge| > 0.2: 0.2 itself is inside.
  const auto ip = gym_env("inverted_pendulum");
  MujocoSlot p(*ip);
  EXPECT_TRUE(healthy_with(*ip, p, "hinge", false, 0.2));
  EXPECT_TRUE(healthy_with(*ip, p, "hinge", false, -0.2));
  EXPECT_FALSE(healthy_with(*ip, p, "hinge", false, std::nextafter(0.2, 1.0)));

  // InvertedDoublePendulum ends when the tip site's height y <= 1 (site_xpos[0][2]).
  const auto idp = gym_env("inverted_double_pendulum");
  MujocoSlot q(*idp);
  const double edge = std::acos(1.0 / 1.2);  // both links of 0.6 m leaning by this much put the tip at 1 m
  for (const double angle : {0.0, edge - 1e-6, edge + 1e-6, 1.0, 2.0}) {
    const bool healthy = healthy_with(*idp, q, "hinge", false, angle);
    EXPECT_EQ(healthy, q.data->site_xpos[2] > 1.0) << angle;
    EXPECT_EQ(healthy, angle < edge) << angle;
  }
  // Its reward is the alive bonus of 10 on every step that does not end.
  reset_with(*idp, q, 0.5);
  const double none = 0.0;
  EXPECT_EQ(idp->step(q, std::span<const double>(&none, 1), {}).reward, 10.0);
}

}  // namespace
}  // namespace pegasus
#endif
