// The second aircraft end to end, from its vehicle file alone: `pegasus pilot` logs the Crazyflie 2.0 ground
// truth, `pegasus identify` fits a model to the logs, `pegasus hover` learns a controller on that model, and
// `pegasus fly` flies it on the ground truth against the scripted pilot, from the same starts and gusts; then
// `pegasus maneuver-pilot` and `pegasus maneuver` do the same for a figure-eight. Under the sanitizers
// (PEGASUS_SANITIZED=1) the chain runs with tiny training and flights, and the flight-quality assertions are
// left to the Release run: the training that earns them takes minutes there.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "pegasus/heli/simulators.hpp"
#include "support/cli_runner.hpp"

namespace {

using namespace pegasus;
using test_support::run_pegasus;

class QuadrotorCli : public test_support::TempDirTest {
 protected:
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  nlohmann::json summary(const std::string& run) const {
    return nlohmann::json::parse(test_support::read_text(dir_ / run / "summary.json"));
  }
  const std::string vehicle_ = std::string(PEGASUS_SOURCE_DIR) + "/experiments/vehicles/crazyflie2.toml";
};

TEST_F(QuadrotorCli, LogsIdentifiesLearnsToHoverAndAFigureEightAndFliesThemOnItsGroundTruth) {
  const bool sanitized = std::getenv("PEGASUS_SANITIZED") != nullptr;
  for (const auto& [name, seconds, seed] : {std::tuple{"train", "150", "1"}, std::tuple{"test", "60", "2"}}) {
    const auto r = run_pegasus(fmt::format("pilot --vehicle {} --seconds {} --seed {} --quiet --out {}",
                                           vehicle_, seconds, seed, path(name)));
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_EQ(summary(name).at("vehicle"), "crazyflie2");
    EXPECT_FALSE(summary(name).at("crashed").get<bool>());
  }
  auto r = run_pegasus(fmt::format(
      "identify --vehicle {} --train {} --test {} --cv-points 60 --scale-grid 1,4 --coordinate-passes 0 "
      "--variants=false --quiet --out {}",
      vehicle_, path("train/log.csv"), path("test/log.csv"), path("id")));
  ASSERT_EQ(r.code, 0) << r.output;
  // The vehicle file's [model] templates = "none" reaches the identification.
  const std::string id_config = test_support::read_text(dir_ / "id" / "config.toml");
  EXPECT_NE(id_config.find("\ntemplates = false\n"), std::string::npos) << id_config;
  // The model names its vehicle; training it for another (here the X-Cell, `heli hover`'s default) is
  // refused.
  EXPECT_EQ(nlohmann::json::parse(test_support::read_text(dir_ / "id" / "model.json")).at("vehicle"),
            "crazyflie2");
  r = run_pegasus(
      fmt::format("heli hover --model {} --quiet --out {}", path("id/model.json"), path("wrong")));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("identified from crazyflie2's logs, and this run is for xcell60"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "wrong"));
  r = run_pegasus(fmt::format(
      "hover --vehicle {} --model {} {} --start-pos-sigma 0.3 --start-vel-sigma 0.1 --then-hill-climb=false "
      "--quiet --out {}",
      vehicle_, path("id/model.json"),
      sanitized ? "--scenarios 2 --seconds 3 --optimizer.gradient.max-iterations 1"
                : "--scenarios 10 --seconds 15 --optimizer.gradient.max-iterations 8",
      path("hover")));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto hover = summary("hover");
  EXPECT_GE(hover.at("final_uhat").get<double>(), hover.at("initial_uhat").get<double>());
  r = run_pegasus(fmt::format(
      "fly --vehicle {} --policy {} --compare-pilot {} --start-pos-sigma 0.3 --start-vel-sigma 0.1 --quiet "
      "--out {}",
      vehicle_, path("hover/policy.json"),
      sanitized ? "--flights 2 --seconds 5" : "--flights 10 --seconds 20", path("fly")));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto fly = summary("fly");
  EXPECT_EQ(fly.at("vehicle"), "crazyflie2");
  EXPECT_TRUE(std::filesystem::exists(dir_ / "fly" / "vehicle.toml"));
  if (!sanitized) {
    // The learned controller holds the quadrotor from every start, and closer than its pilot does.
    EXPECT_EQ(fly.at("crashes").get<int>(), 0);
    EXPECT_LT(fly.at("rms_position_m").get<double>(), fly.at("pilot").at("rms_position_m").get<double>());
  }

