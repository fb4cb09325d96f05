// The hover scenarios' wind (issue 53 item 2, heli/training_wind.hpp): with a vehicle file and none stated,
// the default by the model class identify chose: the documented wind for a global linear model, calm for a
// locally weighted one (whose query crashes beyond the logs' airspeeds); a stated wind is taken as it is.
#include "pegasus/heli/training_wind.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "heli/hover_fixtures.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::heli::training_wind_test {
namespace {

TEST(TrainingWind, DefaultIsTheDocumentedWindForAGlobalLinearModelAndCalmForALocallyWeightedOne) {
  const auto global = test_fixtures::identify_pilot_flight(false, false),
             local = test_fixtures::identify_pilot_flight(false, true);
  ASSERT_TRUE(global->is_global());
  ASSERT_FALSE(local->is_global());
  // Global linear: a steady wind from every direction (drawn per scenario, none stated) and light gusts.
  const TrainingWind g = default_training_wind(*global);
  EXPECT_EQ(g.disturbance.wind, (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(g.disturbance.wind_sigma, 1.5);
  EXPECT_EQ(g.disturbance.gust_sigma, 0.5);
  EXPECT_EQ(g.disturbance.gust_tau_s, 1.0);
  EXPECT_EQ(g.by, "default for a global linear model");
  // Locally weighted: calm, and the reason quotes the logs' airspeeds.
  const TrainingWind l = default_training_wind(*local);
  EXPECT_TRUE(l.disturbance.calm());
  EXPECT_EQ(l.by, "default for a locally weighted model");
  // The logs' horizontal airspeed RMS, by hand over the training rows; in the line.
  double sum = 0;
  const auto& x = local->data().x;
  for (Eigen::Index i = 0; i < x.rows(); ++i)
    sum += x(i, sysid::kU) * x(i, sysid::kU) + x(i, sysid::kV) * x(i, sysid::kV);
  const double rms = std::sqrt(sum / static_cast<double>(x.rows()));
  EXPECT_GT(rms, 0.0);
  EXPECT_NEAR(logs_horizontal_airspeed_rms(*local), rms, 1e-12 * rms);
  EXPECT_NE(training_wind_line(l).find(fmt::format("(horizontal RMS {:.2g} m/s)", rms)), std::string::npos)
      << training_wind_line(l);
  EXPECT_NE(
      training_wind_line(g).find("drawn +- 1.5 m/s per horizontal axis per scenario, AR(1) gusts of 0.5 m/s"),
      std::string::npos)
      << training_wind_line(g);
}

TEST(TrainingWind, AStatedWindIsTakenAsItIsAndTheXCellWithoutAVehicleFileStaysCalm) {
  const auto global = test_fixtures::identify_pilot_flight(false, false);
  const sysid::Disturbance stated{.wind = {0, 1, 0}, .wind_sigma = 0, .gust_sigma = 0, .gust_tau_s = 2};
  for (const WindSource source : {WindSource::kOptions, WindSource::kVehicleFile}) {
    const TrainingWind w = training_wind(source, stated, *global);
    EXPECT_EQ(w.disturbance.wind, stated.wind);
    EXPECT_EQ(w.disturbance.wind_sigma, 0.0);
    EXPECT_EQ(w.disturbance.gust_sigma, 0.0);
  }
  // A stated calm stays calm: only an unstated wind takes the default.
  EXPECT_TRUE(training_wind(WindSource::kVehicleFile, sysid::Disturbance{}, *global).disturbance.calm());
  EXPECT_TRUE(training_wind(WindSource::kNoVehicleFile, sysid::Disturbance{}, *global).disturbance.calm());
  EXPECT_EQ(training_wind(WindSource::kDefault, sysid::Disturbance{}, *global).disturbance.wind_sigma, 1.5);
}

}  // namespace
}  // namespace pegasus::heli::training_wind_test
