#pragma once
// The ground truths by the name a vehicle file's `[vehicle] simulator` gives them, in one registry: each
// entry says what the aircraft is, how to build it with the commands' settings, the turbulence it flies in,
// and the scripted pilot tuned to fly it. "xcell" (aircraft.hpp) and "crazyflie2" (quadrotor.hpp) are built
// in; another aircraft adds one entry (register_ground_truth, or a line of the built-in table in
// src/heli/simulators.cpp), and every command, help text and error message that names ground truths reads it.
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pegasus/heli/ground_truth.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/vehicle/disturbance.hpp"

namespace pegasus::heli {

// What the commands change on any built-in aircraft; unset fields keep the aircraft's own values.
struct GroundTruthSettings {
  double gust_sigma = -1;      // m/s; < 0: the aircraft's own
  bool estimate_noise = true;  // false: the controller sees the true state
  bool set_start = false;      // true: start_p_W and start_yaw below replace the aircraft's start
  Vec3 start_p_W = Vec3::Zero();
  double start_yaw = 0;
  double start_pos_sigma = 0, start_vel_sigma = 0;  // m, m/s
  Vec3 mean_wind_W = Vec3::Zero();                  // steady wind added to the aircraft's own, m/s in W

  // What a user sets of these, once (issue 49 item 1): `fly`'s `wind` (a NumberList, each component within
  // the bounds), `pilot`'s and `fly`'s `estimate_noise` switch; their options, reading and help come from
  // here. The gusts' default is the aircraft's own (heli_config's declare_gust_sigma) and the start's spread
  // hover training's (HoverTrainingOptions), so they are described there.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    v.setting({"wind", -sysid::kMaxSteadyWindMps, sysid::kMaxSteadyWindMps, false, "m/s",
               "steady wind north, east, down (m/s, W), under the gusts"},
              &GroundTruthSettings::mean_wind_W);
  }
  template <class Visitor>
  static void VisitFlags(Visitor& v) {
    v.flag(
        {"estimate_noise",
         "Kalman-filter-like state-estimate errors: in the pilot's log, and in what a flown controller sees "
         "(false: the true state)"},
        &GroundTruthSettings::estimate_noise);
  }
};

// The settings applied to an aircraft's flight conditions (its start and disturbances).
void apply_settings(const GroundTruthSettings& settings, FlightConditions& conditions);

// The ground truth with the settings; throws std::invalid_argument for settings the aircraft rejects.
using GroundTruthFactory = std::function<std::unique_ptr<GroundTruth>(const GroundTruthSettings&)>;

// One registered ground truth.
struct GroundTruthEntry {
  std::string name;  // as `[vehicle] simulator` writes it
  std::string doc;   // one line: the aircraft it simulates
  GroundTruthFactory make;
  double own_gust_sigma = 0;  // the turbulence it flies in by default (its params' gust_sigma), m/s
  PilotOptions pilot;         // the scripted pilot's options for it
  // Its hand-tuned baseline (heli/baselines.hpp), flown by `fly --baseline`: a name ("linear",
  // "cascaded-pd"; empty: none) and its gains.
  std::string baseline_name{};
  BaselineGains baseline{};
};

// The factory of Model built from `params` (an aircraft's params struct: IsValid and a FlightConditions
// member `conditions`): the settings applied to a copy's conditions, which must then be valid.
template <class Model, class Params>
GroundTruthFactory ground_truth_factory(Params params) {
  return [params](const GroundTruthSettings& settings) -> std::unique_ptr<GroundTruth> {
    Params p = params;
    apply_settings(settings, p.conditions);
    std::string error;
    if (!p.IsValid(&error)) throw std::invalid_argument(error);
    return std::make_unique<Model>(p);
  };
}

// Adds a ground truth, or replaces the one of that name (keeping its place). Thread-safe; call before flying.
// Throws std::invalid_argument for an empty name, "none" (a vehicle without one) or an entry without make.
void register_ground_truth(GroundTruthEntry entry);
// The registered ground truths, built-ins first, then in registration order (a copy).
std::vector<GroundTruthEntry> ground_truths();
// The names `[vehicle] simulator` may give: "none" (a vehicle without a ground truth), then the registered.
std::vector<std::string> simulator_names();
// The registered names joined by ", " (for help texts and messages).
std::string ground_truth_list();

// The registered entry of `simulator`; throws std::invalid_argument naming the registered ones.
GroundTruthEntry ground_truth_entry(const std::string& simulator);
// The ground truth of `simulator` with the settings; throws std::invalid_argument for an unknown name or
// settings the aircraft rejects.
std::unique_ptr<GroundTruth> make_ground_truth(const std::string& simulator,
                                               const GroundTruthSettings& settings);
// The turbulence standard deviation that aircraft flies in by default, m/s; throws std::invalid_argument for
// an unknown name.
double own_gust_sigma(const std::string& simulator);
// The scripted pilot's options for that aircraft (the default PilotOptions for a name not registered).
PilotOptions pilot_options_for(const std::string& simulator);

}  // namespace pegasus::heli