  // A figure-eight of 1 m circles at 0.5 m/s, 2 m up: the pilot's logs of it, a model, a short training from
  // the hover policy, and flights against the pilot on the same set points.
  const std::string size = "--altitude-m 2 --speed 0.5 --accel 0.5";
  r =
      run_pegasus(fmt::format("maneuver-pilot --vehicle {} --maneuvers figure8 {} --seconds 120 --repeats 2 "
                              "--quiet --out {}",
                              vehicle_, size, path("pilot8")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(summary("pilot8").at("crashed").get<bool>());
  r = run_pegasus(fmt::format(
      "identify --vehicle {} --train {} --test {} --cv-points 60 --scale-grid 1,4 --coordinate-passes 0 "
      "--variants=false --quiet --out {}",
      vehicle_, path("pilot8/log.csv"), path("test/log.csv"), path("id8")));
  ASSERT_EQ(r.code, 0) << r.output;
  r = run_pegasus(fmt::format(
      "maneuver --vehicle {} --name figure8 {} --model {} --hover-policy {} --scenarios 3 --start-pos-sigma "
      "0.1 "
      "--start-vel-sigma 0.05 --optimizer.gradient.max-iterations 1 --ablations=false --flights 4 "
      "--flight-start-sigma 0.1 --compare-pilot --quiet --out {}",
      vehicle_, size, path("id8/model.json"), path("hover/policy.json"), path("figure8")));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto eight = summary("figure8");
  EXPECT_EQ(eight.at("vehicle"), "crazyflie2");
  EXPECT_EQ(eight.at("maneuver"), "figure8");
  ASSERT_TRUE(eight.contains("pilot"));
  if (!sanitized) {
    // Every flight finishes the figure-eight, closer to the path than the pilot flying the same set points.
    EXPECT_EQ(eight.at("crashes").get<int>(), 0);
    EXPECT_EQ(eight.at("completed").get<int>(), 4);
    EXPECT_LT(eight.at("rms_path_deviation_m").get<double>(),
              eight.at("pilot").at("rms_path_deviation_m").get<double>());
  }
  // The manoeuvre trains in a stated wind (issue 53): with none stated, calm, as its flights fly, and said;
  // a stated wind as stated.
  EXPECT_EQ(eight.at("choices").at("wind").at("by"), "none stated");
  EXPECT_FALSE(eight.contains("wind"));
  r = run_pegasus(fmt::format(
      "maneuver --vehicle {} --name figure8 {} --model {} --hover-policy {} --scenarios 3 --start-pos-sigma "
      "0.1 --start-vel-sigma 0.05 --optimizer.gradient.max-iterations 1 --ablations=false --flights 1 "
      "--wind.steady 0,1.5,0 --wind.gust-sigma 0.3 --out {}",
      vehicle_, size, path("id8/model.json"), path("hover/policy.json"), path("figure8-wind")));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto windy = summary("figure8-wind");
  EXPECT_NE(r.output.find("wind in the scenarios (options): steady [0, 1.5, 0] m/s NED"), std::string::npos)
      << r.output;
  EXPECT_EQ(windy.at("choices").at("wind").at("by"), "options");
  EXPECT_EQ(windy.at("wind").at("steady_ned_mps"), nlohmann::json::array({0.0, 1.5, 0.0}));
  EXPECT_EQ(windy.at("wind").at("gust_sigma_mps").get<double>(), 0.3);
  EXPECT_NE(windy.at("initial_uhat").get<double>(), eight.at("initial_uhat").get<double>());
}

// `pegasus pipeline --vehicle`: the whole chain of the helicopter's demo for any vehicle with a ground truth,
// each stage the generic command with the vehicle file; a vehicle without a ground truth is refused before
// anything runs.
TEST_F(QuadrotorCli, ThePipelineRunsTheWholeChainFromTheVehicleFileAlone) {
  const auto r = run_pegasus(fmt::format(
      "pipeline --vehicle {} --quiet --train-seconds 60 --test-seconds 25 --cv-points 40 --scale-grid 2,4 "
      "--coordinate-passes 0 --scenarios 2 --scenario-seconds 2 --gradient-iterations 0 "
      "--hill-climbing-iterations 1 --flights 2 --flight-seconds 3 --start-pos-sigma 0.3 --start-vel-sigma "
      "0.1 "
      "--out {}",
      vehicle_, path("chain")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(summary("chain").at("vehicle"), "crazyflie2");
  EXPECT_EQ(summary("chain").at("flights"), 2);
  for (const char* stage :
       {"chain/pilot-train", "chain/pilot-test", "chain/identify", "chain/hover", "chain/fly"})
    EXPECT_EQ(summary(stage).at("vehicle"), "crazyflie2") << stage;
  // The vehicle file's hover settings reach the stage: its integral term (38 weights) and starts.
  const auto policy =
      nlohmann::json::parse(test_support::read_text(dir_ / "chain" / "hover" / "policy.json"));
  EXPECT_EQ(policy.at("parameters").size(), 38u);
  const std::string hover_config = test_support::read_text(dir_ / "chain" / "hover" / "config.toml");
  EXPECT_NE(hover_config.find("start_pos_sigma = 0.3"), std::string::npos) << hover_config;
  // The ground truth flies in the vehicle's own turbulence unless told otherwise, as in the library.
  for (const char* stage : {"chain/pilot-train", "chain/pilot-test", "chain/fly"}) {
    const std::string config = test_support::read_text(dir_ / stage / "config.toml");
    EXPECT_NE(config.find(fmt::format("gust_sigma = {}", heli::own_gust_sigma("crazyflie2"))),
              std::string::npos)
        << stage << ": " << config;
  }
  EXPECT_NE(r.output.find("== crazyflie2 pipeline: headline figures =="), std::string::npos) << r.output;

  const auto refused =
      run_pegasus(fmt::format("pipeline --vehicle {}/experiments/vehicles/template.toml --quiet --out {}",
                              PEGASUS_SOURCE_DIR, path("none")));
  EXPECT_EQ(refused.code, 2) << refused.output;
  EXPECT_NE(refused.output.find("template.toml: vehicle.simulator: expected a ground truth for the pipeline "
                                "to fly (one of xcell, crazyflie2, heavy-heli)"),
            std::string::npos)
      << refused.output;
  EXPECT_EQ(std::count(refused.output.begin(), refused.output.end(), '\n'), 1) << refused.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "none"));
}

}  // namespace
