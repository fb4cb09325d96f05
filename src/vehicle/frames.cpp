#include "pegasus/vehicle/frames.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pegasus::heli {

double wrap_angle(double a) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  double r = std::remainder(a, kTwoPi);  // in [-pi, pi]
  if (r <= -std::numbers::pi) r += kTwoPi;
  return r;
}

Mat3 rotation_world_from_body(const Euler& e) {
  const double cf = std::cos(e.roll), sf = std::sin(e.roll);
  const double ct = std::cos(e.pitch), st = std::sin(e.pitch);
  const double cp = std::cos(e.yaw), sp = std::sin(e.yaw);
  Mat3 r;
  // R_z(psi) R_y(theta) R_x(phi)
  r << ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp,  //
      ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp,   //
      -st, sf * ct, cf * ct;
  return r;
}

Vec3 euler_rates_from_body_rates(const Euler& e, const Vec3& w_B) {
  const double cf = std::cos(e.roll), sf = std::sin(e.roll);
  const double ct = std::cos(e.pitch), tt = std::tan(e.pitch);
  const double qr = w_B.y() * sf + w_B.z() * cf;
  return {w_B.x() + qr * tt, w_B.y() * cf - w_B.z() * sf, qr / ct};
}

Vec3 body_rates_from_euler_rates(const Euler& e, const Vec3& d) {
  const double cf = std::cos(e.roll), sf = std::sin(e.roll);
  const double ct = std::cos(e.pitch), st = std::sin(e.pitch);
  return {d.x() - st * d.z(), cf * d.y() + sf * ct * d.z(), -sf * d.y() + cf * ct * d.z()};
}

Euler euler_from_quaternion(double w, double x, double y, double z) {
  Euler e;
  e.roll = std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
  e.pitch = std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0));
  e.yaw = std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
  return e;
}

Euler euler_from_any_quaternion(double w, double x, double y, double z) {
  for (const double c : {w, x, y, z})
    if (!std::isfinite(c)) return Euler{NAN, NAN, NAN};
  const double largest = std::max({std::abs(w), std::abs(x), std::abs(y), std::abs(z)});
  if (!(largest > 0)) return Euler{NAN, NAN, NAN};
  w /= largest, x /= largest, y /= largest, z /= largest;
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  return euler_from_quaternion(w / norm, x / norm, y / norm, z / norm);
}

std::array<double, 4> quaternion_from_euler(const Euler& e) {
  const double cr = std::cos(e.roll / 2), sr = std::sin(e.roll / 2);
  const double cp = std::cos(e.pitch / 2), sp = std::sin(e.pitch / 2);
  const double cy = std::cos(e.yaw / 2), sy = std::sin(e.yaw / 2);
  std::array<double, 4> q{cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
                          cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy};
  if (q[0] < 0)
    for (double& c : q) c = -c;
  return q;
}

}  // namespace pegasus::heli
