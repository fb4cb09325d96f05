// Bad MJCF and task files are rejected with one line naming the file, the field and what is missing.
#ifdef PEGASUS_HAVE_MUJOCO
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>

#include "mujoco_test_support.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace pegasus {
namespace {

using test_support::input_error_message;
using ::testing::AllOf;
using ::testing::HasSubstr;

class MujocoTaskFile : public test_support::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    model_ =
        std::make_unique<MujocoModel>(MujocoModel::load(test_support::mujoco_experiments() / "cartpole.xml"));
  }
  // The message of loading the cart-pole with a task of this text.
  std::string task_error(const std::string& text) {
    const auto path = test_support::write_file(dir_ / "task.toml", text);
    return input_error_message([&] { load_mujoco_task(path, *model_); });
  }
  static std::string minimal(const std::string& extra) {
    return "[observation]\nqpos = [\"slider\"]\n[[reward]]\nterm = \"healthy\"\n" + extra;
  }
  std::unique_ptr<MujocoModel> model_;
};

TEST_F(MujocoTaskFile, AMissingOrMalformedMjcfNamesTheFile) {
  EXPECT_THAT(input_error_message([&] { MujocoModel::load(dir_ / "absent.xml"); }),
              AllOf(HasSubstr("absent.xml"), HasSubstr("no such MJCF file")));
  const auto bad = test_support::write_file(dir_ / "bad.xml", "<mujoco><worldbody><body></mujoco>");
  const std::string message = input_error_message([&] { MujocoModel::load(bad); });
  EXPECT_THAT(message, AllOf(HasSubstr("bad.xml"), HasSubstr("not a valid MJCF model")));
  EXPECT_EQ(message.find('\n'), std::string::npos);
}

TEST_F(MujocoTaskFile, AModelWithoutActuatorsIsNamedNotTheTaskFile) {
  const auto still = test_support::write_file(
      dir_ / "still.xml",
      R"(<mujoco><worldbody><body><joint name="slider" type="slide"/><geom size="0.1"/></body></worldbody></mujoco>)");
  const MujocoModel model = MujocoModel::load(still);
  const auto task = test_support::write_file(dir_ / "task.toml", minimal(""));
  EXPECT_EQ(input_error_message([&] { load_mujoco_task(task, model); }),
            still.string() + ": the model has no actuators (nothing for a policy to drive)");
}

// --resume compares what shapes the results: for an MJCF model that is the compiled model, so a change in a
// file it includes shows (the main file's bytes alone would not), and the same files give the same digest.
TEST_F(MujocoTaskFile, TheModelsDigestFollowsTheFilesItIncludes) {
  const auto main =
      test_support::write_file(dir_ / "main.xml", R"(<mujoco><include file="body.xml"/></mujoco>)");
  const auto body = [&](double mass) {
    test_support::write_file(dir_ / "body.xml",
                             fmt::format(R"(<mujoco><worldbody><body><joint type="slide"/>)"
                                         R"(<geom size="0.1" mass="{}"/></body></worldbody></mujoco>)",
                                         mass));
  };
  body(1.0);
  const std::string first = MujocoModel::load(main).digest();
  EXPECT_EQ(first.size(), 64u);
  EXPECT_EQ(MujocoModel::load(main).digest(), first);
  body(2.0);
  EXPECT_NE(MujocoModel::load(main).digest(), first);
  body(1.0);
  EXPECT_EQ(MujocoModel::load(main).digest(), first);
}

