// Rewards that mean what they say (issue 52): each term against the quantity it names, computed here from
// the state by hand (a rotor's kinematics) or read from MuJoCo's own fields; ranges open, closed and
// unbounded; raw observation clips; training-only terms.
#ifdef PEGASUS_HAVE_MUJOCO
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <string>
#include <vector>

#include "mujoco_test_support.hpp"
#include "pegasus/mujoco/mujoco_objective.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;

// A rotor in zero gravity: a body on a hinge about the world z axis through its frame's origin, its mass
// (a box) centred 0.5 m out along its x axis, a site 1 m out along its y axis. At angle q and rate w the
// frame origin stands still, the centre of mass moves at 0.5 w (-sin q, cos q, 0) and the site at w (-cos q,
// -sin q, 0).
constexpr const char* kRotorXml = R"(
<mujoco><option timestep="0.01" gravity="0 0 0"/>
  <worldbody><body name="rotor" pos="0.3 0.2 1"><joint name="spin" type="hinge" axis="0 0 1"/>
    <geom type="box" pos="0.5 0 0" size="0.1 0.1 0.1" mass="1"/><site name="rim" pos="0 1 0"/></body>
    <body name="other"><site name="elsewhere"/><joint name="free_slide" type="slide" axis="1 0 0"/>
      <geom type="sphere" size="0.1" mass="1"/></body></worldbody>
  <actuator><motor joint="spin" ctrllimited="true" ctrlrange="-1 1"/></actuator></mujoco>)";

class MujocoRewardTerms : public test_support::TempDirTest {
 protected:
  std::shared_ptr<const MujocoEnvironment> rotor(const std::string& task) {
    const auto xml = test_support::write_file(dir_ / "rotor.xml", kRotorXml);
    const auto toml = test_support::write_file(dir_ / "task.toml", task);
    return test_support::environment_of(xml, toml);
  }
  std::string task_error(const std::string& task) {
    return test_support::input_error_message([&] { rotor(task); });
  }
};

std::string one_term(const std::string& term) {
  return "frame_skip = 3\n[observation]\nqpos = [\"spin\"]\nqvel = [\"spin\"]\n[[reward]]\n" + term;
}

TEST_F(MujocoRewardTerms, BodyVelocityMeasuresTheCentreOfMassTheOriginOrASiteAsTheRotorsKinematicsSay) {
  struct Case {
    std::string term;
    double (*expected)(double q, double w);
  };
  const std::vector<Case> cases = {
      // The default is the centre of mass (what body_velocity always measured).
      {"term = \"body_velocity\"\nbody = \"rotor\"\naxis = 1\n",
       [](double q, double w) { return 0.5 * w * std::cos(q); }},
      {"term = \"body_velocity\"\nbody = \"rotor\"\naxis = 0\npoint = \"com\"\n",
       [](double q, double w) { return -0.5 * w * std::sin(q); }},
      {"term = \"body_velocity\"\nbody = \"rotor\"\naxis = 1\npoint = \"origin\"\n",
       [](double, double) { return 0.0; }},
      {"term = \"body_velocity\"\nbody = \"rotor\"\naxis = 0\npoint = \"site:rim\"\n",
       [](double q, double w) { return -w * std::cos(q); }},
      {"term = \"body_velocity\"\nbody = \"rotor\"\naxis = 1\npoint = \"site:rim\"\n",
       [](double q, double w) { return -w * std::sin(q); }},
      {"term = \"joint_velocity\"\njoint = \"spin\"\n", [](double, double w) { return w; }},
      {"term = \"joint_speed\"\njoint = \"spin\"\n", [](double, double w) { return std::abs(w); }},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.term);
    const auto env = rotor(one_term(c.term));
    MujocoSlot slot(*env);
    env->reset(slot, {});
    for (int t = 0; t < 30; ++t) {
      const double a = t < 10 ? 1.0 : -1.0;  // spin up, then back through zero: both signs of w
      const double reward = env->step(slot, std::span<const double>(&a, 1), {}).reward;
      const double q = slot.data->qpos[0], w = slot.data->qvel[0];
      EXPECT_NEAR(reward, c.expected(q, w), 1e-12 * (1.0 + std::abs(w))) << t;
    }
    EXPECT_LT(slot.data->qvel[0], 0.0);
  }
}

