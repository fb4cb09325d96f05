// The manoeuvre's training wind as its config resolves it (issue 53): the vehicle file's [hover.wind] fills
// the wind.* fields as it does hover's, an option wins over the file, and with neither the source says none
// was stated (run_maneuver then trains calm).
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "logs/outside_aircraft.hpp"
#include "pegasus/heli/runs/maneuver_config.hpp"
#include "support/cli_runner.hpp"

namespace pegasus::heli {
namespace {

class ManeuverWindConfig : public test_support::TempDirTest {
 protected:
  // The manoeuvre's options for the outside helicopter's vehicle file with `more` appended, after the
  // command's resolve step, with `wind_steady` set as an option first when given.
  ManeuverRunOptions read(const std::string& more, const std::vector<double>& wind_steady = {}) {
    const std::filesystem::path file = dir_ / "v.toml";
    std::ofstream(file) << test_support::kOutsideVehicle << "\n" << more;
    ConfigSchema s;
    declare_maneuver_config(s);
    s.set("vehicle", file.string(), "--vehicle");
    if (!wind_steady.empty()) s.set("wind.steady", wind_steady, "--wind.steady");
    resolve_maneuver_config(s);
    return read_maneuver_config(s, 1);
  }
};

TEST_F(ManeuverWindConfig, TheVehicleFilesWindIsTrainedInAnOptionWinsAndNoneStatedIsSaid) {
  const std::string windy = "[hover.wind]\nsteady = [0, 1, 0]\nsigma = 0.5\ngust_sigma = 0.2\n";
  const ManeuverRunOptions from_file = read(windy);
  EXPECT_EQ(from_file.wind_source, WindSource::kVehicleFile);
  EXPECT_EQ(from_file.training.disturbance.wind, (std::array<double, 3>{0, 1, 0}));
  EXPECT_EQ(from_file.training.disturbance.wind_sigma, 0.5);
  EXPECT_EQ(from_file.training.disturbance.gust_sigma, 0.2);

  const ManeuverRunOptions option = read(windy, {2, 0, 0});
  EXPECT_EQ(option.wind_source, WindSource::kOptions);
  EXPECT_EQ(option.training.disturbance.wind, (std::array<double, 3>{2, 0, 0}));

  const ManeuverRunOptions none = read("");
  EXPECT_EQ(none.wind_source, WindSource::kDefault);
  EXPECT_TRUE(none.training.disturbance.calm());
}

}  // namespace
}  // namespace pegasus::heli
