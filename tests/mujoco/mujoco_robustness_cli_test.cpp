// End to end, what `pegasus mujoco train` and `rollout` do with bad input, a kill and a resume, non-finite
// returns and Ctrl-C (mujoco_cli_test.cpp: training and replay on small settings).
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

// policy.json is checked where it is read (mujoco/mujoco_policy: parse_mujoco_policy_file): each broken field
// is one line naming the file and the field, exit 2, and no run directory.
TEST_F(MujocoCli, RolloutRefusesABrokenPolicyFileNamingTheField) {
  const auto exp = test_support::mujoco_experiments();
  const MujocoPolicyFile good{.model = (exp / "cartpole.xml").string(),
                              .task = (exp / "cartpole_swingup.toml").string(),
                              .model_digest = {},
                              .task_digest = {},
                              .task_content_digest = {},
                              .policy_class = "linear",
                              .hidden = {},
                              .phase = {},
                              .theta = {0.5, -0.5},
                              .normalizer = ObservationNormalizer(1)};
  EXPECT_EQ(parse_mujoco_policy_file(mujoco_policy_file_json(good), "p.json").theta, good.theta);
  const auto refusal = [&](const nlohmann::json& file) {
    const auto path = dir_ / "p.json";
    test_support::write_file(path, file.dump());
    const auto r = run_pegasus("mujoco rollout --quiet --episodes 1 --policy " + path.string() + " --out " +
                               (dir_ / "r").string());
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "r"));
    EXPECT_FALSE(std::filesystem::exists(dir_ / "r.partial"));
    return r.output;
  };
  nlohmann::json j = mujoco_policy_file_json(good);
  j["theta"] = {1, "x"};
  EXPECT_THAT(refusal(j), HasSubstr("p.json: theta[1]: expected a number, got \"x\""));
  j = mujoco_policy_file_json(good);
  j["class"] = "mlp";
  j["hidden"] = {100000};
  EXPECT_THAT(refusal(j), HasSubstr("p.json: hidden[0]: expected a width in [1, 4096], got 100000"));
  j = mujoco_policy_file_json(good);
  j["normalizer"]["clip"] = -1;
  EXPECT_THAT(refusal(j), HasSubstr("p.json: normalizer.clip: expected a positive finite number, got -1"));
  j = mujoco_policy_file_json(good);
  j["model"] = 5;
  EXPECT_THAT(refusal(j), HasSubstr("p.json: model: expected a non-empty string, got 5"));
}

// Runs `args` (ending in " --out DIR/whole") whole, then killed after its first checkpoint and resumed into
// DIR/cut: both summaries must be the same bytes (counters of steps, rollouts and first success included).
void expect_resume_gives_the_uninterrupted_summary(const std::filesystem::path& dir, const std::string& args,
                                                   int iterations) {
  ASSERT_EQ(run_pegasus(args).code, 0);
  const std::string killed_args = args.substr(0, args.find(" --out "));
  const auto outcome = test_support::kill_pegasus_after_first_checkpoint(killed_args, dir / "cut");
  if (outcome == test_support::KillOutcome::kKilled) {
    const auto resumed = run_pegasus(killed_args + " --resume --out " + (dir / "cut").string());
    ASSERT_EQ(resumed.code, 0) << resumed.output;
  } else {
    ASSERT_EQ(outcome, test_support::KillOutcome::kFinishedFirst);
  }
  EXPECT_EQ(nlohmann::json::parse(read_text(dir / "cut" / "summary.json")).at("iterations"), iterations);
  EXPECT_EQ(read_text(dir / "cut" / "summary.json"), read_text(dir / "whole" / "summary.json"));
  // progress.csv but its wall seconds: the central U-hat of the iterations before the kill rode in the
  // checkpoint.
  const auto without_seconds = [](const std::string& csv) {
    std::string out;
    std::istringstream lines(csv);
    for (std::string line; std::getline(lines, line);) {
      const std::size_t second = line.find(',', line.find(',') + 1), third = line.find(',', second + 1);
      out += line.substr(0, second) + line.substr(third) + "\n";
    }
    return out;
  };
  const std::string whole = without_seconds(read_text(dir / "whole" / "progress.csv"));
  EXPECT_EQ(without_seconds(read_text(dir / "cut" / "progress.csv")), whole);
  EXPECT_EQ(std::count(whole.begin(), whole.end(), '\n'), iterations + 1);
}

TEST_F(MujocoCli, ResumingAfterAKillGivesTheUninterruptedSummary) {
  // 40 iterations with a checkpoint after each: the kill lands mid-run.
  std::string args = small_train(dir_ / "whole", 1);
  args.replace(args.find("--optimizer.ars.max-iterations 3 "), 33, "--optimizer.ars.max-iterations 40 ");
  expect_resume_gives_the_uninterrupted_summary(dir_, args, 40);
}

