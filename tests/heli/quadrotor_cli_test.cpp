// The second aircraft end to end, from its vehicle file alone: `pegasus pilot` logs the Crazyflie 2.0 ground
// truth, `pegasus identify` fits a model to the logs, `pegasus hover` learns a controller on that model, and
// `pegasus fly` flies it on the ground truth against the scripted pilot, from the same starts and gusts.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

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

TEST_F(QuadrotorCli, LogsIdentifiesLearnsToHoverAndFliesItsGroundTruth) {
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
  r = run_pegasus(fmt::format(
      "hover --vehicle {} --model {} --scenarios 10 --seconds 15 --start-pos-sigma 0.3 --start-vel-sigma 0.1 "
      "--optimizer.gradient.max-iterations 8 --then-hill-climb=false --quiet --out {}",
      vehicle_, path("id/model.json"), path("hover")));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto hover = summary("hover");
  EXPECT_GE(hover.at("final_uhat").get<double>(), hover.at("initial_uhat").get<double>());
  r = run_pegasus(fmt::format(
      "fly --vehicle {} --policy {} --compare-pilot --flights 10 --seconds 20 --start-pos-sigma 0.3 "
      "--start-vel-sigma 0.1 --quiet --out {}",
      vehicle_, path("hover/policy.json"), path("fly")));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto fly = summary("fly");
  EXPECT_EQ(fly.at("vehicle"), "crazyflie2");
  EXPECT_TRUE(std::filesystem::exists(dir_ / "fly" / "vehicle.toml"));
  // The learned controller holds the quadrotor from every start, and no worse than its pilot does.
  EXPECT_EQ(fly.at("crashes").get<int>(), 0);
  EXPECT_LT(fly.at("rms_position_m").get<double>(), fly.at("pilot").at("rms_position_m").get<double>());
}

}  // namespace
