// The typed vehicle (vehicle/vehicle.hpp): its channels and state fields, and its conventions ([log]
// world_frame, body_frame, the quaternion's order and direction, the units): every conversion between the
// aircraft's native values and the pipeline's NED, FRD, Z-Y-X Euler angles in rad, in one place. The readers
// and writers of logs, `control --vehicle` and the exported C (codegen/c_policy_heli.cpp, which mirrors these
// operation for operation) all go through them.
#include "pegasus/vehicle/vehicle.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "pegasus/vehicle/frames.hpp"

namespace pegasus::logs {

bool VehicleLogSpec::pipeline_conventions() const {
  return world_frame == "NED" && body_frame == "FRD" && quaternion_order == "wxyz" &&
         quaternion_direction == "body_to_world" && attitude_unit == "rad" && rates_unit == "rad/s";
}

namespace {
constexpr double kPi = std::numbers::pi;
constexpr double kHalfPi = std::numbers::pi / 2;
constexpr double kRadiansPerDegree = std::numbers::pi / 180;
bool enu(const VehicleLogSpec& s) { return s.world_frame == "ENU"; }
bool flu(const VehicleLogSpec& s) { return s.body_frame == "FLU"; }
}  // namespace

// ENU (e, n, u) and NED (n, e, d) are one swap and one sign apart, each way.
heli::Vec3 world_vector_of(const VehicleLogSpec& spec, const heli::Vec3& native) {
  return enu(spec) ? heli::Vec3(native.y(), native.x(), -native.z()) : native;
}
heli::Vec3 native_world_vector(const VehicleLogSpec& spec, const heli::Vec3& v_W) {
  return enu(spec) ? heli::Vec3(v_W.y(), v_W.x(), -v_W.z()) : v_W;
}
// FLU and FRD differ by a half turn about x: R_x(pi) = diag(1, -1, -1), its own inverse.
heli::Vec3 body_vector_of(const VehicleLogSpec& spec, const heli::Vec3& native) {
  return flu(spec) ? heli::Vec3(native.x(), -native.y(), -native.z()) : native;
}
heli::Vec3 native_body_vector(const VehicleLogSpec& spec, const heli::Vec3& v_B) {
  return body_vector_of(spec, v_B);
}

heli::Euler euler_of(const VehicleLogSpec& spec, const heli::Euler& n) {
  heli::Euler e = n;
  if (enu(spec) != flu(spec)) e.roll = heli::wrap_angle(n.roll + kPi);
  if (enu(spec)) {
    e.pitch = -n.pitch;
    e.yaw = heli::wrap_angle(kHalfPi - n.yaw);
  }
  return e;
}
heli::Euler native_euler(const VehicleLogSpec& spec, const heli::Euler& e) {
  heli::Euler n = e;
  if (enu(spec) != flu(spec)) n.roll = heli::wrap_angle(e.roll - kPi);
  if (enu(spec)) {
    n.pitch = -e.pitch;
    n.yaw = heli::wrap_angle(kHalfPi - e.yaw);
  }
  return n;
}
heli::Vec3 euler_rates_of(const VehicleLogSpec& spec, const heli::Vec3& n) {
  return enu(spec) ? heli::Vec3(n.x(), -n.y(), -n.z()) : n;
}
heli::Vec3 native_euler_rates(const VehicleLogSpec& spec, const heli::Vec3& rates) {
  return euler_rates_of(spec, rates);
}

heli::Euler native_euler_of_quaternion(const VehicleLogSpec& spec, const double* q) {
  const bool xyzw = spec.quaternion_order == "xyzw";
  const double w = q[xyzw ? 3 : 0];
  double x = q[xyzw ? 0 : 1], y = q[xyzw ? 1 : 2], z = q[xyzw ? 2 : 3];
  // World to body is the conjugate (the inverse rotation).
  if (spec.quaternion_direction == "world_to_body") x = -x, y = -y, z = -z;
  return heli::euler_from_any_quaternion(w, x, y, z);
}

std::array<double, 4> native_quaternion(const VehicleLogSpec& spec, const heli::Euler& native_rad) {
  std::array<double, 4> q = heli::quaternion_from_euler(native_rad);  // w, x, y, z; body to world
  if (spec.quaternion_direction == "world_to_body") q[1] = -q[1], q[2] = -q[2], q[3] = -q[3];
  if (spec.quaternion_order == "xyzw") q = {q[1], q[2], q[3], q[0]};
  return q;
}

double radians_per_attitude_unit(const VehicleLogSpec& spec) {
  return spec.attitude_unit == "deg" ? kRadiansPerDegree : 1.0;
}
double radians_per_rates_unit(const VehicleLogSpec& spec) {
  return spec.rates_unit == "deg/s" ? kRadiansPerDegree : 1.0;
}

std::vector<std::string> VehicleLogSpec::topic_names() const {
  std::vector<std::string> out;
  auto add = [&](const std::string& t) {
    if (std::find(out.begin(), out.end(), t) == out.end()) out.push_back(t);
  };
  for (const auto* t : {&position, &velocity, &attitude, &rates}) add(t->topic);
  for (const auto& c : controls) add(c.topic);
  return out;
}

heli::Controls Vehicle::axes_of(std::span<const double> native) const {
  heli::Controls a{};
  for (std::size_t c = 0; c < 4; ++c)
    a[static_cast<std::size_t>(log.controls[c].column(c))] =
        log.controls[c].scale * native[c] + log.controls[c].offset;
  return a;
}

std::array<double, 4> Vehicle::native_of(const heli::Controls& axes) const {
  std::array<double, 4> native{};
  for (std::size_t c = 0; c < 4; ++c) {
    const ControlChannel& ch = log.controls[c];
    native[c] = (axes[static_cast<std::size_t>(ch.column(c))] - ch.offset) / ch.scale;
  }
  return native;
}

std::vector<std::string> Vehicle::state_fields() const {
  std::vector<std::string> out;
  for (const auto* q : {&log.position, &log.velocity, &log.attitude, &log.rates})
    out.insert(out.end(), q->fields.begin(), q->fields.end());
  return out;
}

heli::LoggedState Vehicle::state_of(std::span<const double> v) const {
  const bool quaternion = log.attitude_form == "quaternion";
  const std::size_t rates_at = quaternion ? 10 : 9;
  // Each step below is skipped under the pipeline's own conventions: their logs read bit for bit as before.
  heli::Euler e{v[6], v[7], v[8]};
  if (quaternion) {
    e = native_euler_of_quaternion(log, v.data() + 6);
  } else if (log.attitude_unit != "rad") {
    const double k = radians_per_attitude_unit(log);
    e = heli::Euler{e.roll * k, e.pitch * k, e.yaw * k};
  }
  e = euler_of(log, e);
  const heli::Vec3 p = world_vector_of(log, heli::Vec3(v[0], v[1], v[2]));
  heli::Vec3 vel(v[3], v[4], v[5]);
  if (log.velocity_frame == "body")
    vel = heli::world_from_body(e, body_vector_of(log, vel));
  else
    vel = world_vector_of(log, vel);
  heli::Vec3 w(v[rates_at], v[rates_at + 1], v[rates_at + 2]);
  if (log.rates_unit != "rad/s") w *= radians_per_rates_unit(log);
  if (log.rates_form == "body")
    w = heli::euler_rates_from_body_rates(e, body_vector_of(log, w));
  else
    w = euler_rates_of(log, w);
  heli::LoggedState s{};
  s[heli::logged::x] = p.x(), s[heli::logged::y] = p.y(), s[heli::logged::z] = p.z();
  s[heli::logged::roll] = e.roll, s[heli::logged::pitch] = e.pitch, s[heli::logged::yaw] = e.yaw;
  s[heli::logged::xdot] = vel.x(), s[heli::logged::ydot] = vel.y(), s[heli::logged::zdot] = vel.z();
  s[heli::logged::roll_rate] = w.x(), s[heli::logged::pitch_rate] = w.y(), s[heli::logged::yaw_rate] = w.z();
  return s;
}

std::vector<double> Vehicle::native_state(const heli::LoggedState& s) const {
  namespace logged = heli::logged;
  const heli::Euler e{s[logged::roll], s[logged::pitch], s[logged::yaw]};
  const heli::Vec3 p = native_world_vector(log, heli::Vec3(s[logged::x], s[logged::y], s[logged::z]));
  heli::Vec3 velocity(s[logged::xdot], s[logged::ydot], s[logged::zdot]);
  velocity = log.velocity_frame == "body" ? native_body_vector(log, heli::body_from_world(e, velocity))
                                          : native_world_vector(log, velocity);
  heli::Vec3 rates(s[logged::roll_rate], s[logged::pitch_rate], s[logged::yaw_rate]);
  rates = log.rates_form == "body" ? native_body_vector(log, heli::body_rates_from_euler_rates(e, rates))
                                   : native_euler_rates(log, rates);
  if (log.rates_unit != "rad/s") rates /= radians_per_rates_unit(log);
  std::vector<double> out{p.x(), p.y(), p.z(), velocity.x(), velocity.y(), velocity.z()};
  const heli::Euler n = native_euler(log, e);
  if (log.attitude_form == "quaternion") {
    for (const double q : native_quaternion(log, n)) out.push_back(q);
  } else {
    const double k = radians_per_attitude_unit(log);
    if (log.attitude_unit != "rad")
      out.insert(out.end(), {n.roll / k, n.pitch / k, n.yaw / k});
    else
      out.insert(out.end(), {n.roll, n.pitch, n.yaw});
  }
  out.insert(out.end(), {rates.x(), rates.y(), rates.z()});
  return out;
}

}  // namespace pegasus::logs
