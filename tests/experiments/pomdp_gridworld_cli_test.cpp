// End-to-end tests of `pegasus pomdp-gridworld` through the built CLI.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "support/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using pegasus::test_support::read_text;
using PomdpGridworldCli = pegasus::test_support::TempDirTest;

pegasus::test_support::CliResult run(const std::string& args) {
  return pegasus::test_support::run_pegasus(args);
}
std::string read(const fs::path& p) { return read_text(p); }

const char* kSmall = "pomdp-gridworld --scenarios 1,4,16 --trials 3 --montecarlo-max-m 1 --quiet --seed 5";

TEST_F(PomdpGridworldCli, WritesTheDocumentedSummaryKeysAndArtifacts) {
  const auto r = run(std::string(kSmall) + " --out " + (dir_ / "run").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const auto summary = nlohmann::json::parse(read(dir_ / "run" / "summary.json"));
  EXPECT_LT(summary.at("best_in_class_value").get<double>(), -8.0);
  const auto& results = summary.at("results");
  ASSERT_EQ(results.size(), 3u + 3u + 1u);  // normal and hashed at 3 m values, Monte Carlo at m = 1
  for (const auto& row : results) {
    for (const char* key : {"model", "estimator", "m", "trials", "mean_true_value", "stderr_true_value",
                            "mean_estimate", "mean_sup_deviation"})
      EXPECT_TRUE(row.contains(key)) << key;
    EXPECT_EQ(row.at("trials"), 3);
    EXPECT_LE(row.at("mean_true_value").get<double>(),
              summary.at("best_in_class_value").get<double>() + 1e-12);
  }
  for (const char* file :
       {"config.toml", "results.csv", "trials.csv", "value_vs_m.svg", "sup_deviation_vs_m.svg"})
    EXPECT_TRUE(fs::exists(dir_ / "run" / file)) << file;
  EXPECT_FALSE(fs::exists(dir_ / "run.partial"));
}

TEST_F(PomdpGridworldCli, ThreadCountNeverChangesTheResult) {
  ASSERT_EQ(run(std::string(kSmall) + " --threads 1 --out " + (dir_ / "a").string()).code, 0);
  ASSERT_EQ(run(std::string(kSmall) + " --threads 3 --out " + (dir_ / "b").string()).code, 0);
  EXPECT_EQ(read(dir_ / "a" / "summary.json"), read(dir_ / "b" / "summary.json"));
  EXPECT_EQ(read(dir_ / "a" / "trials.csv"), read(dir_ / "b" / "trials.csv"));
}

TEST_F(PomdpGridworldCli, BadInputGetsOneLineExitTwoAndNoRunDirectory) {
  for (const std::string bad :
       {"--scenarios 0,4", "--gamma 1.5", "--horizon 0", "--threads 0", "--trials -1", "--variant lhs"}) {
    const auto r = run("pomdp-gridworld --quiet --out " + (dir_ / "bad").string() + " " + bad);
    EXPECT_EQ(r.code, 2) << bad << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "bad")) << bad;
    EXPECT_FALSE(fs::exists(dir_ / "bad.partial")) << bad;
  }
  std::ofstream(dir_ / "bad.toml") << "trials = 3\nsceanrios = [1, 2]\n";
  const auto r = run("pomdp-gridworld --quiet --out " + (dir_ / "bad").string() + " --config " +
                     (dir_ / "bad.toml").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("bad.toml:2"), std::string::npos) << r.output;
}

// SIGKILL in the middle of a run, then --resume: the finished run equals an uninterrupted one bit for bit.
TEST_F(PomdpGridworldCli, KilledRunResumesToTheSameResult) {
  // Under the sanitizers (about 8 times slower here) 4 trials: still a checkpoint after each to be killed
  // after.
  const bool sanitized = std::getenv("PEGASUS_SANITIZED") != nullptr;
  const std::string args = std::string("pomdp-gridworld --scenarios 64 --trials ") +
                           (sanitized ? "4" : "10") +
                           " --montecarlo=false --hashed=false --quiet --seed 9 --threads 1";
  ASSERT_EQ(run(args + " --out " + (dir_ / "whole").string()).code, 0);

  const fs::path out = dir_ / "killed";
  ASSERT_EQ(pegasus::test_support::kill_pegasus_after_first_checkpoint(args, out),
            pegasus::test_support::KillOutcome::kKilled)
      << "the run left no checkpoint or finished before it could be killed";
  EXPECT_FALSE(fs::exists(out));

  const auto refused = run(args + " --out " + out.string());
  EXPECT_EQ(refused.code, 2) << refused.output;  // an interrupted run is never silently overwritten
  const auto resumed = run(args + " --resume --out " + out.string());
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  EXPECT_EQ(read(dir_ / "whole" / "summary.json"), read(out / "summary.json"));
  EXPECT_EQ(read(dir_ / "whole" / "trials.csv"), read(out / "trials.csv"));
}

}  // namespace
