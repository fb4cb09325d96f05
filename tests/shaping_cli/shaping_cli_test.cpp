// End-to-end tests of `pegasus shaping audit | gridworld | flags | progress-bonus` through the built CLI.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "support/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using pegasus::test_support::read_text;
using pegasus::test_support::run_pegasus;

int lines(const std::string& s) { return static_cast<int>(std::count(s.begin(), s.end(), '\n')); }

const fs::path kAudit = fs::path(PEGASUS_SOURCE_DIR) / "experiments" / "audit";
const std::string kMdp = (kAudit / "gridworld-4x4.mdp.json").string();

std::string audit_args(const std::string& shaping) {
  return "shaping audit --quiet --mdp " + kMdp + " --shaping " + (kAudit / shaping).string();
}

using ShapingCli = pegasus::test_support::TempDirTest;

// ---- shaping audit -------------------------------------------------------------------------------------

TEST_F(ShapingCli, AuditExitsZeroAndPrintsPhiForAPotentialBasedShaping) {
  const auto r =
      run_pegasus(audit_args("gridworld-4x4-phi0.shaping.json") + " --out " + (dir_ / "ok").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("F is potential-based"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("-7.5"), std::string::npos) << r.output;  // Phi0(start) = -6/0.8
  const auto summary = nlohmann::json::parse(read_text(dir_ / "ok" / "summary.json"));
  EXPECT_TRUE(summary.at("potential_based").get<bool>());
  EXPECT_LT(summary.at("max_residual").get<double>(), 1e-9);
  EXPECT_NEAR(summary.at("potential")[0].get<double>(), -7.5, 1e-9);
  EXPECT_FALSE(summary.at("policy_change").at("changes").get<bool>());
  EXPECT_TRUE(fs::exists(dir_ / "ok" / "potential.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "ok" / "counterexample.json"));
}

TEST_F(ShapingCli, AuditExitsOneWithACycleWitnessAndAVerifiedCounterexampleForTheProgressBonus) {
  const auto r = run_pegasus(audit_args("gridworld-4x4-progress-bonus.shaping.json") + " --out " +
                             (dir_ / "bonus").string());
  ASSERT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("NOT potential-based"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("witness (cycle)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("verified by solving both"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("CHANGES"), std::string::npos) << r.output;
  const fs::path out = dir_ / "bonus";
  const auto summary = nlohmann::json::parse(read_text(out / "summary.json"));
  EXPECT_FALSE(summary.at("potential_based").get<bool>());
  EXPECT_GT(summary.at("cycle").at("net_shaping").get<double>(), 0.0);
  EXPECT_TRUE(summary.at("counterexample").at("verified").get<bool>());
  EXPECT_TRUE(summary.at("policy_change").at("changes").get<bool>());
  // The counterexample is a loadable MDP: auditing the same F against it fails too.
  const auto cx = nlohmann::json::parse(read_text(out / "counterexample.json"));
  EXPECT_EQ(cx.at("format"), "pegasus-mdp");
  EXPECT_TRUE(fs::exists(out / "counterexample_shaped.json"));
  const auto again =
      run_pegasus("shaping audit --quiet --mdp " + (out / "counterexample.json").string() + " --shaping " +
                  (kAudit / "gridworld-4x4-progress-bonus.shaping.json").string());
  EXPECT_EQ(again.code, 1) << again.output;
}

TEST_F(ShapingCli, AuditReportsTheLemma4ActionDependence) {
  const auto r = run_pegasus(audit_args("gridworld-4x4-action-bonus.shaping.json"));
  ASSERT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("witness (Lemma 4)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("F(5, 1, "), std::string::npos) << r.output;  // state 5, action east
  EXPECT_NE(r.output.find("counterexample: Lemma 4"), std::string::npos) << r.output;
}

TEST_F(ShapingCli, AuditBadInputExitsTwoWithOneLineNamingTheFileAndField) {
  auto expect_bad = [&](const std::string& args, const std::string& needle) {
    const auto r = run_pegasus("shaping audit --quiet " + args + " --out " + (dir_ / "bad").string());
    EXPECT_EQ(r.code, 2) << args << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << r.output;
    EXPECT_NE(r.output.find(needle), std::string::npos) << args << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << args;
    EXPECT_FALSE(fs::exists(dir_ / "bad.partial")) << args;
  };
  const std::string shaping = (kAudit / "gridworld-4x4-phi0.shaping.json").string();
  expect_bad("--shaping " + shaping, "--mdp");
  expect_bad("--mdp " + kMdp, "--shaping");
  expect_bad("--mdp " + (dir_ / "missing.json").string() + " --shaping " + shaping, "missing.json");

  std::ofstream(dir_ / "prob.mdp.json")
      << R"({"format": "pegasus-mdp", "version": 1, "num_states": 2, "num_actions": 1,
    "gamma": 1, "absorbing": [1], "transitions": [{"state": 0, "action": 0, "next": [[1, 1.5]]}]})";
  expect_bad("--mdp " + (dir_ / "prob.mdp.json").string() + " --shaping " + shaping,
             "transitions[0].next[0]");
  std::ofstream(dir_ / "syntax.json") << "{\"format\": ";
  expect_bad("--mdp " + kMdp + " --shaping " + (dir_ / "syntax.json").string(), "syntax.json");
  // A valid table of the wrong size.
  std::ofstream(dir_ / "small.shaping.json")
      << R"({"format": "pegasus-shaping", "version": 1, "num_states": 3,
    "num_actions": 4, "entries": [[0, 0, 1, 0.5]]})";
  expect_bad("--mdp " + kMdp + " --shaping " + (dir_ / "small.shaping.json").string(), "small.shaping.json");
  std::ofstream(dir_ / "range.shaping.json")
      << R"({"format": "pegasus-shaping", "version": 1, "num_states": 16,
    "num_actions": 4, "entries": [[0, 0, 99, 0.5]]})";
  expect_bad("--mdp " + kMdp + " --shaping " + (dir_ / "range.shaping.json").string(), "entries[0]");
  expect_bad("--mdp " + kMdp + " --shaping " + shaping + " --tolerance 0", "--tolerance");
}

// ---- shaping gridworld / flags ---------------------------------------------------------------------------

const char* kSmallGrid = "shaping gridworld --size 6 --runs 6 --trials 120 --quiet --seed 3";

TEST_F(ShapingCli, GridworldWritesTheDocumentedSummaryKeysCurvesAndPlots) {
  const auto r = run_pegasus(std::string(kSmallGrid) + " --out " + (dir_ / "g").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const fs::path out = dir_ / "g";
  const auto summary = nlohmann::json::parse(read_text(out / "summary.json"));
  // §3.4: about 0.8 cells of progress per step, 10 cells from corner to corner.
  const double optimal = summary.at("optimal_expected_steps").get<double>();
  EXPECT_GT(optimal, 10.0);
  EXPECT_LT(optimal, 10.0 / 0.8 + 1.0);
  const auto& curves = summary.at("curves");
  ASSERT_EQ(curves.size(), 3u);
  const std::vector<std::string> names = {"none", "half", "phi0"};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& c = curves[i];
    std::set<std::string> keys;
    for (const auto& [k, v] : c.items()) keys.insert(k);
    EXPECT_EQ(keys, (std::set<std::string>{"potential", "steps_at", "trials_to_within_25pct"}));
    EXPECT_EQ(c.at("potential"), names[i]);
    std::set<std::string> at;
    for (const auto& [k, v] : c.at("steps_at").items()) {
      at.insert(k);
      EXPECT_TRUE(v.is_number()) << k;
    }
    EXPECT_EQ(at, (std::set<std::string>{"1", "10", "100", "last"}));
    EXPECT_TRUE(c.at("trials_to_within_25pct").is_null() ||
                c.at("trials_to_within_25pct").is_number_integer());
  }
  // Shaping with the good potential learns much faster than no shaping (Fig 3.2).
  EXPECT_LT(curves[2].at("steps_at").at("10").get<double>(), curves[0].at("steps_at").at("10").get<double>());
  EXPECT_TRUE(curves[2].at("trials_to_within_25pct").is_number_integer());

  const std::string csv = read_text(out / "curves.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "trial,none_mean,none_stderr,half_mean,half_stderr,phi0_mean,phi0_stderr");
  EXPECT_EQ(lines(csv), 1 + 120);
  EXPECT_EQ(lines(read_text(out / "runs.csv")), 1 + 3 * 6);
  for (const char* file : {"config.toml", "steps_per_trial.svg", "steps_per_trial_loglog.svg"})
    EXPECT_TRUE(fs::exists(out / file)) << file;
  EXPECT_NE(read_text(out / "steps_per_trial.svg").find("no shaping"), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "checkpoint"));  // per-run checkpoints are gone once the results are written
}

TEST_F(ShapingCli, ShortRunsWriteNullForTrialsTheyDoNotHave) {
  const auto r = run_pegasus("shaping gridworld --size 4 --runs 2 --trials 5 --quiet --out " +
                             (dir_ / "short").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const auto summary = nlohmann::json::parse(read_text(dir_ / "short" / "summary.json"));
  const auto& at = summary.at("curves")[0].at("steps_at");
  EXPECT_TRUE(at.at("1").is_number());
  EXPECT_TRUE(at.at("10").is_null());
  EXPECT_TRUE(at.at("100").is_null());
  EXPECT_TRUE(at.at("last").is_number());
  EXPECT_TRUE(summary.at("curves")[0].at("trials_to_within_25pct").is_null());  // fewer than 10 trials
}

TEST_F(ShapingCli, FlagsRunsTheSubgoalPotentials) {
  const auto r =
      run_pegasus("shaping flags --size 5 --runs 4 --trials 60 --quiet --out " + (dir_ / "f").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const auto summary = nlohmann::json::parse(read_text(dir_ / "f" / "summary.json"));
  EXPECT_EQ(summary.at("experiment"), "shaping-flags");
  EXPECT_GT(summary.at("optimal_expected_steps").get<double>(), 18.0);  // the flag route is 18 cells long
  const auto& curves = summary.at("curves");
  ASSERT_EQ(curves.size(), 3u);
  EXPECT_EQ(curves[1].at("potential"), "phi0");
  EXPECT_EQ(curves[2].at("potential"), "phi1");
  // The fine-tuned potential learns fastest (Fig 3.3).
  EXPECT_LT(curves[2].at("steps_at").at("10").get<double>(), curves[0].at("steps_at").at("10").get<double>());
}

TEST_F(ShapingCli, ThreadCountNeverChangesTheResult) {
  ASSERT_EQ(run_pegasus(std::string(kSmallGrid) + " --threads 1 --out " + (dir_ / "a").string()).code, 0);
  ASSERT_EQ(run_pegasus(std::string(kSmallGrid) + " --threads 3 --out " + (dir_ / "b").string()).code, 0);
  EXPECT_EQ(read_text(dir_ / "a" / "summary.json"), read_text(dir_ / "b" / "summary.json"));
  EXPECT_EQ(read_text(dir_ / "a" / "curves.csv"), read_text(dir_ / "b" / "curves.csv"));
  EXPECT_EQ(read_text(dir_ / "a" / "runs.csv"), read_text(dir_ / "b" / "runs.csv"));
  // A different seed gives different curves.
  ASSERT_EQ(run_pegasus(std::string(kSmallGrid) + " --seed 4 --out " + (dir_ / "c").string()).code, 0);
  EXPECT_NE(read_text(dir_ / "a" / "curves.csv"), read_text(dir_ / "c" / "curves.csv"));
}

TEST_F(ShapingCli, LearningBadInputGetsOneLineExitTwoAndNoRunDirectory) {
  for (const std::string bad :
       {"gridworld --size 1", "gridworld --runs 0", "gridworld --trials 0", "gridworld --potentials none,foo",
        "gridworld --potentials phi1", "gridworld --potentials none,none", "gridworld --alpha 0",
        "gridworld --epsilon 2", "gridworld --intended 0", "flags --size 6", "flags --potentials phi2",
        "gridworld --threads 0", "gridworld --sizee 5", "progress-bonus --bonus 0",
        "progress-bonus --gamma 1.5", "progress-bonus --episodes 0"}) {
    const auto r = run_pegasus("shaping " + bad + " --quiet --out " + (dir_ / "bad").string());
    EXPECT_EQ(r.code, 2) << bad << ": " << r.output;
    EXPECT_EQ(lines(r.output), 1) << bad << ": " << r.output;
    const std::string option = bad.substr(bad.find("--"), bad.find(' ', bad.find("--")) - bad.find("--"));
    EXPECT_NE(r.output.find(option), std::string::npos) << bad << ": " << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << bad;
    EXPECT_FALSE(fs::exists(dir_ / "bad.partial")) << bad;
  }
  std::ofstream(dir_ / "bad.toml") << "size = 6\nruns = 4\ntrails = 10\n";
  const auto r = run_pegasus("shaping gridworld --quiet --out " + (dir_ / "bad").string() + " --config " +
                             (dir_ / "bad.toml").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("bad.toml:3"), std::string::npos) << r.output;
}

TEST_F(ShapingCli, ShippedConfigsLoad) {
  // Every shipped config resolves (run with a tiny override so that the test stays fast).
  for (const char* config :
       {"shaping-gridworld-10.toml", "shaping-gridworld-50.toml", "flags-5.toml", "flags-8.toml"}) {
    const std::string command = std::string(config).starts_with("flags") ? "flags" : "gridworld";
    const auto r = run_pegasus("shaping " + command + " --quiet --config " +
                               (fs::path(PEGASUS_SOURCE_DIR) / "experiments" / config).string() +
                               " --runs 1 --trials 2 --out " + (dir_ / config).string());
    EXPECT_EQ(r.code, 0) << config << ": " << r.output;
  }
}

// SIGKILL after the first finished runs, then --resume: the result equals an uninterrupted run bit for bit.
TEST_F(ShapingCli, KilledRunResumesToTheSameResult) {
  const std::string args =
      "shaping gridworld --size 20 --potentials none --runs 12 --trials 3000 --quiet --seed 9 --threads 1";
  ASSERT_EQ(run_pegasus(args + " --out " + (dir_ / "whole").string()).code, 0);

  const fs::path out = dir_ / "killed";
  const pid_t child = fork();
  if (child == 0) {
    const std::string command =
        std::string(PEGASUS_CLI_PATH) + " " + args + " --out " + out.string() + " >/dev/null 2>&1";
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const fs::path checkpoints = fs::path(out.string() + ".partial") / "checkpoint";
  auto saved = [&] {
    std::error_code ec;
    if (!fs::is_directory(checkpoints, ec)) return 0;
    int n = 0;
    for (const auto& e : fs::directory_iterator(checkpoints, ec))
      if (!e.path().filename().string().starts_with(".")) ++n;
    return n;
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (saved() == 0 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_GT(saved(), 0);
  kill(child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run finished before it could be killed";
  EXPECT_FALSE(fs::exists(out));
  EXPECT_LT(saved(), 12);

  const auto refused = run_pegasus(args + " --out " + out.string());
  EXPECT_EQ(refused.code, 2) << refused.output;  // an interrupted run is never silently overwritten
  const auto resumed = run_pegasus(args + " --resume --out " + out.string());
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  EXPECT_EQ(read_text(dir_ / "whole" / "summary.json"), read_text(out / "summary.json"));
  EXPECT_EQ(read_text(dir_ / "whole" / "curves.csv"), read_text(out / "curves.csv"));
  EXPECT_EQ(read_text(dir_ / "whole" / "runs.csv"), read_text(out / "runs.csv"));
}

// ---- shaping progress-bonus ------------------------------------------------------------------------------

TEST_F(ShapingCli, ProgressBonusPolicyCyclesWhereThePotentialVersionReachesTheGoal) {
  const auto r =
      run_pegasus("shaping progress-bonus --size 6 --episodes 4000 --quiet --out " + (dir_ / "pb").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("never reaches the goal"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("goes round the cycle"), std::string::npos) << r.output;
  const auto summary = nlohmann::json::parse(read_text(dir_ / "pb" / "summary.json"));
  const auto& bonus = summary.at("progress_bonus");
  const auto& potential = summary.at("potential");
  EXPECT_FALSE(bonus.at("reaches_goal").get<bool>());
  EXPECT_GE(bonus.at("cycle").size(), 2u);
  EXPECT_GT(bonus.at("cycle_reward").get<double>(), 0.0);  // the learner is paid for going round
  EXPECT_TRUE(potential.at("reaches_goal").get<bool>());
  EXPECT_TRUE(potential.at("cycle").empty());
  // Judged in the unshaped gridworld, the bonus policy is far slower than the potential one.
  const double optimal = summary.at("optimal_expected_steps").get<double>();
  EXPECT_GT(bonus.at("expected_steps").get<double>(), 5 * optimal);
  EXPECT_LT(potential.at("expected_steps").get<double>(), 1.1 * optimal);
  EXPECT_TRUE(fs::exists(dir_ / "pb" / "learning_curves.csv"));
  // Without --out it only prints.
  const auto printed = run_pegasus("shaping progress-bonus --size 6 --episodes 4000 --quiet");
  EXPECT_EQ(printed.code, 0);
  EXPECT_EQ(printed.output, r.output);
}

}  // namespace
