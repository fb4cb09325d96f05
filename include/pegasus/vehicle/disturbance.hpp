#pragma once
// The wind an aircraft flies in, as the learned model's scenarios draw it (sysid/learned_model.hpp says how
// it acts) and as a vehicle file's [hover.wind] states it. Part of the vehicle layer: a Vehicle carries one,
// and the models and commands above read it.
#include <array>
#include <string>
#include <vector>

#include "pegasus/core/number_setting.hpp"

namespace pegasus::sysid {

// One setting of Disturbance, described once (Disturbance::VisitFields). From it come `hover`'s and
// `maneuver`'s options `wind.KEY` (help, bounds, the default), a vehicle file's `[hover.wind] KEY` (allowed,
// read, bounded), the reading of both, IsValid, summary.json's `wind` object and the Python field.
struct DisturbanceSetting : NumberSetting {  // key: after `wind.` in a config, and in [hover.wind]
  const char* field;                         // Disturbance's member, and Python's field
  const char* summary_key;                   // in summary.json's `wind`
};

// The largest steady wind component a setting takes, m/s: the scenarios' (Disturbance::wind) and a flight's
// (heli::GroundTruthSettings::mean_wind_W).
inline constexpr double kMaxSteadyWindMps = 30;

// The wind the learned model flies in (see above); all zero: calm, as identified.
struct Disturbance {
  std::array<double, 3> wind{0, 0, 0};  // steady wind north, east, down, m/s (W)
  double wind_sigma = 0;                // per-scenario steady wind draw per horizontal axis, m/s
  double gust_sigma = 0;                // AR(1) gust's standard deviation per axis, m/s
  double gust_tau_s = 2;                // its correlation time, s
  bool calm() const { return wind == std::array<double, 3>{0, 0, 0} && wind_sigma == 0 && gust_sigma == 0; }
  bool IsValid(std::string* error) const;

  // Every setting, once: the visitor's `setting(DisturbanceSetting, &Disturbance::member)` for each, member
  // a double or the steady wind's 3 numbers. A new setting: its member, its entry here, its use in the model.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using D = Disturbance;
    v.setting(
        {{"steady", -kMaxSteadyWindMps, kMaxSteadyWindMps, false, "m/s",
          "steady wind in the scenarios, north, east, down (m/s, NED): the learned model's forces act on "
          "the airspeed"},
         "wind",
         "steady_ned_mps"},
        &D::wind);
    v.setting(
        {{"sigma", 0, 30, false, "m/s",
          "each scenario's steady wind drawn about wind.steady, per horizontal axis, m/s; with a vehicle "
          "file and no wind.* or [hover.wind] stated, the default by the model class (1.5 m/s and 0.5 "
          "m/s gusts for a global linear model, calm for a locally weighted one)"},
         "wind_sigma",
         "sigma_mps"},
        &D::wind_sigma);
    v.setting({{"gust_sigma", 0, 30, false, "m/s",
                "AR(1) gusts in the scenarios: standard deviation per axis, m/s"},
               "gust_sigma",
               "gust_sigma_mps"},
              &D::gust_sigma);
    v.setting(
        {{"gust_tau_s", 0, 3600, true, "s", "AR(1) gusts: correlation time, s"}, "gust_tau_s", "gust_tau_s"},
        &D::gust_tau_s);
  }
  // The settings in VisitFields's order.
  static const std::vector<DisturbanceSetting>& settings();
};

}  // namespace pegasus::sysid
