#include "pegasus/heli/simulators.hpp"

#include "pegasus/core/named_registry.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/quadrotor.hpp"

namespace pegasus::heli {
namespace {

// The quadrotor holds its own attitude (angle mode): the pilot commands the tilt it wants instead of feeding
// back the attitude, and sweeps the collective gently (it moves the aircraft 10x harder per stick than the
// X-Cell's).
PilotOptions crazyflie_pilot() {
  const QuadrotorParams q;
  PilotOptions o;
  o.k_att = 0;
  o.k_att_rate = 0;
  o.attitude_command_gain = 1 / q.max_tilt_command_rad;
  o.sweep_amplitude = {0.15, 0.15, 0.05, 0.15};
  return o;
}

// The ground truths every build knows. A new aircraft adds its line here (its model lives in its own files).
std::vector<GroundTruthEntry> builtin_ground_truths() {
  return {{"xcell", "the X-Cell 60 helicopter (heli/aircraft.hpp)",
           ground_truth_factory<Aircraft>(AircraftParams{}), AircraftParams{}.conditions.gust_sigma,
           PilotOptions{}},
          {"crazyflie2", "the Crazyflie 2.0 quadrotor in angle mode (heli/quadrotor.hpp)",
           ground_truth_factory<Quadrotor>(QuadrotorParams{}), QuadrotorParams{}.conditions.gust_sigma,
           crazyflie_pilot()}};
}

NamedRegistry<GroundTruthEntry>& ground_truth_registry() {
  static NamedRegistry<GroundTruthEntry> r(builtin_ground_truths());
  return r;
}

// The entry of `simulator`; throws std::invalid_argument naming the registered ones.
GroundTruthEntry entry_of(const std::string& simulator) {
  if (std::optional<GroundTruthEntry> e = ground_truth_registry().find(simulator)) return std::move(*e);
  throw std::invalid_argument("no ground truth named '" + simulator +
                              "' (registered: " + ground_truth_list() + ")");
}

}  // namespace

void apply_settings(const GroundTruthSettings& s, FlightConditions& c) {
  if (s.gust_sigma >= 0) c.gust_sigma = s.gust_sigma;
  if (!s.estimate_noise) c.est_sigma_pos = c.est_sigma_vel = c.est_sigma_angle = c.est_sigma_rate = 0;
  if (s.set_start) {
    c.start_p_W = s.start_p_W;
    c.start_yaw = s.start_yaw;
  }
  c.start_pos_sigma = s.start_pos_sigma;
  c.start_vel_sigma = s.start_vel_sigma;
  c.mean_wind_W += s.mean_wind_W;
}

void register_ground_truth(GroundTruthEntry entry) {
  if (entry.name.empty() || entry.name == "none")
    throw std::invalid_argument("register_ground_truth: expected a name other than '' and 'none', got '" +
                                entry.name + "'");
  if (!entry.make)
    throw std::invalid_argument("register_ground_truth: '" + entry.name + "' has no make function");
  ground_truth_registry().add(std::move(entry));
}

std::vector<GroundTruthEntry> ground_truths() { return ground_truth_registry().entries(); }

std::vector<std::string> simulator_names() {
  std::vector<std::string> names = {"none"};
  for (const GroundTruthEntry& e : ground_truths()) names.push_back(e.name);
  return names;
}

std::string ground_truth_list() {
  std::string list;
  for (const GroundTruthEntry& e : ground_truths()) list += (list.empty() ? "" : ", ") + e.name;
  return list;
}

std::unique_ptr<GroundTruth> make_ground_truth(const std::string& simulator,
                                               const GroundTruthSettings& settings) {
  return entry_of(simulator).make(settings);
}

double own_gust_sigma(const std::string& simulator) { return entry_of(simulator).own_gust_sigma; }

PilotOptions pilot_options_for(const std::string& simulator) {
  for (const GroundTruthEntry& e : ground_truths())
    if (e.name == simulator) return e.pilot;
  return {};
}

}  // namespace pegasus::heli
