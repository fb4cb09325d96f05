// The hand-tuned baselines (heli/baselines.hpp) fly their ground truths through `pegasus fly --baseline`: the
// X-Cell's linear hover controller as the outside-like helicopter's vehicle file describes it, the
// Crazyflie 2's cascaded PD as the ROS-convention vehicle file describes it, and the heavy helicopter's own
// linear controller as its ROS-convention vehicle file describes it. Each holds its set point in
// gusts and in a steady wind without a crash (the integral term), and the judged cost of the vehicle file's
// [cost] is the mean of the per-flight costs in per_flight.csv.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_runner.hpp"

namespace {

using pegasus::test_support::run_pegasus;

class BaselinesCli : public pegasus::test_support::TempDirTest {
 protected:
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  nlohmann::json summary(const std::string& run) const {
    return nlohmann::json::parse(pegasus::test_support::read_text(dir_ / run / "summary.json"));
  }
  // The judged_cost column of a run's per_flight.csv.
  std::vector<double> per_flight_costs(const std::string& run) const {
    std::istringstream in(pegasus::test_support::read_text(dir_ / run / "per_flight.csv"));
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(line.substr(line.rfind(',') + 1), "judged_cost");
    std::vector<double> costs;
    while (std::getline(in, line)) costs.push_back(std::stod(line.substr(line.rfind(',') + 1)));
    return costs;
  }
  static std::string vehicle(const char* name) {
    return std::string(PEGASUS_SOURCE_DIR) + "/experiments/vehicles/" + name;
  }
};

TEST_F(BaselinesCli, HoldTheirGroundTruthsInGustsAndASteadyWindWithoutACrash) {
  struct Case {
    const char* file;
    const char* controller;
    double max_rms_m;  // the bound each baseline holds (docs/results/baselines.md has its figures)
  };
  for (const Case& c : {Case{"outside-heli.toml", "baseline:linear", 0.5},
                        Case{"ros-crazyflie.toml", "baseline:cascaded-pd", 0.3},
                        Case{"heavy-heli.toml", "baseline:linear", 0.5}}) {
    for (const char* wind : {"0,0,0", "0,4,0"}) {
      const std::string run = std::string(c.file) + "-" + wind;
      const auto r = run_pegasus(
          fmt::format("fly --vehicle {} --baseline --flights 3 --seconds 20 --wind {} --start-pos-sigma 0.3 "
                      "--start-vel-sigma 0.1 --seed 5 --quiet --out {}",
                      vehicle(c.file), wind, path(run)));
      ASSERT_EQ(r.code, 0) << r.output;
      const auto s = summary(run);
      EXPECT_EQ(s.at("controller"), c.controller);
      EXPECT_EQ(s.at("crashes").get<int>(), 0) << run;
      EXPECT_LT(s.at("rms_position_m").get<double>(), c.max_rms_m) << run;
      // The mean of the flights' judged costs, each a sum of nonnegative terms.
      const std::vector<double> costs = per_flight_costs(run);
      ASSERT_EQ(costs.size(), 3u);
      double sum = 0;
      for (const double x : costs) {
        EXPECT_GT(x, 0);
        sum += x;
      }
      EXPECT_NEAR(s.at("judged_cost").get<double>(), sum / 3, 1e-9 * sum);
    }
  }
}

TEST_F(BaselinesCli, TheBaselineOrThePilotNotBoth) {
  const auto r = run_pegasus(fmt::format("fly --vehicle {} --baseline --pilot --quiet --out {}",
                                         vehicle("ros-crazyflie.toml"), path("both")));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--pilot, --baseline"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "both"));
}

}  // namespace
