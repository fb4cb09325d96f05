#include "pegasus/heli/aircraft.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "simulation.hpp"

namespace pegasus::heli {

bool AircraftParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = std::string("aircraft: ") + what;
    return false;
  };
  if (!(mass_kg > 0 && ixx > 0 && iyy > 0 && izz > 0)) return fail("mass and inertias must be positive");
  if (!(dt > 0 && substeps >= 1 && substeps <= kMaxSubsteps))
    return fail(fmt::format("dt must be positive and substeps in [1, {}]", kMaxSubsteps));
  if (!(tau_flap > 0 && gyro_tau > 0 && conditions.est_tau > 0 && conditions.gust_tau > 0))
    return fail("time constants must be positive");
  if (!(conditions.gust_sigma >= 0 && conditions.est_sigma_pos >= 0 && conditions.est_sigma_vel >= 0 &&
        conditions.est_sigma_angle >= 0 && conditions.est_sigma_rate >= 0))
    return fail("noise levels must be >= 0");
  if (!(servo_rate > 0)) return fail("servo_rate must be positive");
  if (!(conditions.start_p_W.z() < 0)) return fail("the start must be above the ground (z < 0)");
  return true;
}

namespace {

// Blade-element thrust with momentum inflow ([GMF01]; Padfield, Helicopter Flight Dynamics, §3.2):
//   C_T = a sigma / 2 * (theta0 (1/3 + mu^2 / 2) + (mu_z - lambda0) / 2),
//   lambda0 = C_T / (2 sqrt(mu^2 + (lambda0 - mu_z)^2)),
// mu the advance ratio, mu_z the velocity along the thrust's opposite direction (descent) over the tip speed.
// Newton's method on lambda0 from the hover value; returns C_T and sets lambda0.
double solve_thrust(double theta0, double mu, double mu_z, double a_sigma_half, double* lambda0) {
  double lam = 0.05;
  double ct = 0;
  for (int it = 0; it < 12; ++it) {
    ct = a_sigma_half * (theta0 * (1.0 / 3.0 + mu * mu / 2) + (mu_z - lam) / 2);
    const double d = std::sqrt(mu * mu + (lam - mu_z) * (lam - mu_z)) + 1e-9;
    const double f = lam - ct / (2 * d);
    const double df = 1 + a_sigma_half / (4 * d) + ct * (lam - mu_z) / (2 * d * d * d);
    const double next = lam - f / df;
    if (std::abs(next - lam) < 1e-13) {
      lam = next;
      break;
    }
    lam = next;
  }
  ct = a_sigma_half * (theta0 * (1.0 / 3.0 + mu * mu / 2) + (mu_z - lam) / 2);
  *lambda0 = lam;
  return ct;
}

double clamp1(double x) { return std::clamp(x, -1.0, 1.0); }

}  // namespace

Aircraft::Aircraft(AircraftParams params)
    : params_(std::move(params)), disturbances_(params_.conditions.disturbances()) {
  std::string error;
  if (!params_.IsValid(&error)) throw std::invalid_argument(error);
  trim_ = find_trim();
}

ActionSpace Aircraft::action_space() const { return ActionSpace::box({-1, -1, -1, -1}, {1, 1, 1, 1}); }