TEST_F(MujocoTaskFile, EveryMissingNameIsReportedWithItsFieldAndKind) {
  EXPECT_THAT(task_error("[observation]\nqpos = [\"slider\", \"elbow\"]\n[[reward]]\nterm = \"healthy\"\n"),
              AllOf(HasSubstr("task.toml: observation.qpos[1]: the model has no joint \"elbow\""),
                    HasSubstr("joints: slider, hinge")));
  EXPECT_THAT(
      task_error(minimal("[[reward]]\nterm = \"body_velocity\"\nbody = \"torso\"\n")),
      AllOf(HasSubstr("reward[1].body: the model has no body \"torso\""), HasSubstr("(bodies: world, ")));
  EXPECT_THAT(
      task_error(minimal("[[reward]]\nterm = \"site_distance\"\nsite = \"hand\"\ntarget = [0, 0, 1]\n")),
      HasSubstr("reward[1].site: the model has no site \"hand\""));
  EXPECT_THAT(task_error(minimal("[[reward]]\nterm = \"joint_speed\"\njoint = \"wrist\"\n")),
              HasSubstr("reward[1].joint: the model has no joint \"wrist\""));
  EXPECT_THAT(task_error("[observation]\nsensors = [\"gyro\"]\n[[reward]]\nterm = \"healthy\"\n"),
              HasSubstr("observation.sensors[0]: the model has no sensor \"gyro\" (sensors: none)"));
  EXPECT_THAT(
      task_error(minimal("[[termination]]\nquantity = \"body_height\"\nname = \"torso\"\nmin = 0.5\n")),
      HasSubstr("termination[0].name: the model has no body \"torso\""));
  EXPECT_THAT(task_error(minimal("[noise]\npush_bodies = [\"pole\", \"arm\"]\n")),
              HasSubstr("noise.push_bodies[1]: the model has no body \"arm\""));
}

// Task text goes through io/toml_input: bytes that are not UTF-8 never reach toml++ and the line is named;
// the same text read from a file or given as text (parse_mujoco_task) gives the same task.
TEST_F(MujocoTaskFile, InvalidUtf8IsNamedWithItsLineAndTextEqualsTheFile) {
  EXPECT_THAT(task_error(minimal("# caf\xe9\n")),
              HasSubstr("task.toml:5: expected UTF-8 text, got the byte 0xE9"));
  const std::string text = "horizon = 77\n" + minimal("");
  const auto path = test_support::write_file(dir_ / "same.toml", text);
  const MujocoTask from_file = load_mujoco_task(path, *model_);
  const MujocoTask from_text = parse_mujoco_task(text, path, *model_);
  EXPECT_EQ(from_text.horizon, 77);
  EXPECT_EQ(from_file.horizon, from_text.horizon);
  EXPECT_EQ(from_file.observation_dim(), from_text.observation_dim());
  EXPECT_THAT(input_error_message([&] { (void)parse_mujoco_task("horizon = = 1", "t.toml", *model_); }),
              HasSubstr("t.toml:1: invalid TOML"));
  // A name holding a newline (a TOML escape) is shown escaped: the message stays one line (found by fuzzing).
  const std::string message =
      task_error("[observation]\nqpos = [\"sli\\nder\"]\n[[reward]]\nterm = \"healthy\"\n");
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_THAT(message, HasSubstr("no joint \"sli\\x0Ader\""));
}

TEST_F(MujocoTaskFile, WrongFieldsTermsRangesAndSyntaxAreNamed) {
  EXPECT_THAT(task_error("horizn = 3\n" + minimal("")),
              HasSubstr("task.toml:1: horizn: unknown key (did you mean 'horizon'?); expected one of"));
  EXPECT_THAT(task_error(minimal("[[reward]]\nterm = \"speed\"\n")),
              HasSubstr("reward[1].term: expected one of body_velocity"));
  EXPECT_THAT(task_error("discount = 1.5\n" + minimal("")),
              HasSubstr("discount: expected a number in [0, 1], got 1.5"));
  EXPECT_THAT(task_error("frame_skip = 0\n" + minimal("")),
              HasSubstr("frame_skip: expected an integer in [1, 1000]"));
  // A value of the wrong type is named with its line and what the file holds.
  EXPECT_THAT(task_error("horizon = \"long\"\n" + minimal("")),
              HasSubstr("task.toml:1: horizon: expected an integer in [1, 1000000], got 'long'"));
  EXPECT_THAT(task_error("crash_penalty = -inf\n" + minimal("")),
              HasSubstr("task.toml:1: crash_penalty: expected a finite number, got -inf"));
  EXPECT_THAT(task_error("[[reward]]\nterm = \"healthy\"\n"), HasSubstr("observation: missing"));
  EXPECT_THAT(task_error("[observation]\nqpos = [\"slider\"]\n"), HasSubstr("reward: missing"));
  EXPECT_THAT(task_error("[observation]\nqpos = [\"slider\", \"slider\"]\n[[reward]]\nterm = \"healthy\"\n"),
              HasSubstr("observation.qpos[1]: 'slider' is already observed as observation.qpos[0]"));
  EXPECT_THAT(task_error("horizon = \n"), HasSubstr("task.toml:1:"));
  EXPECT_THAT(task_error(minimal("[[reward]]\nterm = \"joint_target\"\njoint = \"hinge\"\n")),
              HasSubstr("reward[1].target: missing"));
  EXPECT_THAT(task_error(minimal("[[termination]]\nquantity = \"qpos\"\nname = \"slider\"\n")),
              HasSubstr("termination[0]: expected min, max or both"));
  // A key another term reads is named, not ignored.
  EXPECT_THAT(
      task_error(minimal("[[reward]]\nterm = \"healthy\"\nweight = 2\nbody = \"pole\"\n")),
      HasSubstr("task.toml:8: reward[1].body: the healthy term does not read this key (it takes term, "
                "weight, cap, training_only)"));
  EXPECT_THAT(
      task_error(minimal("[[reward]]\nterm = \"joint_speed\"\njoint = \"hinge\"\ntarget = 1\n")),
      HasSubstr("reward[1].target: the joint_speed term does not read this key (it takes term, weight, "
                "cap, training_only, joint)"));
  EXPECT_THAT(
      task_error(minimal("[[termination]]\nquantity = \"qpos\"\nname = \"slider\"\nmin = 1\nmax = 0\n")),
      HasSubstr("termination[0].max: expected max > min"));
}

