#include "pegasus/heli/simulators.hpp"

#include <stdexcept>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/quadrotor.hpp"

namespace pegasus::heli {
namespace {

// The settings on either aircraft's params (the same field names in both).
template <class Params>
void apply(const GroundTruthSettings& s, Params& p) {
  if (s.gust_sigma >= 0) p.gust_sigma = s.gust_sigma;
  if (!s.estimate_noise) p.est_sigma_pos = p.est_sigma_vel = p.est_sigma_angle = p.est_sigma_rate = 0;
  if (s.set_start) {
    p.start_p_W = s.start_p_W;
    p.start_yaw = s.start_yaw;
  }
  p.start_pos_sigma = s.start_pos_sigma;
  p.start_vel_sigma = s.start_vel_sigma;
  p.mean_wind_W += s.mean_wind_W;
  std::string error;
  if (!p.IsValid(&error)) throw std::invalid_argument(error);
}

}  // namespace

std::vector<std::string> simulator_names() { return {"none", "xcell", "crazyflie2"}; }

std::unique_ptr<GroundTruth> make_ground_truth(const std::string& simulator,
                                               const GroundTruthSettings& settings) {
  if (simulator == "xcell") {
    AircraftParams p;
    apply(settings, p);
    return std::make_unique<Aircraft>(p);
  }
  if (simulator == "crazyflie2") {
    QuadrotorParams p;
    apply(settings, p);
    return std::make_unique<Quadrotor>(p);
  }
  throw std::invalid_argument("no ground truth named '" + simulator + "' (built in: xcell, crazyflie2)");
}

double own_gust_sigma(const std::string& simulator) {
  if (simulator == "xcell") return AircraftParams{}.gust_sigma;
  if (simulator == "crazyflie2") return QuadrotorParams{}.gust_sigma;
  throw std::invalid_argument("no ground truth named '" + simulator + "' (built in: xcell, crazyflie2)");
}

PilotOptions pilot_options_for(const std::string& simulator) {
  PilotOptions o;
  if (simulator == "crazyflie2") {
    // The quadrotor holds its own attitude (angle mode): the pilot commands the tilt it wants instead of
    // feeding back the attitude, and sweeps the collective gently (it moves the aircraft 10x harder per
    // stick than the X-Cell's).
    const QuadrotorParams q;
    o.k_att = 0;
    o.k_att_rate = 0;
    o.attitude_command_gain = 1 / q.max_tilt_command_rad;
    o.sweep_amplitude = {0.15, 0.15, 0.05, 0.15};
  }
  return o;
}

}  // namespace pegasus::heli