Aircraft::Derivative Aircraft::derivative(const State& s, const Vec3& wind_W, RotorReport* report) const {
  const AircraftParams& P = params_;
  const Mat3 r_WB = rotation_world_from_body(s.attitude);
  const Vec3 air_B = s.v_B - r_WB.transpose() * wind_W;  // velocity relative to the air, in B
  const double tip = P.omega_mr * P.radius_mr;
  const double area = std::numbers::pi * P.radius_mr * P.radius_mr;
  const double sigma = 2 * P.chord_mr / (std::numbers::pi * P.radius_mr);  // two blades
  const double mu = std::hypot(air_B.x(), air_B.y()) / tip;
  const double mu_z = air_B.z() / tip;
  const double theta0 = P.collective_mid_rad + P.collective_span_rad * s.servo[2];
  double lambda0 = 0;
  const double ct = solve_thrust(theta0, mu, mu_z, P.lift_slope_mr * sigma / 2, &lambda0);
  const double q_dyn = P.air_density * area * tip * tip;
  const double thrust = ct * q_dyn;
  // Torque coefficient: induced plus profile power ([GMF01]).
  const double cq = ct * (lambda0 - mu_z) + P.profile_drag_mr * sigma / 8 * (1 + 7.0 / 3.0 * mu * mu);
  const double torque = cq * q_dyn * P.radius_mr;

  // Tail rotor: thrust pushes the tail towards -y (it blows air to the right), which yaws the nose right.
  const double tip_tr = P.omega_mr * P.gear_tr * P.radius_tr;
  const double area_tr = std::numbers::pi * P.radius_tr * P.radius_tr;
  const double sigma_tr = 2 * P.chord_tr / (std::numbers::pi * P.radius_tr);
  const Vec3 r_tail_B(-P.arm_tr, 0.0, -P.height_tr);
  const Vec3 air_tail_B = air_B + s.w_B.cross(r_tail_B);
  const double theta_tr = P.tail_mid_rad + P.tail_span_rad * s.servo[3] - P.gyro_gain * s.gyro_rate;
  double lambda_tr = 0;
  const double ct_tr = solve_thrust(theta_tr, std::hypot(air_tail_B.x(), air_tail_B.z()) / tip_tr,
                                    air_tail_B.y() / tip_tr, P.lift_slope_tr * sigma_tr / 2, &lambda_tr);
  const double thrust_tr = ct_tr * P.air_density * area_tr * tip_tr * tip_tr;

  // Main rotor force along the tilted tip-path plane, applied at the hub, plus the hub spring.
  const double fl = s.flap_lon, fr = s.flap_lat;
  const Vec3 f_mr_B(thrust * std::sin(fl), thrust * std::sin(fr), -thrust * std::cos(fl) * std::cos(fr));
  const Vec3 r_hub_B(0.0, 0.0, -P.hub_height);
  Vec3 m_B = r_hub_B.cross(f_mr_B) + Vec3(P.hub_stiffness * fr, -P.hub_stiffness * fl, -torque);
  // Rotors turn clockwise seen from above (thesis footnote 2): the reaction torque yaws the body left (-z).
  const Vec3 f_tr_B(0.0, -thrust_tr, 0.0);
  m_B += r_tail_B.cross(f_tr_B);

  // Fuselage drag with the rotor downwash v_i = lambda0 * tip speed along +z ([GMF01]).
  const double v_i = lambda0 * tip;
  const double w_rel = air_B.z() - v_i;
  const double v_inf = std::sqrt(air_B.x() * air_B.x() + air_B.y() * air_B.y() + w_rel * w_rel);
  const double half_rho = 0.5 * P.air_density;
  const Vec3 f_fus_B(-half_rho * P.fus_area_x * air_B.x() * v_inf,
                     -half_rho * P.fus_area_y * air_B.y() * v_inf, -half_rho * P.fus_area_z * w_rel * v_inf);

  const Vec3 g_B = r_WB.transpose() * Vec3(0.0, 0.0, P.gravity);
  Derivative d;
  d.p_dot_W = r_WB * s.v_B;
  d.v_dot_B = (f_mr_B + f_tr_B + f_fus_B) / P.mass_kg + g_B - s.w_B.cross(s.v_B);
  const Vec3 inertia(P.ixx, P.iyy, P.izz);
  const Vec3 iw = inertia.cwiseProduct(s.w_B);
  d.w_dot_B = (m_B - s.w_B.cross(iw)).cwiseQuotient(inertia);
  d.euler_rates = euler_rates_from_body_rates(s.attitude, s.w_B);
  // Flapping: first-order lags to the cyclic command, with the gyroscopic lag behind body rotation and the
  // flap-back away from the relative wind, a1 = mu (8/3 theta0 - 2 lambda) (Prouty; [GMF01]).
  const double flap_back = 8.0 / 3.0 * theta0 - 2 * (lambda0 - mu_z);
  const double lon_cmd = P.a_lon * P.cyclic_max_rad * s.servo[0] - flap_back * air_B.x() / tip;
  const double lat_cmd = P.b_lat * P.cyclic_max_rad * s.servo[1] - flap_back * air_B.y() / tip;
  d.flap_lon_dot = s.w_B.y() + (lon_cmd - fl) / P.tau_flap;
  d.flap_lat_dot = -s.w_B.x() + (lat_cmd - fr) / P.tau_flap;
  d.gyro_dot = (s.w_B.z() - s.gyro_rate) / P.gyro_tau;
  if (report) {
    report->thrust_n = thrust;
    report->torque_nm = torque;
    report->inflow_ratio = lambda0;
    report->tail_thrust_n = thrust_tr;
    report->thrust_coeff_over_solidity = ct / sigma;
  }
  return d;
}