TEST_F(MujocoCli, ResumingCmaesAfterAKillGivesTheUninterruptedSummaryWithItsStepCounts) {
  // CMA-ES keeps no objective state of its own: the run's checkpoint carries the step counters (they
  // restarted from 0 on resume, so a resumed run reported fewer training steps than it took).
  std::string args = small_train(dir_ / "whole", 1);
  args.insert(
      args.find(" --out "),
      " --optimizer.method cmaes --optimizer.cmaes.max-iterations 40 --optimizer.cmaes.population-size 4");
  expect_resume_gives_the_uninterrupted_summary(dir_, args, 40);
}

// issue 51: numbers that would make every return NaN are bad input, named where they are written.
TEST_F(MujocoCli, ANanTargetOrABadTimestepIsOneLineExitTwoAndLeavesNothingBehind) {
  const auto exp = test_support::mujoco_experiments();
  const std::string model = read_text(exp / "cartpole.xml");
  std::string task = read_text(exp / "cartpole_swingup.toml");
  task.replace(task.find("target = [0.0, 0.0, 1.0]"), 24, "target = [0.0, nan, 1.0]");
  const auto nan_task = test_support::write_file(dir_ / "nan.toml", task);
  struct Case {
    std::string args, expected;
  };
  std::vector<Case> cases = {{"--model " + (exp / "cartpole.xml").string() + " --task " + nan_task.string(),
                              "nan.toml:30: reward[1].target[1]: expected a finite number, got nan"}};
  for (const std::string h : {"0", "-0.01", "nan"}) {
    std::string xml = model;
    xml.replace(xml.find("timestep=\"0.01\""), 15, "timestep=\"" + h + "\"");
    const auto bad = test_support::write_file(dir_ / ("h" + std::to_string(cases.size()) + ".xml"), xml);
    cases.push_back({"--model " + bad.string() + " --task " + (exp / "cartpole_swingup.toml").string(),
                     bad.filename().string() + ": option.timestep: expected a positive finite number"});
  }
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const auto out = dir_ / "run";
    const auto r = run_pegasus("mujoco train " + c.args + " --optimizer.ars.max-iterations 1 --quiet --out " +
                               out.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_THAT(r.output, HasSubstr(c.expected));
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    for (const char* left : {"", ".partial", ".lock"})
      EXPECT_FALSE(std::filesystem::exists(out.string() + left)) << left;
  }
}

// issue 51: a search whose U-hat is not finite (here a reward of 1e308 per step sums to inf) is no success.
TEST_F(MujocoCli, ARunWhoseUhatIsNotFiniteEndsWithExitOneAndSaysSo) {
  const auto exp = test_support::mujoco_experiments();
  const auto task = test_support::write_file(
      dir_ / "huge.toml",
      "horizon = 5\n[observation]\nqpos = [\"slider\"]\n[[reward]]\nterm = \"healthy\"\nweight = 1e308\n");
  const auto r =
      run_pegasus("mujoco train --model " + (exp / "cartpole.xml").string() + " --task " + task.string() +
                  " --scenarios 2 --optimizer.ars.max-iterations 2 --evaluation-episodes 2 --quiet "
                  "--out " +
                  (dir_ / "run").string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("error: U-hat of the policy found is not finite (inf)"));
  const auto s = nlohmann::json::parse(read_text(dir_ / "run" / "summary.json"));
  EXPECT_EQ(s.at("uhat_finite"), false);
  EXPECT_TRUE(s.at("final_uhat").is_null());
  EXPECT_EQ(s.at("nonfinite_uhat_evaluations"), s.at("evaluations"));
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 3) << r.output;  // the brief reports + 1
}

// The same when only the search met a non-finite U-hat: at theta = 0 the cart-pole stands exactly still (a
// reward of 0), every perturbed policy moves the cart and 1e308 per m/s overflows; ARS stops with FAILURE and
// its result, the start, is finite.
TEST_F(MujocoCli, ASearchThatMetANonFiniteUhatIsNoSuccessThoughItsResultIsFinite) {
  const auto exp = test_support::mujoco_experiments();
  const auto task =
      test_support::write_file(dir_ / "overflow.toml",
                               "horizon = 200\n[observation]\nqpos = [\"slider\"]\n[[reward]]\n"
                               "term = \"joint_velocity\"\njoint = \"slider\"\nweight = 1e308\n");
  const auto r =
      run_pegasus("mujoco train --model " + (exp / "cartpole.xml").string() + " --task " + task.string() +
                  " --scenarios 1 --optimizer.ars.max-iterations 3 --optimizer.ars.directions 1 "
                  "--optimizer.ars.top-directions 1 --evaluation-episodes 1 --quiet --out " +
                  (dir_ / "run").string());
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_THAT(r.output, HasSubstr("evaluations of U-hat were not finite (the first: evaluation 2)"));
  const auto s = nlohmann::json::parse(read_text(dir_ / "run" / "summary.json"));
  EXPECT_EQ(s.at("uhat_finite"), true);
  EXPECT_EQ(s.at("termination"), "FAILURE");
  EXPECT_EQ(s.at("final_uhat"), 0.0);
  EXPECT_GT(s.at("nonfinite_uhat_evaluations").get<int>(), 0);
}

