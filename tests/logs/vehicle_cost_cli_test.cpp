// `pegasus hover` with a vehicle file that states its judged cost (issue 53 item 3): the cost is the reward,
// whole (the printed line names only its terms, the summary records them), and a reward.* option beside it
// stops the run with one line, exit 2 and no run directory.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "outside_aircraft.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "support/cli_runner.hpp"

namespace {

using namespace pegasus;
using test_support::run_pegasus;

class JudgedCostCli : public test_support::TempDirTest {
 protected:
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }
};

TEST_F(JudgedCostCli, TheVehiclesJudgedCostIsTheWholeReward) {
  // One pilot flight of the X-Cell as the outside aircraft's 10 Hz log, identified for it.
  auto r = run_pegasus(fmt::format("heli pilot --seconds 90 --seed 1 --quiet --out {}", path("pilot")));
  ASSERT_EQ(r.code, 0) << r.output;
  const sysid::FlightLog own =
      test_support::every_nth_row(sysid::read_flight_log(dir_ / "pilot" / "log.csv"), 5);
  write("train.csv", test_support::outside_log_csv(own));
  write("cost.toml", std::string(test_support::kOutsideVehicle) +
                         "\n[cost]\nposition = [1, 1, 2]\nvelocity = [0.5, 0.5, 0.5]\ncrash = 1000\n");
  r =
      run_pegasus(fmt::format("identify --vehicle {} --train {} --test {} --cv-points 40 --scale-grid 1,4 "
                              "--coordinate-passes 0 --variants=false --quiet --out {}",
                              path("cost.toml"), path("train.csv"), path("train.csv"), path("id")));
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string hover = fmt::format(
      "hover --vehicle {} --model {} --scenarios 3 --seconds 2 --optimizer.gradient.max-iterations 1 "
      "--then-hill-climb=false --max-start-crash-fraction 1 --quiet",
      path("cost.toml"), path("id/model.json"));
  r = run_pegasus(hover + " --out " + path("hover"));
  ASSERT_EQ(r.code, 0) << r.output;
  // Only the stated terms: no yaw, action, attitude or rate term of the default reward.
  EXPECT_NE(r.output.find("reward (the vehicle file's [cost], whole): position x y z 1 1 2 /m^2; velocity x "
                          "y z 0.5 0.5 0.5 /(m/s)^2; crash 1000 "),
            std::string::npos)
      << r.output;
  const auto summary = nlohmann::json::parse(test_support::read_text(dir_ / "hover" / "summary.json"));
  EXPECT_EQ(summary["judged_cost"]["crash_penalty"], 1000.0) << summary.dump();
  // No wind stated: the default by the model class identify chose (heli/training_wind.hpp), in one line and
  // in the summary's choices; wind in the scenarios only for a global linear model.
  const bool global = summary["choices"]["model_class"] == "global linear";
  const std::string by =
      global ? "default for a global linear model" : "default for a locally weighted model";
  EXPECT_EQ(summary["choices"]["wind"]["by"], by) << summary.dump();
  EXPECT_NE(r.output.find("wind in the scenarios (" + by + "): " + (global ? "steady" : "calm")),
            std::string::npos)
      << r.output;
  EXPECT_EQ(summary.contains("wind"), global) << summary.dump();
  // Stated, by an option (a calm one) or by the file's [hover.wind]: taken as stated.
  r = run_pegasus(hover + " --wind.sigma 0 --out " + path("calm"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto calm = nlohmann::json::parse(test_support::read_text(dir_ / "calm" / "summary.json"));
  EXPECT_EQ(calm["choices"]["wind"]["by"], "options") << calm.dump();
  EXPECT_FALSE(calm.contains("wind")) << calm.dump();
  write("wind.toml", test_support::read_text(dir_ / "cost.toml") + "\n[hover.wind]\nsteady = [0, 1, 0]\n");
  r = run_pegasus(fmt::format(
      "hover --vehicle {} --model {} --scenarios 3 --seconds 2 --optimizer.gradient.max-iterations 1 "
      "--then-hill-climb=false --max-start-crash-fraction 1 --quiet --out {}",
      path("wind.toml"), path("id/model.json"), path("stated")));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto stated = nlohmann::json::parse(test_support::read_text(dir_ / "stated" / "summary.json"));
  EXPECT_EQ(stated["choices"]["wind"]["by"], "vehicle file") << stated.dump();
  EXPECT_EQ(stated["wind"]["sigma_mps"], 0.0) << stated.dump();
  EXPECT_EQ(stated["wind"]["gust_sigma_mps"], 0.0) << stated.dump();
  // The default reward's options beside it: refused, naming the option.
  r = run_pegasus(hover + " --reward.action 0.1 --out " + path("refused"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("reward.action (--reward.action): the vehicle file's [cost] is the whole reward"),
            std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "refused"));
  // Turned off, the default reward (its yaw term among others) is back.
  r = run_pegasus(hover + " --reward.judged-cost=false --out " + path("default"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("reward (the reward.* options): position x y z 4 4 4 /m^2"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("yaw 100 /rad^2"), std::string::npos) << r.output;
}

}  // namespace
