// The hover config's judged cost, envelope limits and wind (issue 53): the fields, their values from a
// vehicle file's [cost], [envelope] and [hover.wind], and the training options they give.
#include "vehicle_cost_config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "pegasus/core/error.hpp"

namespace pegasus::heli {

namespace {

// The reward `hover` trains on: the vehicle file's judged cost, whole, or the typical sizes' reward.
// Whether it is the judged cost.
bool read_reward(const ConfigSchema& c, const logs::Vehicle& v, HoverTrainingOptions& o) {
  if (c.get_bool("reward.judged_cost")) {
    if (!v.cost)
      throw InputError(fmt::format("reward.judged_cost ({}): expected a vehicle file with a [cost] section",
                                   c.origin("reward.judged_cost")));
    std::vector<std::string> fields;
    for (const HoverRewardSize& size : HoverReward::sizes())
      fields.push_back(std::string("reward.") + size.key);
    fields.emplace_back("reward.action_centre");
    for (const std::string& field : fields)
      if (c.origin(field) != "default")
        throw InputError(
            fmt::format("{} ({}): the vehicle file's [cost] is the whole reward; expected no "
                        "reward.* option with it (or reward.judged_cost = false)",
                        field, c.origin(field)));
    o.reward = logs::judged_reward(v);
    o.centre_at_trim = v.cost->controls_about_trim;
    return true;
  }
  // Each weight from its size (alpha = 1 / size^2); the centre stays 0 (training moves it to the trim when
  // centre_at_trim).
  o.reward = HoverReward{};
  for (const HoverRewardSize& size : HoverReward::sizes())
    o.reward.set_typical(size, c.get_double(std::string("reward.") + size.key));
  o.centre_at_trim = c.get_string("reward.action_centre") == "trim";
  return false;
}

double limit_of(const ConfigSchema& c, const char* field) {
  const double x = c.get_double(field);
  return x > 0 ? x : std::numeric_limits<double>::infinity();
}

}  // namespace

namespace {

// `wind.KEY` for each of Disturbance::VisitFields's settings.
std::string wind_option(const sysid::DisturbanceSetting& setting) {
  return std::string("wind.") + setting.key;
}

// Declares each setting as an option, its default Disturbance{}'s.
struct DeclareWind {
  ConfigSchema& s;
  sysid::Disturbance defaults;
  void setting(const sysid::DisturbanceSetting& d, double sysid::Disturbance::*member) {
    s.add_double(wind_option(d), defaults.*member, d.help).bounds(d);
  }
  void setting(const sysid::DisturbanceSetting& d, std::array<double, 3> sysid::Disturbance::*member) {
    const auto& w = defaults.*member;
    s.add_double_list(wind_option(d), {w.begin(), w.end()}, d.help).bounds(d).size(w.size());
  }
};

// Reads each option into its member.
struct ReadWind {
  const ConfigSchema& c;
  sysid::Disturbance d;
  void setting(const sysid::DisturbanceSetting& s, double sysid::Disturbance::*member) {
    d.*member = c.get_double(wind_option(s));
  }
  void setting(const sysid::DisturbanceSetting& s, std::array<double, 3> sysid::Disturbance::*member) {
    const auto& w = c.get_double_list(wind_option(s));
    std::copy(w.begin(), w.end(), (d.*member).begin());
  }
};

// Sets each option from the vehicle file's [hover.wind] KEY.
struct WindFromVehicle {
  ConfigSchema& s;
  const logs::Vehicle& v;
  template <class T>
  void setting(const sysid::DisturbanceSetting& d, T sysid::Disturbance::*member) {
    const T& value = (*v.wind).*member;
    FieldValue field_value;
    if constexpr (std::is_same_v<T, double>)
      field_value = value;
    else
      field_value = std::vector<double>(value.begin(), value.end());
    set_from_vehicle(s, v, wind_option(d), std::move(field_value), std::string("hover.wind.") + d.key);
  }
};

}  // namespace

void declare_training_wind(ConfigSchema& s) {
  DeclareWind v{s, {}};
  sysid::Disturbance::VisitFields(v);
}

sysid::Disturbance read_training_wind(const ConfigSchema& c) {
  ReadWind v{c, {}};
  sysid::Disturbance::VisitFields(v);
  return v.d;
}

void resolve_training_wind(ConfigSchema& s, const logs::Vehicle& v) {
  // Each of [hover.wind]'s fields, also where calm: a stated calm is no default (heli/training_wind.hpp).
  if (!v.wind) return;
  WindFromVehicle visitor{s, v};
  sysid::Disturbance::VisitFields(visitor);
}

void declare_hover_cost_and_wind(ConfigSchema& s) {
  const HoverTrainingOptions defaults;
  s.add_bool(
      "reward.judged_cost", false,
      "the vehicle file's [cost] is the whole reward (every other reward.* term left out); on when the "
      "file has a [cost] section");
  s.add_double(
       "crash_penalty", defaults.crash_penalty,
       "what a crash of the learned model costs (thesis footnote 13: 50000); with a vehicle file, its "
       "[cost] crash")
      .range(0, 1e12);
  s.add_double(
       "max_position_error_m", 0,
       "the envelope: a distance from the set point beyond this crashes the learned model, m; 0: none")
      .range(0, 1e12);
  s.add_double("max_speed_mps", 0,
               "the envelope: a speed beyond this crashes the learned model, m/s; 0: none")
      .range(0, 1e12);
  s.add_double("max_rate_radps", 0,
               "the envelope: any Euler-angle rate beyond this crashes the learned model, rad/s; 0: none")
      .range(0, 1e12);
  declare_training_wind(s);
}

void resolve_hover_cost_and_wind(ConfigSchema& s, const logs::Vehicle& vehicle) {
  const logs::Vehicle* v = &vehicle;
  if (v->cost) {
    set_from_vehicle(s, *v, "reward.judged_cost", true, "cost");
    set_from_vehicle(s, *v, "crash_penalty", v->cost->crash, "cost.crash");
  }
  const auto limit = [&](const char* field, double value, const char* key) {
    if (std::isfinite(value)) set_from_vehicle(s, *v, field, value, key);
  };
  limit("max_position_error_m", v->max_position_error_m, "envelope.max_position_error");
  limit("max_speed_mps", v->max_speed_mps, "envelope.max_speed");
  limit("max_rate_radps", v->max_rate_radps, "envelope.max_rate");
  resolve_training_wind(s, vehicle);
}

bool read_hover_cost_and_wind(const ConfigSchema& c, const logs::Vehicle& v, HoverTrainingOptions& o) {
  const bool judged = read_reward(c, v, o);
  o.crash_penalty = c.get_double("crash_penalty");
  o.max_position_error_m = limit_of(c, "max_position_error_m");
  o.max_speed_mps = limit_of(c, "max_speed_mps");
  o.max_rate_radps = limit_of(c, "max_rate_radps");
  o.disturbance = read_training_wind(c);
  return judged;
}

WindSource hover_wind_source(const ConfigSchema& c, const VehicleChoice& aircraft) {
  const logs::Vehicle& v = aircraft.vehicle;
  const std::string from_file = v.log.file + ": hover.wind.";
  for (const sysid::DisturbanceSetting& setting : sysid::Disturbance::settings())
    if (const std::string& origin = c.origin(wind_option(setting));
        origin != "default" && !origin.starts_with(from_file))
      return WindSource::kOptions;
  if (v.wind) return WindSource::kVehicleFile;
  return aircraft.from_file() ? WindSource::kDefault : WindSource::kNoVehicleFile;
}

}  // namespace pegasus::heli