// issue 51: Ctrl-C ends `mujoco train` at once, even in the middle of a long iteration on a large model
// (the command's handler says where the partial run is and lets SIGINT take its default course).
TEST_F(MujocoCli, SigintStopsTrainingOnALargeModelWithinASecond) {
  constexpr int kLinks = 60;
  std::string bodies, closing, motors;
  for (int k = 0; k < kLinks; ++k) {
    bodies += "<body pos=\"0 0 -0.1\"><joint name=\"j" + std::to_string(k) +
              "\" type=\"hinge\" axis=\"0 1 0\" damping=\"0.1\"/><geom type=\"capsule\" fromto=\"0 0 0 0 0 "
              "-0.1\" size=\"0.02\" mass=\"0.1\"/>";
    closing += "</body>";
    motors += "<motor joint=\"j" + std::to_string(k) + "\" ctrllimited=\"true\" ctrlrange=\"-1 1\"/>";
  }
  const auto xml = test_support::write_file(
      dir_ / "chain.xml", "<mujoco><option timestep=\"0.001\"/><worldbody>" + bodies + closing +
                              "</worldbody><actuator>" + motors + "</actuator></mujoco>");
  const auto task = test_support::write_file(
      dir_ / "chain.toml",
      "horizon = 100000\n[observation]\nqpos = [\"j0\", \"j59\"]\n[[reward]]\nterm = \"healthy\"\n");
  const std::string command = std::string(PEGASUS_CLI_PATH) + " mujoco train --model " + xml.string() +
                              " --task " + task.string() + " --scenarios 4 --quiet --out " +
                              (dir_ / "run").string() + " >/dev/null 2>&1";
  const pid_t child = fork();
  if (child == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  // Well inside the first evaluation (100,000 control steps per rollout).
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  const auto sent = std::chrono::steady_clock::now();
  kill(child, SIGINT);
  int status = 0;
  waitpid(child, &status, 0);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  EXPECT_LT(seconds, 1.0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << status;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "run"));  // never a finished run
}

TEST_F(MujocoCli, BadInputIsOneLineExitTwoAndNoRunDirectory) {
  const auto& dir = dir_;
  const auto exp = test_support::mujoco_experiments();
  const auto bad_task = test_support::write_file(
      dir / "bad.toml",
      "[observation]\nqpos = [\"slider\"]\n[[reward]]\nterm = \"body_velocity\"\nbody = \"torso\"\n");
  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {"--model " + (dir / "none.xml").string() + " --task " + (exp / "cartpole_swingup.toml").string(),
       "none.xml: no such MJCF file"},
      {"--model " + (exp / "cartpole.xml").string() + " --task " + bad_task.string(),
       "bad.toml: reward[0].body: the model has no body \"torso\""},
      {"--model " + (exp / "cartpole.xml").string(), "task: expected a task file"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    const auto out = dir / "run";
    const auto r = run_pegasus("mujoco train " + c.args + " --optimizer.ars.max-iterations 1 --quiet --out " +
                               out.string());
    EXPECT_EQ(r.code, 2);
    EXPECT_THAT(r.output, HasSubstr(c.expected));
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  }
  // A policy file whose theta does not fit the model, task and class.
  const auto policy = test_support::write_file(
      dir / "policy.json",
      nlohmann::json{
          {"format", "pegasus.mujoco.policy"},
          {"version", 1},
          {"model", (exp / "cartpole.xml").string()},
          {"task", (exp / "cartpole_swingup.toml").string()},
          {"class", "linear"},
          {"hidden", nlohmann::json::array()},
          {"theta", {1.0, 2.0}},
          {"normalizer", {{"mean", {0, 0, 0, 0, 0}}, {"inverse_std", {1, 1, 1, 1, 1}}, {"clip", 10}}}}
          .dump());
  const auto r =
      run_pegasus("mujoco rollout --policy " + policy.string() + " --quiet --out " + (dir / "r").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_THAT(r.output, HasSubstr("theta: expected 6 numbers for this model, task and policy class, got 2"));
  EXPECT_FALSE(std::filesystem::exists(dir / "r"));
}

}  // namespace
}  // namespace pegasus
#endif
