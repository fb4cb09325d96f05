#include "pegasus/heli/maneuver_policy.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "pegasus/core/error.hpp"

namespace pegasus::heli {

ManeuverPolicy::ManeuverPolicy(std::shared_ptr<const Trajectory> trajectory, const HoverPolicyInit& init,
                               ManeuverPolicyOptions options)
    : trajectory_(std::move(trajectory)), init_(init), options_(options) {
  if (!trajectory_) throw InputError("manoeuvre policy: expected a trajectory");
  if (std::string error; !command_limits_valid(init_.command_lower, init_.command_upper, &error))
    throw InputError("manoeuvre policy: command limits: " + error);
  if (!(options_.max_delay_s > 0 && std::isfinite(options_.max_delay_s)))
    throw InputError("manoeuvre policy: max_delay_s: expected a number > 0");
  const HoverPolicy hover(init);
  for (const auto& p : hover.parameters().all()) spec_.add(p);
  spec_.add({.name = "couple.tail_to_lat", .initial = 0.0, .lower = -2.0, .upper = 2.0, .scale = 0.05});
  spec_.add({.name = "couple.coll_to_tail", .initial = 0.0, .lower = -2.0, .upper = 2.0, .scale = 0.05});
  if (options_.learn_delay) {
    delay_index_ = static_cast<int>(spec_.size());
    spec_.add({.name = "z_delay", .initial = 0.0, .lower = 0.0, .upper = options_.max_delay_s, .scale = 0.2});
  }
  if (options_.feedforward) {
    ff_index_ = static_cast<int>(spec_.size());
    spec_.add({.name = "feedforward", .initial = 1.0, .lower = 0.0, .upper = 1.5, .scale = 0.05});
  }
}

SetPoint ManeuverPolicy::target(std::span<const double> theta, double time) const {
  const TrajectoryPoint p = trajectory_->delayed(time, z_delay(theta));
  return SetPoint{.x = p.p_W.x(), .y = p.p_W.y(), .z = p.p_W.z(), .yaw = wrap_angle(p.yaw)};
}

Controls ManeuverPolicy::act(std::span<const double> theta, const ManeuverObservation& o) const {
  const TrajectoryPoint p = trajectory_->delayed(o.time, z_delay(theta));
  HeliObservation h{.state = o.state, .target = {p.p_W.x(), p.p_W.y(), p.p_W.z(), wrap_angle(p.yaw)}};
  const double k = feedforward(theta);
  if (k != 0) {
    h.state[logged::xdot] -= k * p.v_W.x();
    h.state[logged::ydot] -= k * p.v_W.y();
    h.state[logged::zdot] -= k * p.v_W.z();
    h.state[logged::yaw_rate] -= k * p.yaw_rate;
  }
  Controls a = HoverPolicy::unclipped(theta.first(kHover), hover_inputs(h));
  namespace axis = control_axis;
  const double tail = a[axis::yaw] - init_.trim[axis::yaw], coll = a[axis::thrust] - init_.trim[axis::thrust];
  a[axis::roll] += theta[kTailToLat] * tail;
  a[axis::yaw] += theta[kCollToTail] * coll;
  return clip_command(a, init_.command_lower, init_.command_upper);
}

Theta ManeuverPolicy::from_hover(std::span<const double> hover_theta) const {
  if (hover_theta.size() != static_cast<std::size_t>(kHover))
    throw InputError("manoeuvre policy: expected the 34 weights of a hover policy");
  Theta theta = spec_.initial();
  std::copy(hover_theta.begin(), hover_theta.end(), theta.begin());
  return theta;
}

}  // namespace pegasus::heli