namespace {

AircraftState advance(const AircraftState& s, const Aircraft::Derivative& d, double h) {
  AircraftState n = s;
  advance_rigid_body(n, d, h);
  n.flap_lon += h * d.flap_lon_dot;
  n.flap_lat += h * d.flap_lat_dot;
  n.gyro_rate += h * d.gyro_dot;
  return n;
}

}  // namespace

Aircraft::State Aircraft::step(const State& s, const Action& a, std::span<const double> p) const {
  if (s.crash != CrashReason::kNone) return s;
  const AircraftParams& P = params_;
  State x = s;
  const Vec3 wind_W = P.conditions.mean_wind_W + s.gust_W;
  const double h = P.dt / P.substeps;
  for (int k = 0; k < P.substeps; ++k) {
    for (int c = 0; c < 4; ++c) {
      const double target = clamp1(a[c]);
      const double move = std::clamp(target - x.servo[c], -P.servo_rate * h, P.servo_rate * h);
      x.servo[c] = clamp1(x.servo[c] + move);
    }
    // Classical RK4 on the rigid body, flapping and gyro; servos and wind held over the substep.
    const Derivative k1 = derivative(x, wind_W);
    const Derivative k2 = derivative(advance(x, k1, h / 2), wind_W);
    const Derivative k3 = derivative(advance(x, k2, h / 2), wind_W);
    const Derivative k4 = derivative(advance(x, k3, h), wind_W);
    Derivative sum;
    sum.p_dot_W = rk4_mean<Vec3>(k1.p_dot_W, k2.p_dot_W, k3.p_dot_W, k4.p_dot_W);
    sum.v_dot_B = rk4_mean<Vec3>(k1.v_dot_B, k2.v_dot_B, k3.v_dot_B, k4.v_dot_B);
    sum.euler_rates = rk4_mean<Vec3>(k1.euler_rates, k2.euler_rates, k3.euler_rates, k4.euler_rates);
    sum.w_dot_B = rk4_mean<Vec3>(k1.w_dot_B, k2.w_dot_B, k3.w_dot_B, k4.w_dot_B);
    sum.flap_lon_dot = rk4_mean(k1.flap_lon_dot, k2.flap_lon_dot, k3.flap_lon_dot, k4.flap_lon_dot);
    sum.flap_lat_dot = rk4_mean(k1.flap_lat_dot, k2.flap_lat_dot, k3.flap_lat_dot, k4.flap_lat_dot);
    sum.gyro_dot = rk4_mean(k1.gyro_dot, k2.gyro_dot, k3.gyro_dot, k4.gyro_dot);
    x = advance(x, sum, h);
  }
  x.attitude.yaw = wrap_angle(x.attitude.yaw);
  x.time = s.time + P.dt;
  disturbances_.step(P.dt, p, x.gust_W, x.estimate_error);
  check_crash(x);
  return x;
}

