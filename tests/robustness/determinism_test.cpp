// summary.json is a function of the inputs alone (issue 16, case 10: `heli hover` wrote wall-clock seconds
// into it): two identical runs of each command on small settings give byte-identical summaries, and the
// timings live in run.json.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/cli_runner.hpp"

namespace {

namespace fs = std::filesystem;
using pegasus::test_support::read_text;
using pegasus::test_support::run_pegasus;

class SummaryDeterminism : public pegasus::test_support::TempDirTest {
 protected:
  // Runs `args` twice (into NAME-a on one thread and NAME-b on two) and expects byte-identical summary.json
  // files: a summary is a function of the inputs, and the thread count never changes a result.
  void expect_identical_summaries(const std::string& name, const std::string& args) const {
    SCOPED_TRACE(args);
    for (const char* copy : {"-a", "-b"}) {
      const std::string threads = copy == std::string("-a") ? " --threads 1" : " --threads 2";
      const auto r = run_pegasus(args + threads + " --quiet --out " + (dir_ / (name + copy)).string());
      ASSERT_EQ(r.code, 0) << r.output;
    }
    const std::string a = read_text(dir_ / (name + "-a") / "summary.json");
    ASSERT_FALSE(a.empty());
    EXPECT_EQ(a, read_text(dir_ / (name + "-b") / "summary.json"));
    ++commands_;
  }
  std::string path(const std::string& relative) const { return (dir_ / relative).string(); }
  mutable int commands_ = 0;
};

const std::string kAudit = std::string(PEGASUS_SOURCE_DIR) + "/experiments/audit/";

TEST_F(SummaryDeterminism, EveryCommandWithoutAHelicopterGivesIdenticalSummaries) {
  expect_identical_summaries("horizon", "horizon --gamma 0.9");
  expect_identical_summaries("dev", "dev count --steps 4");
  expect_identical_summaries("pomdp",
                             "pomdp-gridworld --scenarios 1,4 --trials 2 --montecarlo-max-m 1 --seed 5");
  expect_identical_summaries("gridworld", "shaping gridworld --size 4 --runs 2 --trials 5");
  expect_identical_summaries("flags", "shaping flags --size 5 --runs 2 --trials 20");
  expect_identical_summaries("bonus", "shaping progress-bonus --size 6 --episodes 2000");
  expect_identical_summaries("audit", "shaping audit --mdp " + kAudit + "gridworld-4x4.mdp.json --shaping " +
                                          kAudit + "gridworld-4x4-phi0.shaping.json");
  expect_identical_summaries(
      "pendulum",
      "pendulum train --scenarios 8 --optimizer.hill-climbing.max-iterations 4 --refine-scenarios 8 "
      "--refine.hill-climbing.max-iterations 2 --evaluation-episodes 4 --seed 3");
  const std::string bicycle =
      " --scenarios 4 --horizon 100 --optimizer.gradient.max-iterations 2 --max-km 1 --goal-km 0.3 --seed 3";
  expect_identical_summaries("bicycle-train", "bicycle train --rides 2" + bicycle);
  expect_identical_summaries("bicycle-ride", "bicycle ride --rides 2 --max-km 1 --goal-km 0.3 --policy " +
                                                 path("bicycle-train-a/policy.json"));
  expect_identical_summaries("bicycle-experiment",
                             "bicycle experiment --trials 1 --rides 2 --lesson-trials 1" + bicycle);
  EXPECT_EQ(commands_, 11);
}

// The helicopter chain on a minute of pilot flight: every stage twice, each from the first copy's inputs.
TEST_F(SummaryDeterminism, EveryHelicopterCommandGivesIdenticalSummaries) {
  expect_identical_summaries("pilot", "heli pilot --seconds 40 --hover-seconds 4 --seed 3");
  const std::string log = path("pilot-a/log.csv");
  expect_identical_summaries("identify",
                             "heli identify --train " + log + " --test " + log +
                                 " --cv-points 20 --scale-grid 2,4 --coordinate-passes 0 --horizon-s 2 "
                                 "--variants=false");
  const std::string model = path("identify-a/model.json");
  expect_identical_summaries("hover", "heli hover --model " + model +
                                          " --scenarios 2 --seconds 2 --optimizer.gradient.max-iterations 1 "
                                          "--optimizer.hill-climbing.max-iterations 2 "
                                          "--optimizer.hill-climbing.proposals-per-iteration 2");
  // Its wall-clock figures went to run.json.
  const auto timings = nlohmann::json::parse(read_text(dir_ / "hover-a" / "run.json"))["timings"];
  EXPECT_TRUE(timings.contains("train_seconds")) << timings;
  expect_identical_summaries("fly",
                             "heli fly --policy " + path("hover-a/policy.json") + " --flights 2 --seconds 2");
  EXPECT_EQ(commands_, 4);
}

// The manoeuvre trainer and the whole pipeline on tiny settings; the pipeline's stages name each other's
// files by paths relative to its run directory, so every stage's summary is also identical between the two
// copies.
TEST_F(SummaryDeterminism, TheManeuverAndThePipelineGiveIdenticalSummaries) {
  expect_identical_summaries(
      "pipeline",
      "heli pipeline --train-seconds 40 --test-seconds 25 --cv-points 20 --scale-grid 2,4 "
      "--coordinate-passes 0 "
      "--scenarios 2 --scenario-seconds 2 --gradient-iterations 0 --hill-climbing-iterations 1 --flights 2 "
      "--flight-seconds 2 --seed 4");
  for (const char* stage : {"pilot-train", "pilot-test", "identify", "hover", "fly"}) {
    SCOPED_TRACE(stage);
    EXPECT_EQ(read_text(dir_ / "pipeline-a" / stage / "summary.json"),
              read_text(dir_ / "pipeline-b" / stage / "summary.json"));
  }
  expect_identical_summaries(
      "maneuver", "heli maneuver --name III.2 --model " + path("pipeline-a/identify/model.json") +
                      " --circle-radius 2 --pause-s 0.5 --hold-end-s 0.5 --speed 1 --scenarios 2 "
                      "--optimizer.method hill-climb --optimizer.hill-climbing.max-iterations 1 "
                      "--optimizer.hill-climbing.proposals-per-iteration 2 --flights 2 --ablations=false");
  EXPECT_EQ(commands_, 2);
}

}  // namespace
