#include "pegasus/heli/frames.hpp"

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

}  // namespace pegasus::heli
