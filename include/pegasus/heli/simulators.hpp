#pragma once
// The built-in ground truths by the name a vehicle file's `[vehicle] simulator` gives them ("xcell",
// "crazyflie2"), each with the scripted pilot tuned to fly it.
#include <memory>
#include <string>
#include <vector>

#include "pegasus/heli/ground_truth.hpp"
#include "pegasus/heli/pilot.hpp"

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
};

// The simulators `[vehicle] simulator` may name ("none" included: a vehicle without a ground truth).
std::vector<std::string> simulator_names();
// The ground truth of `simulator` with the settings; throws std::invalid_argument for an unknown name or
// settings the aircraft rejects.
std::unique_ptr<GroundTruth> make_ground_truth(const std::string& simulator,
                                               const GroundTruthSettings& settings);
// The turbulence standard deviation that aircraft flies in by default (its params' gust_sigma), m/s.
double own_gust_sigma(const std::string& simulator);
// The scripted pilot's options for that aircraft.
PilotOptions pilot_options_for(const std::string& simulator);

}  // namespace pegasus::heli
