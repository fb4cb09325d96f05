// The shipped planar hopper (experiments/mujoco/hopper.xml) has the physical parameters it cites, and its
// task resolves against it: the masses and inertias of Raibert's simulation model, a 1000 N/m leg spring,
// and a touch sensor that reads the machine's weight when it rests on its foot.
#ifdef PEGASUS_HAVE_MUJOCO
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "mujoco_test_support.hpp"
#include "pegasus/core/error.hpp"

namespace pegasus {
namespace {

MujocoModel hopper_model() { return MujocoModel::load(test_support::mujoco_experiments() / "hopper.xml"); }

TEST(MujocoHopper, MassesInertiasAndTheLegSpringAreTheCitedOnes) {
  const MujocoModel model = hopper_model();
  const mjModel* m = model.get();
  const int body = model.id_of(mjOBJ_BODY, "body"), leg = model.id_of(mjOBJ_BODY, "leg");
  EXPECT_DOUBLE_EQ(m->body_mass[body], 10.0);
  EXPECT_DOUBLE_EQ(m->body_inertia[3 * body + 1], 10.0);  // pitch (y) inertia
  EXPECT_DOUBLE_EQ(m->body_ipos[3 * body + 2], 0.4);      // centre of mass r2 above the hip
  EXPECT_DOUBLE_EQ(m->body_mass[leg], 1.0);
  EXPECT_DOUBLE_EQ(m->body_inertia[3 * leg + 1], 1.0);
  EXPECT_DOUBLE_EQ(m->body_ipos[3 * leg + 2], -0.5);  // leg centre of mass r1 = 0.5 m above the 1 m foot
  EXPECT_DOUBLE_EQ(mj_getTotalmass(m), 11.1);
  const int spring = model.id_of(mjOBJ_JOINT, "spring");
  EXPECT_DOUBLE_EQ(m->jnt_stiffness[spring], 1000.0);
  EXPECT_DOUBLE_EQ(m->actuator_gear[6 * model.id_of(mjOBJ_ACTUATOR, "hip")], 60.0);
}

TEST(MujocoHopper, HeldUprightOnItsFootItCompressesTheSpringByItsWeightOverTheStiffness) {
  const MujocoModel model = hopper_model();
  const mjModel* m = model.get();
  mjData* d = mj_makeData(m);
  // Hold the body's pitch and x (their velocities zeroed every step) and let it settle on the spring for 5 s
  // with joint damping added by hand: the spring then carries the weight above it.
  for (int s = 0; s < 2500; ++s) {
    d->qvel[0] = d->qvel[2] = d->qvel[3] = 0.0;
    d->qpos[2] = d->qpos[3] = 0.0;
    d->qfrc_applied[4] = -20.0 * d->qvel[4];  // damping on the spring
    d->qfrc_applied[1] = -50.0 * d->qvel[1];  // and on the height
    mj_step(m, d);
  }
  const double weight_above_spring = (10.0 + 1.0) * 9.8;
  EXPECT_NEAR(d->qpos[4], weight_above_spring / 1000.0, 0.005);  // 0.108 m
  const int touch = model.id_of(mjOBJ_SENSOR, "foot_touch");
  EXPECT_NEAR(d->sensordata[m->sensor_adr[touch]], mj_getTotalmass(m) * 9.8, 2.0);
  mj_deleteData(d);
}

TEST(MujocoHopper, TheTaskSeesTenNumbersAndDrivesTwoActuators) {
  MujocoModel model = hopper_model();
  MujocoTask task = load_mujoco_task(test_support::mujoco_experiments() / "hopper_forward.toml", model);
  EXPECT_EQ(task.observation_dim(), 10);  // 4 positions, 5 velocities, the foot's touch
  EXPECT_EQ(task.frame_skip, 5);
  const MujocoEnvironment env(std::move(model), std::move(task));
  EXPECT_EQ(env.action_dim(), 2);
  // Left alone it falls: the rollout ends early (pitch or height) and does not succeed.
  const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
  MujocoSlot slot(env);
  const auto r = env.rollout(*policy, Theta(policy->parameters().size(), 0.0),
                             ObservationNormalizer(env.observation_dim()),
                             env.scenarios(3, 1, ScenarioVariant::kPlain), 0, slot);
  EXPECT_LT(r.steps, env.task().horizon);
  EXPECT_FALSE(r.success);
  EXPECT_FALSE(r.crashed);
}

// The phased linear class holds Raibert's hopping controller (Raibert 1986, ch. 2), and with gains set by
// hand from the model's numbers it meets the task's bar on every one of 40 scenarios: the bar is within the
// class's reach, whatever a search finds. Stance (the foot's touch sensor above 0): the hip servoes the
// body's pitch, a torque of 250 N m/rad and 100 N m s/rad (about 5 rad/s on the body's 10 kg m^2), and the
// leg pushes a little while it extends (0.1 of full thrust per m/s of extension); flight: the hip places the
// leg (world angle phi = pitch + hip) at phi* = 0.2 - 0.215 xdot rad, 0.215 s being about half the stance
// time (a 11.1 kg mass on 1000 N/m: pi sqrt(m/k) / 2 ~ 0.17 s, plus a placement gain), with a servo of 150 N
// m/rad and 10 N m s/rad. Actions are fractions of the hip's 60 N m and the leg's 250 N.
TEST(MujocoHopper, RaibertsControllerInThePhasedLinearClassHopsTwoMetresOnEveryScenario) {
  MujocoModel model = hopper_model();
  MujocoTask task = load_mujoco_task(test_support::mujoco_experiments() / "hopper_forward.toml", model);
  const PolicyPhase contact{.observation = "sensors.foot_touch",
                            .position = observation_position(task, "sensors.foot_touch", "phase")};
  const MujocoEnvironment env(std::move(model), std::move(task));
  const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {}, contact);
  // Rows of (rootz, pitch, hip, spring, xdot, zdot, pitch rate, hip rate, spring rate, touch, bias).
  const double kp_flight = 150.0 / 60.0, kd_flight = 10.0 / 60.0;
  const std::vector<double> flight_hip = {0,          -kp_flight, -kp_flight, 0, -0.215 * kp_flight, 0,
                                          -kd_flight, -kd_flight, 0,          0, 0.2 * kp_flight};
  const std::vector<double> flight_thrust(11, 0.0);
  const std::vector<double> stance_hip = {0, 250.0 / 60.0, 0, 0, 0, 0, 100.0 / 60.0, 0, 0, 0, 0};
  const std::vector<double> stance_thrust = {0, 0, 0, 0, 0, 0, 0, 0, -0.1, 0, 0};
  Theta theta;
  for (const auto* row : {&flight_hip, &flight_thrust, &stance_hip, &stance_thrust})
    theta.insert(theta.end(), row->begin(), row->end());
  ASSERT_EQ(theta.size(), policy->parameters().size());
  const int n = 40;
  const ScenarioSet scenarios = env.scenarios(11, n, ScenarioVariant::kPlain);
  MujocoSlot slot(env);
  int successes = 0;
  for (int i = 0; i < n; ++i)
    successes +=
        env.rollout(*policy, theta, ObservationNormalizer(env.observation_dim()), scenarios, i, slot).success
            ? 1
            : 0;
  EXPECT_EQ(successes, n);
  // Without its phases (the stance rows acting in flight too) the same gains fall on every scenario.
  const auto plain = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
  const Theta stance_only(theta.begin() + 22, theta.end());
  int plain_successes = 0;
  for (int i = 0; i < n; ++i)
    plain_successes +=
        env.rollout(*plain, stance_only, ObservationNormalizer(env.observation_dim()), scenarios, i, slot)
                .success
            ? 1
            : 0;
  EXPECT_EQ(plain_successes, 0);
}

// A phased policy's switch is named as the task names its observation: the touch sensor is number 9 of
// (rootz, pitch, hip, spring; five velocities; the touch), and a name the observation lacks lists what it
// has.
TEST(MujocoHopper, ObservationNumbersAreFoundByTheTasksNames) {
  const MujocoModel model = hopper_model();
  const MujocoTask task = load_mujoco_task(test_support::mujoco_experiments() / "hopper_forward.toml", model);
  EXPECT_EQ(observation_position(task, "sensors.foot_touch", "phase"), 9);
  EXPECT_EQ(observation_position(task, "qpos.rootz", "phase"), 0);
  EXPECT_EQ(observation_position(task, "qvel.rootx", "phase"), 4);
  EXPECT_EQ(observation_position(task, "qvel.spring", "phase"), 8);
  EXPECT_THAT(
      [&] { observation_position(task, "qpos.rootx", "phase_observation"); },
      ::testing::ThrowsMessage<InputError>(::testing::HasSubstr(
          "phase_observation: the task's observation has no number \"qpos.rootx\" (expected one of "
          "qpos.rootz, qpos.pitch, qpos.hip, qpos.spring, qvel.rootx, qvel.rootz, qvel.pitch, qvel.hip, "
          "qvel.spring, sensors.foot_touch)")));
  // Items of several numbers are indexed: a site's position has three.
  MujocoTask with_site = task;
  with_site.observation.push_back({.kind = ObservationKind::kSitePos, .name = "foot", .dim = 3});
  EXPECT_EQ(observation_position(with_site, "site_pos.foot[2]", "phase"), 12);
  EXPECT_THROW(observation_position(with_site, "site_pos.foot", "phase"), InputError);
}

}  // namespace
}  // namespace pegasus
#endif
