#pragma once
// The one place where helicopter quantities change frame (STYLE.md, Drake's monogram notation).
//
// Frames: W is the world frame, north-east-down (x north, y east, z down; the ground is the plane z = 0, so
// flying means z < 0). B is the body frame (x forward, y right, z down, origin at the centre of mass).
// Attitude is the Z-Y-X Euler sequence (yaw psi, then pitch theta, then roll phi), radians:
//   roll in (-pi, pi], pitch in [-pi/2, pi/2], yaw wrapped to (-pi, pi] by wrap_angle().
// Names say the frame: v_W is a velocity expressed in W, v_B the same velocity expressed in B,
// w_B = (p, q, r) the body angular rate; euler_rates = (dphi/dt, dtheta/dt, dpsi/dt).
#include <Eigen/Core>
#include <array>

namespace pegasus::heli {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

struct Euler {
  double roll = 0;   // phi, rad
  double pitch = 0;  // theta, rad
  double yaw = 0;    // psi, rad
};

// Wraps an angle to (-pi, pi].
double wrap_angle(double a);

// R_WB: maps a vector expressed in B to the same vector expressed in W.
Mat3 rotation_world_from_body(const Euler& e);
inline Vec3 world_from_body(const Euler& e, const Vec3& v_B) { return rotation_world_from_body(e) * v_B; }
inline Vec3 body_from_world(const Euler& e, const Vec3& v_W) {
  return rotation_world_from_body(e).transpose() * v_W;
}

// Euler angle rates from the body angular rate w_B = (p, q, r) and back (singular at pitch = +-pi/2; the
// aircraft crashes long before: see AircraftParams::max_tilt_rad).
Vec3 euler_rates_from_body_rates(const Euler& e, const Vec3& w_B);
Vec3 body_rates_from_euler_rates(const Euler& e, const Vec3& euler_rates);

// The Z-Y-X Euler angles of a unit quaternion (w, x, y, z) that rotates body vectors into W (PX4's
// vehicle_attitude.q), and the unit quaternion with w >= 0 of Euler angles.
Euler euler_from_quaternion(double w, double x, double y, double z);
// The same for a quaternion of any length, as logs give them: scaled by its largest component first, so that
// components near the largest double do not overflow the norm. NaN angles when it has no direction (all zero,
// or a component not finite).
Euler euler_from_any_quaternion(double w, double x, double y, double z);
std::array<double, 4> quaternion_from_euler(const Euler& e);

}  // namespace pegasus::heli