// A task file may say its format and version; every file from before (neither) is version 1, and another
// version or format is one line naming the file, the line and the field.
TEST_F(MujocoTaskFile, TheFormatAndVersionAreOptionalAndAnotherVersionIsRefused) {
  const auto with_header = test_support::write_file(
      dir_ / "with.toml", "format = \"pegasus.mujoco.task\"\nversion = 1\nhorizon = 7\n" + minimal(""));
  const auto without = test_support::write_file(dir_ / "without.toml", "horizon = 7\n" + minimal(""));
  EXPECT_EQ(load_mujoco_task(with_header, *model_).horizon, 7);
  EXPECT_EQ(load_mujoco_task(without, *model_).horizon, 7);
  EXPECT_EQ(load_mujoco_task(with_header, *model_).observation_dim(),
            load_mujoco_task(without, *model_).observation_dim());
  EXPECT_THAT(task_error("version = 2\n" + minimal("")),
              AllOf(HasSubstr("task.toml:1: version: expected an integer in [1, 1], got 2"),
                    ::testing::Not(HasSubstr("\n"))));
  EXPECT_THAT(task_error("format = \"pegasus.heli.task\"\n" + minimal("")),
              HasSubstr("task.toml:1: format: expected 'pegasus.mujoco.task', got"));
}

TEST_F(MujocoTaskFile, SuccessRangesAreCheckedLikeTerminationRanges) {
  EXPECT_THAT(task_error(minimal("[success]\nhold_steps = 10\n")), HasSubstr("success.range: missing"));
  EXPECT_THAT(task_error("horizon = 50\n" + minimal("[success]\nhold_steps = 51\n[[success.range]]\n"
                                                    "quantity = \"qpos\"\nname = \"slider\"\nmin = 0\n")),
              HasSubstr("success.hold_steps: expected an integer in [1, 50], got 51"));
  EXPECT_THAT(task_error(minimal("[success]\nat = \"start\"\n[[success.range]]\nquantity = \"qpos\"\n"
                                 "name = \"slider\"\nmin = 0\n")),
              HasSubstr("success.at: expected 'end' or 'any', got 'start'"));
  EXPECT_THAT(
      task_error(minimal("[success]\n[[success.range]]\nquantity = \"site_height\"\nname = \"top\"\n")),
      HasSubstr("success.range[0].name: the model has no site \"top\""));
  EXPECT_THAT(task_error(minimal("[success]\nhold = 3\n")),
              HasSubstr("success.hold: unknown key (did you mean 'hold_steps'?)"));
}

