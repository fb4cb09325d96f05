// The hover scenarios' wind: the stated one or the default by the model class (issue 53 item 2).
#include "pegasus/heli/training_wind.hpp"

#include <fmt/format.h>

#include <cmath>
#include <numbers>

namespace pegasus::heli {

namespace {

std::string disturbance_text(const sysid::Disturbance& d) {
  if (d.calm()) return "calm";
  return fmt::format(
      "steady [{:g}, {:g}, {:g}] m/s NED, drawn +- {:g} m/s per horizontal axis per scenario, AR(1) gusts of "
      "{:g} m/s with a correlation time of {:g} s",
      d.wind[0], d.wind[1], d.wind[2], d.wind_sigma, d.gust_sigma, d.gust_tau_s);
}

}  // namespace

double logs_horizontal_airspeed_rms(const sysid::IdentifiedModel& model) {
  const auto& x = model.data().x;
  if (x.rows() == 0) return 0;
  const double sum = x.col(sysid::kU).squaredNorm() + x.col(sysid::kV).squaredNorm();
  return std::sqrt(sum / static_cast<double>(x.rows()));
}

TrainingWind default_training_wind(const sysid::IdentifiedModel& model) {
  const double rms = logs_horizontal_airspeed_rms(model);
  if (!model.is_global())
    return {
        .disturbance = {},
        .by = "default for a locally weighted model",
        .reason = fmt::format(
            "calm: the locally weighted model crashes where the airspeed leaves the logs' (horizontal RMS "
            "{:.2g} m/s), so wind in its scenarios would train on crashes; state one with [hover.wind] or "
            "--wind.* within the logs' airspeeds",
            rms)};
  const sysid::Disturbance d = kDefaultTrainingWind;
  return {.disturbance = d,
          .by = "default for a global linear model",
          .reason = fmt::format(
              "a steady wind from every direction (mean speed {:.2g} m/s) and light turbulence, so that the "
              "integral term is trained where the aircraft will fly; the global linear model's forces are "
              "linear in the airspeed, so no draw leaves its support (the logs' horizontal airspeed RMS: "
              "{:.2g} m/s)",
              d.wind_sigma * std::sqrt(std::numbers::pi / 2), rms)};
}

TrainingWind training_wind(WindSource source, const sysid::Disturbance& stated,
                           const sysid::IdentifiedModel& model) {
  switch (source) {
    case WindSource::kDefault:
      return default_training_wind(model);
    case WindSource::kOptions:
      return {.disturbance = stated, .by = "options", .reason = "as the wind.* options state it"};
    case WindSource::kVehicleFile:
      return {.disturbance = stated,
              .by = "vehicle file",
              .reason = "as the vehicle file's [hover.wind] states it"};
    case WindSource::kNoVehicleFile:
      break;
  }
  return {.disturbance = stated, .by = "no vehicle file", .reason = "calm, as the thesis trains the X-Cell"};
}

std::string training_wind_line(const TrainingWind& w) {
  return fmt::format("wind in the scenarios ({}): {}: {}", w.by, disturbance_text(w.disturbance), w.reason);
}

}  // namespace pegasus::heli
