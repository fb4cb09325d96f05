// End-to-end tests of `pegasus pendulum train` through the built CLI, on a small setting.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "support/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using pegasus::test_support::read_text;
using pegasus::test_support::run_pegasus;

nlohmann::json read_json(const fs::path& p) {
  return nlohmann::json::parse(pegasus::test_support::read_text(p));
}

class PendulumCli : public pegasus::test_support::TempDirTest {
 protected:
  std::string out(const std::string& name) const { return " --out " + (dir_ / name).string(); }
};

const std::string kSmall =
    " --scenarios 16 --optimizer.hill-climbing.max-iterations 40 --refine-scenarios 24 "
    "--refine.hill-climbing.max-iterations 8 --quiet --seed 3";

TEST_F(PendulumCli, TrainWritesTheDocumentedSummaryAndClearsTheBar) {
  const auto r = run_pegasus("pendulum train --config " + std::string(PEGASUS_SOURCE_DIR) +
                             "/experiments/pendulum.toml" + kSmall + out("run"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = read_json(dir_ / "run" / "summary.json");
  for (const char* key :
       {"mean_return_100", "evaluations_to_bar", "bar", "evaluation_episodes", "initial_uhat", "final_uhat",
        "iterations", "evaluations", "race_mean_return_100", "mean_return_5000", "refine_scenarios",
        "refine_initial_uhat", "refine_final_uhat", "refine_iterations", "refine_evaluations"})
    EXPECT_TRUE(s.contains(key)) << key;
  // Wall-clock figures are provenance (run.json), never results.
  const auto timings = read_json(dir_ / "run" / "run.json")["timings"];
  for (const char* key : {"seconds_to_bar", "cpu_seconds_to_bar", "training_seconds", "refine_seconds"}) {
    EXPECT_TRUE(timings.contains(key)) << key;
    EXPECT_FALSE(s.contains(key)) << key;
  }
  EXPECT_GE(s["mean_return_100"].get<double>(), -200.0);
  EXPECT_GE(s["mean_return_5000"].get<double>(), -200.0);
  EXPECT_EQ(s["refine_scenarios"], 24);
  EXPECT_EQ(s["refine_iterations"], 8);
  EXPECT_GE(s["refine_final_uhat"].get<double>(), s["refine_initial_uhat"].get<double>());
  EXPECT_GT(timings["seconds_to_bar"].get<double>(), 0.0);
  EXPECT_LT(s["initial_uhat"].get<double>(), -1000.0);  // no torque at all: the pendulum only swings
  EXPECT_GT(s["final_uhat"].get<double>(), s["initial_uhat"].get<double>());
  const auto policy = read_json(dir_ / "run" / "policy.json");
  EXPECT_EQ(policy["policy"], "pendulum-swing-up");
  EXPECT_EQ(policy["parameters"].size(), 7u);
  EXPECT_TRUE(policy["parameters"].contains("swing.lead"));
  EXPECT_TRUE(policy["parameters"].contains("stabilise.skew"));
  for (const char* file :
       {"learning_curve.csv", "bar_checks.csv", "episode_returns.csv", "learning_curve.svg"})
    EXPECT_TRUE(fs::exists(dir_ / "run" / file)) << file;
}

TEST_F(PendulumCli, ThreadCountNeverChangesTheResult) {
  ASSERT_EQ(run_pegasus("pendulum train" + kSmall +
                        " --optimizer.hill-climbing.max-iterations 10 --threads 1" + out("a"))
                .code,
            0);
  ASSERT_EQ(run_pegasus("pendulum train" + kSmall +
                        " --optimizer.hill-climbing.max-iterations 10 --threads 2" + out("b"))
                .code,
            0);
  EXPECT_EQ(read_text(dir_ / "a" / "summary.json"), read_text(dir_ / "b" / "summary.json"));
  EXPECT_EQ(read_json(dir_ / "a" / "policy.json"), read_json(dir_ / "b" / "policy.json"));
}

TEST_F(PendulumCli, BadInputGetsOneLineAndExitTwoWithoutARunDirectory) {
  const auto r = run_pegasus("pendulum train --evaluation-episodes 0 --quiet" + out("bad"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("evaluation-episodes"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

}  // namespace
