// A vehicle file's conventions (logs/vehicle.hpp: [log] world_frame, body_frame, the quaternion's order and
// direction, the units): every conversion between the aircraft's native values and the pipeline's NED, FRD,
// Z-Y-X Euler angles in rad, in one place. The readers and writers of logs, `control --vehicle` and the
// exported C (codegen/c_policy_heli.cpp, which mirrors these operation for operation) all go through them.
#include <cmath>
#include <numbers>

#include "pegasus/logs/vehicle.hpp"
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

}  // namespace pegasus::logs