void Aircraft::check_crash(State& s) const {
  const AircraftParams& P = params_;
  RotorReport rotor;
  derivative(s, P.conditions.mean_wind_W + s.gust_W, &rotor);
  s.crash = rigid_body_crash(true_logged_state(s), s.attitude, s.w_B, P.max_tilt_rad, P.max_rate_rad_s);
  if (s.crash == CrashReason::kNone &&
      std::abs(rotor.thrust_coeff_over_solidity) > P.max_thrust_coeff_over_solidity)
    s.crash = CrashReason::kRotorOverload;
}

Aircraft::Trim Aircraft::find_trim() const {
  // Unknowns: a1, a2, a3, a4, roll, pitch; equations: the six accelerations at rest with the flapping at
  // its steady state. Newton's method with a forward-difference Jacobian.
  using V6 = Eigen::Matrix<double, 6, 1>;
  auto residual = [&](const V6& z) {
    State s;
    s.p_W = params_.conditions.start_p_W;
    s.attitude = {z[4], z[5], params_.conditions.start_yaw};
    for (int c = 0; c < 4; ++c) s.servo[static_cast<std::size_t>(c)] = z[c];
    s.flap_lon = params_.a_lon * params_.cyclic_max_rad * z[0];
    s.flap_lat = params_.b_lat * params_.cyclic_max_rad * z[1];
    const Derivative d = derivative(s, Vec3::Zero());
    V6 r;
    r << d.v_dot_B, d.w_dot_B;
    return r;
  };
  V6 z = V6::Zero();
  for (int it = 0; it < 50; ++it) {
    const V6 r0 = residual(z);
    if (r0.cwiseAbs().maxCoeff() < 1e-12) break;
    Eigen::Matrix<double, 6, 6> j;
    for (int c = 0; c < 6; ++c) {
      V6 zc = z;
      zc[c] += 1e-7;
      j.col(c) = (residual(zc) - r0) / 1e-7;
    }
    z -= j.partialPivLu().solve(r0);
  }
  Trim t;
  for (int c = 0; c < 4; ++c) t.controls[static_cast<std::size_t>(c)] = z[c];
  t.roll = z[4];
  t.pitch = z[5];
  t.residual = residual(z).cwiseAbs().maxCoeff();
  State s;
  s.attitude = {t.roll, t.pitch, 0.0};
  s.servo = t.controls;
  s.flap_lon = params_.a_lon * params_.cyclic_max_rad * z[0];
  s.flap_lat = params_.b_lat * params_.cyclic_max_rad * z[1];
  derivative(s, Vec3::Zero(), &t.rotor);
  return t;
}

Aircraft::State Aircraft::initial_state(std::span<const double> p0) const {
  const AircraftParams& P = params_;
  State s;
  s.attitude = {trim_.roll, trim_.pitch, wrap_angle(P.conditions.start_yaw)};
  s.servo = trim_.controls;
  s.flap_lon = P.a_lon * P.cyclic_max_rad * trim_.controls[control_axis::pitch];  // longitudinal cyclic
  s.flap_lat = P.b_lat * P.cyclic_max_rad * trim_.controls[control_axis::roll];   // lateral cyclic
  draw_start(P.conditions, disturbances_, p0, s);
  return s;
}

LoggedState true_logged_state(const AircraftState& s) {
  return logged_state_of(s.p_W, s.attitude, s.v_B, s.w_B);
}

std::unique_ptr<SimulatedFlight> Aircraft::start_flight(std::span<const double> p0) const {
  return std::make_unique<ModelFlight<Aircraft>>(*this, p0);
}

Aircraft::Observation Aircraft::observe(const State& s) const {
  return with_estimate_error(true_logged_state(s), s.estimate_error);
}

}  // namespace pegasus::heli
