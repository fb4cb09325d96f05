// End to end: `pegasus mujoco train` and `pegasus mujoco rollout` on small settings
// (mujoco_robustness_cli_test.cpp: bad input, resumes, non-finite returns and Ctrl-C).
#ifdef PEGASUS_HAVE_MUJOCO
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "mujoco_cli_fixture.hpp"
#include "mujoco_test_support.hpp"
#include "pegasus/mujoco/mujoco_policy.hpp"
#include "support/cli_runner.hpp"

namespace pegasus {
namespace {

using test_support::read_text;
using test_support::run_pegasus;
using ::testing::HasSubstr;
using namespace mujoco_cli_test;

std::vector<double> read_policy_theta(const std::filesystem::path& file) {
  return read_mujoco_policy_file(file).theta;
}

TEST_F(MujocoCli, TrainGivesTheSameSummaryOnOneAndTwoThreadsAndRolloutReplaysThePolicy) {
  const auto& dir = dir_;
  const auto one = run_pegasus(small_train(dir / "one", 1));
  ASSERT_EQ(one.code, 0) << one.output;
  const auto two = run_pegasus(small_train(dir / "two", 2));
  ASSERT_EQ(two.code, 0) << two.output;
  const std::string summary = read_text(dir / "one" / "summary.json");
  EXPECT_EQ(summary, read_text(dir / "two" / "summary.json"));
  const auto s = nlohmann::json::parse(summary);
  EXPECT_EQ(s.at("method"), "ars");
  EXPECT_EQ(s.at("integrator"), "Euler");  // the cart-pole's MJCF says so
  EXPECT_EQ(s.at("reward").at("uhat_of"), "task reward");
  EXPECT_EQ(s.at("evaluation").count("mean_training_return"), 0u);
  EXPECT_EQ(s.at("iterations"), 3);
  EXPECT_EQ(s.at("evaluations"), 1 + 3 * (2 * 2 + 1));
  // Every evaluation is 3 rollouts; the control steps are counted exactly.
  EXPECT_EQ(s.at("training_rollouts"), 3 * s.at("evaluations").get<int>());
  EXPECT_EQ(s.at("training_physics_steps").get<std::int64_t>(),
            2 * s.at("training_control_steps").get<std::int64_t>());
  // progress.csv: the best U-hat so far (objective) and each iteration's central policy's; ARS's result is
  // its best central policy (or the start's), with the statistics it was measured under.
  const std::string progress = read_text(dir / "one" / "progress.csv");
  EXPECT_EQ(progress.substr(0, progress.find('\n')), "iteration,evaluations,seconds,objective,central_uhat");
  double best = s.at("initial_uhat").get<double>(), best_so_far = 0.0;
  std::istringstream rows(progress.substr(progress.find('\n') + 1));
  for (std::string row; std::getline(rows, row);) {
    std::vector<std::string> cells;
    std::istringstream fields(row);
    for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
    ASSERT_EQ(cells.size(), 5u) << row;
    best = std::max(best, std::stod(cells[4]));
    best_so_far = std::stod(cells[3]);
  }
  EXPECT_EQ(s.at("final_uhat").get<double>(), best) << progress;
  EXPECT_EQ(s.at("final_uhat").get<double>(), best_so_far) << progress;
  EXPECT_EQ(std::count(progress.begin(), progress.end(), '\n'), 4);
  EXPECT_GT(nlohmann::json::parse(read_text(dir / "one" / "run.json"))
                .at("timings")
                .at("training_seconds")
                .get<double>(),
            0.0);
  EXPECT_TRUE(std::filesystem::exists(dir / "one" / "report.html"));

  // The rollout of the saved policy on the same held-out seed gives the training run's evaluation back.
  const auto rollout = run_pegasus("mujoco rollout --policy " + (dir / "one" / "policy.json").string() +
                                   " --episodes 4 --seed 7 --quiet --out " + (dir / "replay").string());
  ASSERT_EQ(rollout.code, 0) << rollout.output;
  const auto r = nlohmann::json::parse(read_text(dir / "replay" / "summary.json"));
  EXPECT_EQ(r.at("evaluation"), s.at("evaluation"));
  const std::string trajectory = read_text(dir / "replay" / "trajectory.csv");
  EXPECT_THAT(trajectory.substr(0, trajectory.find('\n')), HasSubstr("step,time,reward,qpos0,qpos1,cart_x"));
  EXPECT_GT(std::count(trajectory.begin(), trajectory.end(), '\n'), 2);
  EXPECT_EQ(rollout.output.find("warning"), std::string::npos) << rollout.output;

  // The policy records what its model and task were. A task file whose comments alone were edited since is
  // the same task: no warning. One whose content changed is used as it is now, with a warning that names it.
  auto policy = nlohmann::json::parse(read_text(dir / "one" / "policy.json"));
  EXPECT_EQ(policy.at("model_digest").get<std::string>().size(), 64u);
  const std::string task_text = read_text(policy.at("task").get<std::string>());
  const auto commented_task = dir / "commented.toml";
  test_support::write_file(commented_task, "# a new first line\n" + task_text + "# edited\n");
  policy["task"] = commented_task.string();
  test_support::write_file(dir / "commented.json", policy.dump());
  const auto commented = run_pegasus("mujoco rollout --policy " + (dir / "commented.json").string() +
                                     " --episodes 4 --seed 7 --quiet --out " + (dir / "commented").string());
  ASSERT_EQ(commented.code, 0) << commented.output;
  EXPECT_EQ(commented.output.find("warning"), std::string::npos) << commented.output;
  const auto edited_task = dir / "edited.toml";
  std::string changed = task_text;
  changed.replace(changed.find("crash_penalty = -100.0"), 22, "crash_penalty = -101.0");
  test_support::write_file(edited_task, changed);
  policy["task"] = edited_task.string();
  test_support::write_file(dir / "edited.json", policy.dump());
  const auto edited = run_pegasus("mujoco rollout --policy " + (dir / "edited.json").string() +
                                  " --episodes 4 --seed 7 --quiet --out " + (dir / "edited").string());
  ASSERT_EQ(edited.code, 0) << edited.output;
  EXPECT_THAT(edited.output, HasSubstr("warning: the task " + edited_task.string() + " has changed since " +
                                       (dir / "edited.json").string() + " was trained on it"));
  EXPECT_EQ(nlohmann::json::parse(read_text(dir / "edited" / "summary.json")).at("evaluation"),
            s.at("evaluation"));

  // --task rolls the policy out under another task for its model; --threads changes nothing in the results.
  const auto longer = dir / "longer.toml";
  std::string longer_text = task_text;
  longer_text.replace(longer_text.find("horizon = 400"), 13, "horizon = 450");
  test_support::write_file(longer, longer_text);
  std::string returns;
  for (const int threads : {1, 2}) {
    const auto out = dir / ("other-task-" + std::to_string(threads));
    const auto other = run_pegasus(
        "mujoco rollout --policy " + (dir / "one" / "policy.json").string() + " --task " + longer.string() +
        " --episodes 5 --seed 7 --quiet --threads " + std::to_string(threads) + " --out " + out.string());
    ASSERT_EQ(other.code, 0) << other.output;
    EXPECT_THAT(other.output, HasSubstr("rollout under the task " + longer.string()));
    const auto o = nlohmann::json::parse(read_text(out / "summary.json"));
    EXPECT_EQ(o.at("task"), longer.string());
    EXPECT_EQ(o.at("integrator"), "Euler");
    EXPECT_NE(o.at("evaluation"), s.at("evaluation"));
    if (threads == 1) returns = read_text(out / "returns.csv");
    EXPECT_EQ(read_text(out / "returns.csv"), returns);
  }
}

TEST_F(MujocoCli, TheHopperTrainsByCmaesOnSmallSettingsTheSameOnOneAndTwoThreads) {
  const auto exp = test_support::mujoco_experiments();
  auto train = [&](int threads, const std::string& name) {
    return run_pegasus("mujoco train --model " + (exp / "hopper.xml").string() + " --task " +
                       (exp / "hopper_forward.toml").string() +
                       " --policy mlp --hidden 4 --normalize=false --optimizer.method cmaes "
                       "--optimizer.cmaes.max-iterations 2 --scenarios 2 --evaluation-episodes 3 --seed 5 "
                       "--quiet --threads " +
                       std::to_string(threads) + " --out " + (dir_ / name).string());
  };
  const auto one = train(1, "one");
  ASSERT_EQ(one.code, 0) << one.output;
  const auto two = train(2, "two");
  ASSERT_EQ(two.code, 0) << two.output;
  const std::string summary = read_text(dir_ / "one" / "summary.json");
  EXPECT_EQ(summary, read_text(dir_ / "two" / "summary.json"));
  const auto s = nlohmann::json::parse(summary);
  EXPECT_EQ(s.at("method"), "cmaes");
  EXPECT_EQ(s.at("observation_dim"), 10);
  EXPECT_EQ(s.at("parameters"), (10 * 4 + 4) + (4 * 2 + 2));
  EXPECT_EQ(s.at("training_rollouts"), 2 * s.at("evaluations").get<int>());
  EXPECT_EQ(s.at("training_physics_steps").get<std::int64_t>(),
            5 * s.at("training_control_steps").get<std::int64_t>());
  EXPECT_LE(s.at("training_control_steps").get<std::int64_t>(),
            500 * s.at("training_rollouts").get<std::int64_t>());
  // The bar: 2 m forward after the whole 3 s, upright throughout.
  EXPECT_EQ(s.at("success").at("at"), "end");
  EXPECT_EQ(s.at("success").at("ranges").at(0).at("min"), 2.0);
  const double rate = s.at("evaluation").at("success_rate").get<double>();
  EXPECT_GE(rate, 0.0);
  EXPECT_LE(rate, 1.0);
}

// The training configs of the README's table (experiments/mujoco/*-train.toml) load and run one iteration,
// with the optimizer and the policy size the table names: a config that drifts from its row fails here, not
// in a newcomer's hands. Their model and task paths are relative to the repository's root, so the test names
// them.
TEST_F(MujocoCli, TheShippedTrainingConfigsRunWithTheMethodAndPolicySizeTheReadmeGives) {
  const auto exp = test_support::mujoco_experiments();
  struct Shipped {
    std::string config, model, task, method;
    int parameters;
    nlohmann::json phase;
  };
  const std::vector<Shipped> shipped = {
      {"cartpole-train.toml", "cartpole.xml", "cartpole_swingup.toml", "cmaes", 113, nullptr},
      {"acrobot-train.toml", "acrobot.xml", "acrobot_swingup.toml", "cmaes", 7, nullptr},
      {"hopper-train.toml",
       "hopper.xml",
       "hopper_forward.toml",
       "ars",
       44,
       {{"observation", "sensors.foot_touch"}, {"above", 0.0}}},
  };
  for (const auto& c : shipped) {
    SCOPED_TRACE(c.config);
    const auto out = dir_ / c.config;
    const auto r = run_pegasus("mujoco train --config " + (exp / c.config).string() + " --model " +
                               (exp / c.model).string() + " --task " + (exp / c.task).string() +
                               " --optimizer.cmaes.max-iterations 1 --optimizer.ars.max-iterations 1 "
                               "--scenarios 2 --evaluation-episodes 2 --quiet --threads 2 --out " +
                               out.string());
    ASSERT_EQ(r.code, 0) << r.output;
    const auto s = nlohmann::json::parse(read_text(out / "summary.json"));
    EXPECT_EQ(s.at("method"), c.method);
    EXPECT_EQ(s.at("iterations"), 1);
    EXPECT_EQ(s.at("parameters"), c.parameters);
    EXPECT_EQ(s.at("phase"), c.phase);
  }
}

// A phased policy (two linear policies switched by the hopper's foot contact) trains, is saved with its
// switch, and replays: the rollout gives the training run's held-out evaluation back. A switch the task's
// observation lacks, or a start policy of the other phasing, is one line, exit 2, no run directory.
TEST_F(MujocoCli, APhasedPolicyTrainsSavesItsSwitchAndReplays) {
  const auto exp = test_support::mujoco_experiments();
  const std::string base =
      "mujoco train --model " + (exp / "hopper.xml").string() + " --task " +
      (exp / "hopper_forward.toml").string() +
      " --policy linear --normalize=false --optimizer.method cmaes "
      "--optimizer.cmaes.population-size 4 --scenarios 2 --evaluation-episodes 3 --seed 5 "
      "--quiet";
  const auto trained = run_pegasus(base +
                                   " --phase-observation sensors.foot_touch --phase-above 1 "
                                   "--optimizer.cmaes.max-iterations 2 --out " +
                                   (dir_ / "phased").string());
  ASSERT_EQ(trained.code, 0) << trained.output;
  const auto s = nlohmann::json::parse(read_text(dir_ / "phased" / "summary.json"));
  EXPECT_EQ(s.at("parameters"), 2 * 2 * (10 + 1));
  EXPECT_EQ(s.at("phase"), nlohmann::json::parse(R"({"observation": "sensors.foot_touch", "above": 1.0})"));
  const std::string saved = (dir_ / "phased" / "policy.json").string();
  EXPECT_EQ(read_mujoco_policy_file(saved).phase,
            (PolicyPhase{.observation = "sensors.foot_touch", .above = 1.0}));
  const auto rollout = run_pegasus("mujoco rollout --policy " + saved +
                                   " --episodes 3 --seed 5 --quiet --out " + (dir_ / "replay").string());
  ASSERT_EQ(rollout.code, 0) << rollout.output;
  EXPECT_EQ(nlohmann::json::parse(read_text(dir_ / "replay" / "summary.json")).at("evaluation"),
            s.at("evaluation"));

  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {" --phase-observation sensors.foot",
       "--phase-observation: the task's observation has no number \"sensors.foot\" (expected one of "
       "qpos.rootz"},
      {" --initial-policy " + saved,
       "holds a policy phased by sensors.foot_touch above 1; this run trains one unphased"},
      {" --phase-observation sensors.foot_touch --initial-policy " + saved,
       "holds a policy phased by sensors.foot_touch above 1; this run trains one phased by "
       "sensors.foot_touch above 0"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const auto out = dir_ / "refused";
    const auto r = run_pegasus(base + c.args + " --optimizer.cmaes.max-iterations 1 --out " + out.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_THAT(r.output, HasSubstr(c.expected));
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  }
}

TEST_F(MujocoCli, ATaskWithoutASuccessCriterionReportsNoSuccessRate) {
  // Every rollout of this task earns a positive return; without success_return or [success] none of them
  // is called a success, and the summary says there is no rate rather than 1.
  const auto task = test_support::write_file(dir_ / "plain.toml", R"(
horizon = 50
[observation]
qpos = ["slider", "hinge"]
[[reward]]
term = "healthy"
)");
  const auto run =
      run_pegasus("mujoco train --model " + (test_support::mujoco_experiments() / "cartpole.xml").string() +
                  " --task " + task.string() +
                  " --policy linear --scenarios 2 --optimizer.ars.max-iterations 1 "
                  "--evaluation-episodes 3 --quiet --out " +
                  (dir_ / "run").string());
  ASSERT_EQ(run.code, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("over 3 episodes (0 crashes), no success criterion in the task;"));
  const auto s = nlohmann::json::parse(read_text(dir_ / "run" / "summary.json"));
  EXPECT_EQ(s.at("evaluation").at("mean_return"), 50.0);
  EXPECT_TRUE(s.at("evaluation").at("success_rate").is_null());
  EXPECT_TRUE(s.at("first_success").is_null());
  EXPECT_TRUE(s.at("success_return").is_null());
}

// A term marked training_only shifts U-hat and nothing else; the run says which reward each figure is of and
// that such a shift is not potential-based (thesis ch. 3). --time-budget stops the search with the best so
// far.
TEST_F(MujocoCli, ATrainingOnlyShiftIsReportedApartAndATimeBudgetStopsTheSearch) {
  const auto exp = test_support::mujoco_experiments();
  const auto task = test_support::write_file(
      dir_ / "shifted.toml", read_text(exp / "cartpole_swingup.toml") +
                                 "\n[[reward]]\nterm = \"healthy\"\nweight = -3.0\ntraining_only = true\n");
  const auto r =
      run_pegasus("mujoco train --model " + (exp / "cartpole.xml").string() + " --task " + task.string() +
                  " --scenarios 2 --optimizer.ars.max-iterations 1000000 --optimizer.ars.directions 2 "
                  "--optimizer.ars.top-directions 1 --evaluation-episodes 2 --time-budget 1 --quiet "
                  "--out " +
                  (dir_ / "run").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_THAT(r.output, HasSubstr("a constant shift in a task with termination is not potential-based"));
  EXPECT_THAT(r.output, HasSubstr("stopped by the time budget of 1 s"));
  const auto s = nlohmann::json::parse(read_text(dir_ / "run" / "summary.json"));
  EXPECT_EQ(s.at("reward").at("training_only_terms"), nlohmann::json::array({"reward[4] healthy"}));
  EXPECT_EQ(s.at("stopped_by_time_budget"), true);
  EXPECT_EQ(s.at("termination"), "USER_REQUESTED");
  EXPECT_LT(s.at("iterations").get<int>(), 1000000);
  // Every held-out step that ends on the track pays the healthy 3 in the task's reward and not in the
  // training reward (a step that leaves the track pays neither).
  const auto& e = s.at("evaluation");
  const double shift = e.at("mean_return").get<double>() - e.at("mean_training_return").get<double>();
  const double steps = e.at("control_steps").get<double>(), episodes = e.at("episodes").get<double>();
  EXPECT_LE(shift, 3.0 * steps / episodes + 1e-9);
  EXPECT_GE(shift, 3.0 * (steps - episodes) / episodes - 1e-9);
  EXPECT_GT(shift, 0.0);
}

// --initial-policy starts the search where a saved policy left it: with no iterations the run's first U-hat
// is the saved run's last one and its held-out evaluation is the saved policy's. A policy of another class or
// shape, or a run that would renormalise, is refused before anything is written.
TEST_F(MujocoCli, InitialPolicyContinuesFromTheSavedThetaAndRefusesAnotherShape) {
  const auto& dir = dir_;
  const auto exp = test_support::mujoco_experiments();
  const std::string base = "mujoco train --model " + (exp / "cartpole.xml").string() + " --task " +
                           (exp / "cartpole_swingup.toml").string() +
                           " --normalize=false --scenarios 3 --optimizer.method cmaes "
                           "--optimizer.cmaes.population-size 4 --evaluation-episodes 4 --seed 7 --quiet";
  const auto first = run_pegasus(base + " --policy mlp --hidden 4 --optimizer.cmaes.max-iterations 3 --out " +
                                 (dir / "first").string());
  ASSERT_EQ(first.code, 0) << first.output;
  const std::string saved = (dir / "first" / "policy.json").string();
  const auto next = run_pegasus(base + " --policy mlp --hidden 4 --optimizer.cmaes.max-iterations 0 --out " +
                                (dir / "next").string() + " --initial-policy " + saved);
  ASSERT_EQ(next.code, 0) << next.output;
  const auto a = nlohmann::json::parse(read_text(dir / "first" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(dir / "next" / "summary.json"));
  EXPECT_EQ(b.at("initial_uhat"), a.at("final_uhat"));
  EXPECT_EQ(b.at("evaluation"), a.at("evaluation"));
  EXPECT_EQ(read_policy_theta(dir / "next" / "policy.json"),
            read_policy_theta(dir / "first" / "policy.json"));

  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {" --policy mlp --hidden 5", "this run trains a mlp policy with [5]"},
      {" --policy linear", "holds a mlp policy with hidden widths [4]; this run trains a linear policy"},
      {" --policy mlp --hidden 4 --normalize=true", "initial_policy: only with normalize = false"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const auto out = dir / "refused";
    const auto r = run_pegasus(base + c.args + " --optimizer.cmaes.max-iterations 1 --initial-policy " +
                               saved + " --out " + out.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_THAT(r.output, HasSubstr(c.expected));
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  }
}

}  // namespace
}  // namespace pegasus
#endif
