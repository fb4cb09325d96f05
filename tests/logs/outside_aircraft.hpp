#pragma once
// An aircraft in another layout than the pipeline's (issue 15's outside aircraft): logs at 10 Hz with
// quaternion attitude, body-frame velocities and body rates, columns in another order with other names, and
// its controls in another order with other ranges and signs. Its logs are made from the X-Cell's own, so the
// pipeline's results on them can be checked against the X-Cell's.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::test_support {

inline constexpr const char* kOutsideVehicle = R"(# an outside helicopter
[vehicle]
name = "outside-heli"

[log]
rate_hz = 10
model_rate_hz = 10
time = "t"

[log.position]
fields = ["n", "e", "d"]

[log.velocity]
fields = ["u", "v", "w"]
frame = "body"

[log.attitude]
fields = ["qw", "qx", "qy", "qz"]
form = "quaternion"

[log.rates]
fields = ["p", "q", "r"]
form = "body"

[[log.controls]]
field = "thr"
axis = "thrust"
range = [0, 1]

[[log.controls]]
field = "ail"
axis = "roll"
range = [-0.5, 0.5]

[[log.controls]]
field = "ele"
axis = "pitch"
sign = -1

[[log.controls]]
field = "rud"
name = "rudder_us"
axis = "yaw"
range = [1000, 2000]
sign = -1

[control]
rate_hz = 10
)";

// `text` with the first `from` replaced by `to` (a test fails when there is none).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// The outside aircraft's channels from a1..a4: thr, ail, ele, rud.
inline std::array<double, 4> outside_controls(const heli::Controls& a) {
  return {(a[2] + 1) / 2, 0.5 * a[1], -a[0], 1500 - 500 * a[3]};
}

// The outside aircraft's state fields (n, e, d, u, v, w, qw, qx, qy, qz, p, q, r) of the pipeline's 12
// states.
inline std::array<double, 13> outside_state(const heli::LoggedState& s) {
  const heli::Euler e{s[3], s[4], s[5]};
  const heli::Vec3 v_B = heli::body_from_world(e, heli::Vec3(s[6], s[7], s[8]));
  const heli::Vec3 w_B = heli::body_rates_from_euler_rates(e, heli::Vec3(s[9], s[10], s[11]));
  const auto q = heli::quaternion_from_euler(e);
  return {s[0], s[1], s[2], v_B.x(), v_B.y(), v_B.z(), q[0], q[1], q[2], q[3], w_B.x(), w_B.y(), w_B.z()};
}

// Every `every`-th row of a log (a 50 Hz log at 10 Hz with every = 5).
inline sysid::FlightLog every_nth_row(const sysid::FlightLog& log, std::size_t every) {
  sysid::FlightLog out;
  for (std::size_t i = 0; i < log.rows(); i += every) {
    out.time.push_back(log.time[i]);
    out.states.push_back(log.states[i]);
    out.controls.push_back(log.controls[i]);
  }
  return out;
}

// Where `read` first differs from `own`: a row count, a time, or a state or control beyond 1e-12 (yaw modulo
// 2 pi); empty when the two are the same log.
inline std::string log_difference(const sysid::FlightLog& read, const sysid::FlightLog& own) {
  if (read.rows() != own.rows()) return fmt::format("{} rows, expected {}", read.rows(), own.rows());
  for (std::size_t i = 0; i < own.rows(); ++i) {
    if (read.time[i] != own.time[i])
      return fmt::format("row {}: time {}, expected {}", i, read.time[i], own.time[i]);
    for (std::size_t k = 0; k < 12; ++k) {
      const double d = read.states[i][k] - own.states[i][k];
      if (!(std::abs(k == 5 ? heli::wrap_angle(d) : d) <= 1e-12))
        return fmt::format("row {} state {}: {}, expected {}", i, k, read.states[i][k], own.states[i][k]);
    }
    for (std::size_t c = 0; c < 4; ++c)
      if (!(std::abs(read.controls[i][c] - own.controls[i][c]) <= 1e-12))
        return fmt::format("row {} control {}: {}, expected {}", i, c, read.controls[i][c],
                           own.controls[i][c]);
  }
  return {};
}

// The log as the outside aircraft writes it: its columns shuffled, one column it does not describe.
inline std::string outside_log_csv(const sysid::FlightLog& log) {
  std::string text = "rud,n,qx,t,e,thr,u,qy,battery_v,d,v,ail,qz,w,p,qw,q,ele,r\n";
  for (std::size_t i = 0; i < log.rows(); ++i) {
    const auto s = outside_state(log.states[i]);  // n e d u v w qw qx qy qz p q r
    const auto c = outside_controls(log.controls[i]);
    const std::array<double, 19> row = {c[3], s[0], s[7], log.time[i], s[1],  c[0], s[3],  s[8], 12.6, s[2],
                                        s[4], c[1], s[9], s[5],        s[10], s[6], s[11], c[2], s[12]};
    for (std::size_t k = 0; k < row.size(); ++k) text += (k ? "," : "") + format_double(row[k]);
    text += '\n';
  }
  return text;
}

}  // namespace pegasus::test_support
