#include "pegasus/heli/baselines.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "pegasus/heli/simulators.hpp"

namespace pegasus::heli {

std::string baseline_name(const std::string& simulator) {
  const GroundTruthEntry entry = ground_truth_entry(simulator);
  if (!entry.baseline_name.empty()) return entry.baseline_name;
  std::string with;
  for (const GroundTruthEntry& e : ground_truths())
    if (!e.baseline_name.empty()) with += (with.empty() ? "" : ", ") + e.name;
  throw std::invalid_argument("no baseline for the ground truth '" + simulator + "' (baselines: " + with +
                              ")");
}

BaselineGains baseline_gains(const std::string& simulator) {
  const GroundTruthEntry entry = ground_truth_entry(simulator);
  if (entry.baseline_name.empty()) baseline_name(simulator);  // throws, naming those that have one
  return entry.baseline;
}

BaselineController::BaselineController(const GroundTruth& aircraft, BaselineGains gains, const SetPoint& hold,
                                       double control_seconds)
    : trim_(aircraft.hover_point()), gravity_(aircraft.gravity()), gains_(gains), hold_(hold) {
  integrator_.dt = control_seconds;
  integrator_.limit_position = gains_.integral_limit_m_s;
  integrator_.limit_yaw = gains_.integral_limit_m_s;
  std::string error;
  if (!gains_.law.IsValid(&error) || !integrator_.IsValid(&error))
    throw std::invalid_argument("baseline: " + error);
}

Controls BaselineController::act(const LoggedState& estimate, double, ControllerMemory& memory) const {
  LoggedState hold{};
  hold[logged::x] = hold_.x, hold[logged::y] = hold_.y, hold[logged::z] = hold_.z;
  hold[logged::yaw] = hold_.yaw;
  // The integral of the errors before this step (0 at the flight's first call), then this step's added.
  Controls a = hover_feedback(trim_, gravity_, gains_.law, estimate, hold, memory.integral, gains_.k_int);
  memory.integral = integrator_.advanced(memory.integral, estimate, hold_);
  memory.started = true;
  for (double& x : a) x = std::isnan(x) ? 0.0 : std::clamp(x, -1.0, 1.0);
  return a;
}

std::unique_ptr<HeliController> make_baseline(const std::string& simulator, const GroundTruth& aircraft,
                                              const SetPoint& hold, double control_seconds) {
  return std::make_unique<BaselineController>(aircraft, baseline_gains(simulator), hold, control_seconds);
}

}  // namespace pegasus::heli