TEST_F(MujocoTaskFile, ARolloutSucceedsOnlyWhenItEndsItsWholeHorizonInsideTheSuccessRanges) {
  // The cart-pole left alone hangs still: its tip stays about 1 m below the pivot.
  auto outcome = [&](const std::string& top, const std::string& success) {
    const auto path = test_support::write_file(
        dir_ / "hang.toml", "horizon = 100\n" + top + "[initial]\nqpos = { hinge = 3.141592653589793 }\n" +
                                minimal("[[termination]]\nquantity = \"qpos\"\nname = \"slider\"\n"
                                        "min = -2.4\nmax = 2.4\n" +
                                        success));
    MujocoModel model = MujocoModel::load(test_support::mujoco_experiments() / "cartpole.xml");
    MujocoTask task = load_mujoco_task(path, model);
    const MujocoEnvironment env(std::move(model), std::move(task));
    const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
    const Theta theta(policy->parameters().size(), 0.0);
    MujocoSlot slot(env);
    return env.rollout(*policy, theta, ObservationNormalizer(env.observation_dim()),
                       env.scenarios(1, 1, ScenarioVariant::kPlain), 0, slot);
  };
  const std::string hanging =
      "[success]\nhold_steps = 40\n[[success.range]]\nquantity = \"site_height\"\n"
      "name = \"tip\"\nmax = -0.99\n";
  EXPECT_TRUE(outcome("", hanging).success);
  EXPECT_FALSE(outcome("success_return = 101.0\n", hanging).success);  // 1 per step: 100 at most
  EXPECT_FALSE(outcome("",
                       "[success]\nhold_steps = 1\n[[success.range]]\nquantity = \"site_height\"\n"
                       "name = \"tip\"\nmin = 0.9\n")
                   .success);
  // at = "any": 40 steps held anywhere; the pole never rises above the pivot, so "tip above 0.9" fails.
  EXPECT_TRUE(outcome("",
                      "[success]\nat = \"any\"\nhold_steps = 40\n[[success.range]]\n"
                      "quantity = \"site_height\"\nname = \"tip\"\nmax = -0.99\n")
                  .success);
  EXPECT_FALSE(outcome("",
                       "[success]\nat = \"any\"\n[[success.range]]\nquantity = \"site_height\"\n"
                       "name = \"tip\"\nmin = 0.0\n")
                   .success);
  // Without a [success] table the bar is the return alone.
  EXPECT_TRUE(outcome("success_return = 100.0\n", "").success);
  EXPECT_FALSE(outcome("success_return = 100.5\n", "").success);
  // With neither, the task has no criterion: a rollout that earned 100 is no success.
  EXPECT_FALSE(outcome("", "").success);
  EXPECT_EQ(outcome("", "").discounted_return, 100.0);
  // success_bonus joins the last step's reward of a success only (discounted as that step), and the bar on
  // the return is checked without it.
  EXPECT_EQ(outcome("success_bonus = 50.0\n", hanging).discounted_return, 150.0);
  EXPECT_EQ(outcome("success_bonus = 50.0\ndiscount = 0.99\n", hanging).discounted_return,
            outcome("discount = 0.99\n", hanging).discounted_return + std::pow(0.99, 99) * 50.0);
  EXPECT_EQ(outcome("success_bonus = 50.0\n", "").discounted_return, 100.0);  // no criterion, no success
  EXPECT_FALSE(outcome("success_bonus = 50.0\nsuccess_return = 120.0\n", "").success);
}

TEST_F(MujocoTaskFile, ACapLimitsWhatATermPaysBeforeItsWeight) {
  // The cart sliding at 2 m/s: body_velocity pays its weight x the speed, or x the cap when that is lower.
  auto reward = [&](const std::string& term) {
    const auto path = test_support::write_file(dir_ / "speed.toml",
                                               "[observation]\nqpos = [\"slider\"]\n[[reward]]\n" + term);
    MujocoModel model = MujocoModel::load(test_support::mujoco_experiments() / "cartpole.xml");
    MujocoTask task = load_mujoco_task(path, model);
    const MujocoEnvironment env(std::move(model), std::move(task));
    MujocoSlot slot(env);
    env.reset(slot, {});
    slot.data->qvel[0] = 2.0;  // the slider's velocity, before the step
    const double a = 0.0;
    return env.step(slot, std::span<const double>(&a, 1), {}).reward;
  };
  const std::string speed = "term = \"body_velocity\"\nbody = \"cart\"\naxis = 0\nweight = 3.0\n";
  const double uncapped = reward(speed);
  EXPECT_NEAR(uncapped, 6.0, 0.05);  // the hanging pole barely slows the cart in 0.02 s
  EXPECT_EQ(reward(speed + "cap = 0.5\n"), 1.5);
  EXPECT_EQ(reward(speed + "cap = 10.0\n"), uncapped);
  EXPECT_THAT(task_error(minimal("[[reward]]\n" + speed + "cap = \"fast\"\n")),
              HasSubstr(":10: reward[1].cap: expected a finite number, got 'fast'"));
}