TEST_F(MujocoRewardTerms, DisplacementIsThePointsMoveOverTheControlStepOverItsDuration) {
  // Gymnasium's forward reward (x_after - x_before) / dt: over a control step of 3 x 0.01 s the centre of
  // mass moves along a chord, which differs from its velocity at the step's end.
  const auto env = rotor(one_term("term = \"displacement\"\nbody = \"rotor\"\naxis = 0\n"));
  const auto velocity = rotor(one_term("term = \"body_velocity\"\nbody = \"rotor\"\naxis = 0\n"));
  MujocoSlot slot(*env), other(*velocity);
  env->reset(slot, {});
  velocity->reset(other, {});
  double largest_gap = 0.0;
  for (int t = 0; t < 30; ++t) {
    const double a = 1.0, x0 = 0.3 + 0.5 * std::cos(slot.data->qpos[0]), before = slot.data->xipos[3];
    const double reward = env->step(slot, std::span<const double>(&a, 1), {}).reward;
    const double x1 = 0.3 + 0.5 * std::cos(slot.data->qpos[0]);
    EXPECT_NEAR(reward, (x1 - x0) / 0.03, 1e-9) << t;
    EXPECT_EQ(reward, (slot.data->xipos[3] - before) / (3 * 0.01)) << t;  // MuJoCo's xipos of the rotor
    const double v = velocity->step(other, std::span<const double>(&a, 1), {}).reward;
    largest_gap = std::max(largest_gap, std::abs(v - reward));
  }
  EXPECT_GT(largest_gap, 1e-3);
  // Of the origin: it never moves.
  const auto origin = rotor(one_term("term = \"displacement\"\nbody = \"rotor\"\npoint = \"origin\"\n"));
  MujocoSlot still(*origin);
  origin->reset(still, {});
  const double a = 1.0;
  for (int t = 0; t < 5; ++t)
    EXPECT_NEAR(origin->step(still, std::span<const double>(&a, 1), {}).reward, 0.0, 1e-12);
}

TEST_F(MujocoRewardTerms, APointOnAnotherBodyOrAnUnknownPointIsRefusedNamingTheField) {
  EXPECT_THAT(
      task_error(one_term("term = \"body_velocity\"\nbody = \"rotor\"\npoint = \"site:elsewhere\"\n")),
      HasSubstr("task.toml: reward[0].point: site \"elsewhere\" is fixed in body \"other\", not in "
                "\"rotor\""));
  EXPECT_THAT(task_error(one_term("term = \"displacement\"\nbody = \"rotor\"\npoint = \"middle\"\n")),
              HasSubstr("reward[0].point: expected \"com\", \"origin\" or \"site:NAME\"; got \"middle\""));
  EXPECT_THAT(task_error(one_term("term = \"displacement\"\nbody = \"rotor\"\npoint = \"site:nope\"\n")),
              HasSubstr("reward[0].point: the model has no site \"nope\""));
  EXPECT_THAT(task_error(one_term("term = \"healthy\"\npoint = \"com\"\n")),
              HasSubstr("reward[0].point: the healthy term does not read this key"));
}

TEST_F(MujocoRewardTerms, RangesAreClosedOrOpenAtEitherEndAndMayBeUnbounded) {
  // The rotor at rest at q = 0 stays exactly there with no action: each range's verdict on the value 0.
  struct Case {
    std::string bounds;
    double inside;
  };
  const std::vector<Case> cases = {
      {"min = 0.0\n", 1.0},
      {"min = 0.0\nmax = inf\n", 1.0},
      {"min = 0.0\nmax = inf\nbounds = \"()\"\n", 0.0},
      {"min = 0.0\nmax = inf\nbounds = \"(]\"\n", 0.0},
      {"min = 0.0\nmax = inf\nbounds = \"[)\"\n", 1.0},
      {"min = -inf\nmax = 0.0\n", 1.0},
      {"min = -inf\nmax = 0.0\nbounds = \"[)\"\n", 0.0},
      {"min = -inf\nmax = inf\nbounds = \"()\"\n", 1.0},
      {"max = 0.0\nbounds = \"(]\"\n", 1.0},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.bounds);
    const auto env =
        rotor(one_term("term = \"in_range\"\nquantity = \"qpos\"\nname = \"spin\"\n" + c.bounds));
    MujocoSlot slot(*env);
    env->reset(slot, {});
    const double a = 0.0;
    EXPECT_EQ(env->step(slot, std::span<const double>(&a, 1), {}).reward, c.inside);
    EXPECT_EQ(slot.data->qpos[0], 0.0);
  }
  // Termination ranges read the same way: open at 0, the first step ends the rollout.
  const auto ends = rotor(
      "[observation]\nqpos = [\"spin\"]\n[[reward]]\nterm = \"healthy\"\n[[termination]]\nquantity = "
      "\"qpos\"\nname = \"spin\"\nmin = 0.0\nmax = inf\nbounds = \"()\"\n");
  MujocoSlot slot(*ends);
  ends->reset(slot, {});
  const double a = 0.0;
  EXPECT_TRUE(ends->step(slot, std::span<const double>(&a, 1), {}).terminal);

  const std::string range = "term = \"in_range\"\nquantity = \"qpos\"\nname = \"spin\"\n";
  EXPECT_THAT(task_error(one_term(range + "min = nan\n")),
              HasSubstr("reward[0].min: expected a number, -inf or inf, got nan"));
  EXPECT_THAT(task_error(one_term(range + "min = inf\n")), HasSubstr("reward[0].max: expected max > min"));
  EXPECT_THAT(task_error(one_term(range + "min = 0.0\nbounds = \"[[\"\n")), HasSubstr("reward[0].bounds"));
  EXPECT_THAT(task_error(one_term(range)), HasSubstr("expected min, max or both"));
}

