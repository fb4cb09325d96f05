#pragma once
// The state and controls every part of the helicopter pipeline shares, defined once: the 12 logged states of
// thesis §5.1, in the flight log's column order (vehicle/flight_log.hpp), which the identification, the
// learned model, the tasks, flights, the control protocol (`heli control`) and the exported controllers all
// read. A LoggedState is read by name: the accessors give its vector parts in frames.hpp's terms, and
// logged:: names each column; no code indexes it with a bare number.
//   x, y, z                          p_W, position in the world frame W (north-east-down), m
//   roll, pitch, yaw                 Z-Y-X Euler angles, rad
//   xdot, ydot, zdot                 v_W, velocity in W, m/s
//   roll_rate, pitch_rate, yaw_rate  Euler-angle rates d(roll)/dt, d(pitch)/dt, d(yaw)/dt, rad/s
#include <array>
#include <cstddef>

#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {

inline constexpr int kLoggedStates = 12;
inline constexpr std::array<const char*, kLoggedStates> kLoggedStateNames = {
    "x", "y", "z", "roll", "pitch", "yaw", "xdot", "ydot", "zdot", "roll_rate", "pitch_rate", "yaw_rate"};
using LoggedState = std::array<double, kLoggedStates>;

// The four controls every aircraft takes, a1..a4 in [-1, 1], one per axis (a vehicle file maps its own
// channels onto them): a1 pitch (+: nose down, accelerate forward), a2 roll (+: roll right), a3 thrust (+:
// climb), a4 yaw (+: yaw right, clockwise seen from above).
inline constexpr std::array<const char*, 4> kControlNames = {"a1", "a2", "a3", "a4"};
using Controls = std::array<double, 4>;
// The axes a1..a4 drive, by name (vehicle files name them so), and where each lives in Controls.
inline constexpr std::array<const char*, 4> kControlAxisNames = {"pitch", "roll", "thrust", "yaw"};
namespace control_axis {
inline constexpr std::size_t pitch = 0, roll = 1, thrust = 2, yaw = 3;
}  // namespace control_axis

// Where each column of kLoggedStateNames lives in a LoggedState.
namespace logged {
inline constexpr std::size_t x = 0, y = 1, z = 2, roll = 3, pitch = 4, yaw = 5, xdot = 6, ydot = 7, zdot = 8,
                             roll_rate = 9, pitch_rate = 10, yaw_rate = 11;
}  // namespace logged

inline Vec3 position_of(const LoggedState& s) { return {s[logged::x], s[logged::y], s[logged::z]}; }
inline Euler attitude_of(const LoggedState& s) { return {s[logged::roll], s[logged::pitch], s[logged::yaw]}; }
inline Vec3 velocity_of(const LoggedState& s) { return {s[logged::xdot], s[logged::ydot], s[logged::zdot]}; }
inline Vec3 euler_rates_of(const LoggedState& s) {
  return {s[logged::roll_rate], s[logged::pitch_rate], s[logged::yaw_rate]};
}

// The logged state of a rigid body given as its simulators keep it: position p_W, attitude, velocity v_B and
// body rates w_B.
inline LoggedState logged_state_of(const Vec3& p_W, const Euler& attitude, const Vec3& v_B, const Vec3& w_B) {
  const Vec3 v_W = world_from_body(attitude, v_B);
  const Vec3 rates = euler_rates_from_body_rates(attitude, w_B);
  return {p_W.x(), p_W.y(), p_W.z(), attitude.roll, attitude.pitch, attitude.yaw,
          v_W.x(), v_W.y(), v_W.z(), rates.x(),     rates.y(),      rates.z()};
}

}  // namespace pegasus::heli