TEST_F(MujocoTaskFile, TheTerminationPenaltyIsPaidOnceOnTheStepThatLeavesARange) {
  // The cart starts at 0.95 m moving at 2 m/s toward the 1 m limit: the first step ends outside it.
  auto step = [&](const std::string& top, double x) {
    const auto path = test_support::write_file(
        dir_ / "fall.toml", top + minimal("[[termination]]\nquantity = \"qpos\"\nname = \"slider\"\n"
                                          "min = -1.0\nmax = 1.0\n"));
    MujocoModel model = MujocoModel::load(test_support::mujoco_experiments() / "cartpole.xml");
    MujocoTask task = load_mujoco_task(path, model);
    const MujocoEnvironment env(std::move(model), std::move(task));
    MujocoSlot slot(env);
    env.reset(slot, {});
    slot.data->qpos[0] = x;
    slot.data->qvel[0] = 2.0;
    const double a = 0.0;
    return env.step(slot, std::span<const double>(&a, 1), {});
  };
  const MujocoStepOutcome fall = step("termination_penalty = -250.0\n", 0.99);
  EXPECT_TRUE(fall.terminal);
  EXPECT_FALSE(fall.crashed);
  EXPECT_EQ(fall.reward, -250.0);  // no healthy bonus on the step that left, and the penalty
  EXPECT_EQ(step("", 0.99).reward, 0.0);
  const MujocoStepOutcome inside = step("termination_penalty = -250.0\n", 0.0);
  EXPECT_FALSE(inside.terminal);
  EXPECT_EQ(inside.reward, 1.0);
  EXPECT_THAT(task_error("termination_penalty = \"big\"\n" + minimal("")),
              HasSubstr("task.toml:1: termination_penalty: expected a finite number, got 'big'"));
}

// The rollout's "task changed" warning compares this: comments, spacing and key order are no change.
TEST_F(MujocoTaskFile, TheContentDigestIgnoresCommentsSpacingAndKeyOrderButNotValues) {
  const auto digest = [&](const std::string& text) {
    return mujoco_task_content_digest(test_support::write_file(dir_ / "d.toml", text));
  };
  const std::string base = digest("horizon = 10\ndiscount = 0.9\n[observation]\nqpos = [\"slider\"]\n");
  EXPECT_EQ(base.size(), 64u);
  EXPECT_EQ(
      digest("# a comment\ndiscount   = 0.9 # why\nhorizon = 10\n\n[observation]\nqpos = [ \"slider\" ]\n"),
      base);
  EXPECT_NE(digest("horizon = 11\ndiscount = 0.9\n[observation]\nqpos = [\"slider\"]\n"), base);
  EXPECT_NE(digest("horizon = 10\ndiscount = 0.9\n[observation]\nqpos = [\"hinge\"]\n"), base);
}

TEST_F(MujocoTaskFile, TheShippedTaskResolvesToTheModelsAddresses) {
  const MujocoTask task =
      load_mujoco_task(test_support::mujoco_experiments() / "cartpole_swingup.toml", *model_);
  EXPECT_EQ(task.observation_dim(), 5);  // x, cos, sin, xdot, thetadot
  EXPECT_EQ(task.horizon, 400);
  EXPECT_EQ(task.frame_skip, 2);
  ASSERT_EQ(task.initial_qpos.size(), 1u);
  EXPECT_EQ(task.initial_qpos[0].first, 1);  // the hinge's qpos address
  ASSERT_EQ(task.reward.size(), 4u);
  EXPECT_EQ(task.reward[1].kind, RewardKind::kSiteDistance);
  EXPECT_EQ(task.reward[2].kind, RewardKind::kInRange);
  EXPECT_EQ(task.reward[2].range.id, model_->id_of(mjOBJ_SITE, "tip"));
  ASSERT_EQ(task.success_ranges.size(), 1u);
  EXPECT_EQ(task.success_hold_steps, 150);
  EXPECT_FALSE(task.success_anywhere);
}

}  // namespace
}  // namespace pegasus
#endif