TEST_F(MujocoRewardTerms, RawClipLimitsTheObservedNumbersBeforeNormalisation) {
  const auto env = rotor(
      "[observation]\nqpos = [\"spin\"]\nqvel = [\"spin\"]\nraw_clip = { qvel = 0.5 }\n[[reward]]\nterm = "
      "\"healthy\"\n");
  MujocoSlot slot(*env);
  env->reset(slot, {});
  std::vector<double> observed(2);
  const double a = 1.0;
  for (int t = 0; t < 80; ++t) env->step(slot, std::span<const double>(&a, 1), {});
  ASSERT_GT(slot.data->qvel[0], 0.5);
  env->observe(slot, observed);
  EXPECT_EQ(observed[1], 0.5);
  EXPECT_EQ(observed[0], slot.data->qpos[0]);  // qpos is not clipped (and is past 0.5 rad by now)
  EXPECT_GT(observed[0], 0.5);
  EXPECT_THAT(task_error("[observation]\nqpos = [\"spin\"]\nraw_clip = { qvel = 1.0 }\n[[reward]]\nterm = "
                         "\"healthy\"\n"),
              HasSubstr("observation.raw_clip.qvel: the observation has no qvel items to clip"));
  EXPECT_THAT(task_error("[observation]\nqpos = [\"spin\"]\nraw_clip = { qpos = -1.0 }\n[[reward]]\nterm = "
                         "\"healthy\"\n"),
              HasSubstr("observation.raw_clip.qpos: expected a number in"));
}

TEST_F(MujocoRewardTerms, ATrainingOnlyTermCountsInUhatAndNowhereElse) {
  // ARS's shift: the alive bonus of 1 per step, less 1 in training only.
  const auto env = rotor(
      "horizon = 20\n[observation]\nqpos = [\"spin\"]\n[[reward]]\nterm = \"healthy\"\n[[reward]]\nterm = "
      "\"healthy\"\nweight = -1.0\ntraining_only = true\n");
  EXPECT_TRUE(env->task().has_training_only_terms());
  std::shared_ptr<const MujocoPolicy> policy = make_mujoco_policy("linear", 1, 1, {});
  const Theta theta(policy->parameters().size(), 0.2);
  MujocoSlot slot(*env);
  const ScenarioSet scenarios = env->scenarios(1, 3, ScenarioVariant::kPlain);
  const auto r = env->rollout(*policy, theta, ObservationNormalizer(1), scenarios, 0, slot);
  EXPECT_EQ(r.discounted_return, 20.0);
  EXPECT_EQ(r.training_return, 0.0);
  MujocoObjective objective(env, policy, scenarios, nullptr, false);
  EXPECT_EQ(objective.evaluate(theta), 0.0);
  EXPECT_EQ(objective.rollout_all(theta, scenarios)[2].discounted_return, 20.0);
  EXPECT_THAT(task_error(one_term("term = \"healthy\"\ntraining_only = 1\n")),
              HasSubstr("reward[0].training_only: expected true or false"));
}

TEST_F(MujocoRewardTerms, ANanSiteTargetIsRefusedNamingTheFileAndField) {
  EXPECT_THAT(task_error(one_term("term = \"site_distance\"\nsite = \"rim\"\ntarget = [0.0, nan, 1.0]\n")),
              HasSubstr("task.toml:8: reward[0].target[1]: expected a finite number, got nan"));
}

TEST_F(MujocoRewardTerms, AZeroNegativeOrNanTimestepIsRefusedNamingTheFileAndField) {
  for (const std::string h : {"0", "-0.01", "nan"}) {
    SCOPED_TRACE(h);
    std::string xml = kRotorXml;
    xml.replace(xml.find("timestep=\"0.01\""), 15, "timestep=\"" + h + "\"");
    const auto path = test_support::write_file(dir_ / "bad.xml", xml);
    EXPECT_THAT(test_support::input_error_message([&] { MujocoModel::load(path); }),
                HasSubstr("bad.xml: option.timestep: expected a positive finite number of seconds"));
  }
}

}  // namespace
}  // namespace pegasus
#endif
