#include "pegasus/heli/quadrotor.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "simulation.hpp"

namespace pegasus::heli {
namespace {

// Motor i sits at (kMotorX[i], kMotorY[i]) * arm / sqrt(2) in B and spins so that its drag torque about z_B
// has the sign kMotorSpin[i]: front-right, back-right, back-left, front-left.
constexpr std::array<double, 4> kMotorX = {1, -1, -1, 1};
constexpr std::array<double, 4> kMotorY = {1, 1, -1, -1};
constexpr std::array<double, 4> kMotorSpin = {-1, 1, -1, 1};

double clamp1(double x) { return std::clamp(x, -1.0, 1.0); }

QuadrotorState advance(const QuadrotorState& s, const Quadrotor::Derivative& d, double h) {
  QuadrotorState n = s;
  advance_rigid_body(n, d, h);
  for (std::size_t i = 0; i < 4; ++i) n.rotor_speed[i] += h * d.rotor_accel[i];
  return n;
}

}  // namespace

bool QuadrotorParams::IsValid(std::string* error) const {
  auto fail = [&](const std::string& what) {
    if (error) *error = std::string("quadrotor: ") + what;
    return false;
  };
  if (!(mass_kg > 0 && ixx > 0 && iyy > 0 && izz > 0 && arm_m > 0 && gravity > 0))
    return fail("mass, inertia, arm and gravity must be positive");
  if (!(thrust_coeff > 0 && torque_per_thrust_m > 0 && motor_tau > 0 && drag_xy >= 0 && drag_z >= 0))
    return fail("rotor coefficients must be positive (drag >= 0)");
  if (!(4 * max_motor_thrust_n > mass_kg * gravity))
    return fail("the four motors' full thrust must exceed the weight");
  if (!(max_tilt_command_rad > 0 && max_tilt_command_rad < max_tilt_rad && max_yaw_rate_command > 0))
    return fail("need 0 < max_tilt_command_rad < max_tilt_rad and max_yaw_rate_command > 0");
  if (!(attitude_gain > 0 && rate_gain > 0 && yaw_rate_gain > 0))
    return fail("controller gains must be positive");
  if (!(conditions.gust_tau > 0 && conditions.est_tau > 0)) return fail("time constants must be positive");
  if (!(conditions.gust_sigma >= 0 && conditions.est_sigma_pos >= 0 && conditions.est_sigma_vel >= 0 &&
        conditions.est_sigma_angle >= 0 && conditions.est_sigma_rate >= 0))
    return fail("noise sizes must be >= 0");
  if (!(max_tilt_rad > 0 && max_tilt_rad < 1.5 && max_rate_rad_s > 0))
    return fail("crash limits out of range");
  if (!(dt > 0 && substeps >= 1 && substeps <= kMaxSubsteps))
    return fail(fmt::format("need dt > 0 and substeps in [1, {}]", kMaxSubsteps));
  if (!(conditions.start_p_W.z() < 0)) return fail("the start must be above the ground (z < 0)");
  if (!(conditions.start_pos_sigma >= 0 && conditions.start_vel_sigma >= 0))
    return fail("start perturbations must be >= 0");
  return true;
}

Quadrotor::Quadrotor(QuadrotorParams params) : params_(std::move(params)) {
  std::string error;
  if (!params_.IsValid(&error)) throw std::invalid_argument(error);
  const QuadrotorParams& P = params_;
  disturbances_ = P.conditions.disturbances();
  const double d = params_.arm_m / std::numbers::sqrt2;
  Eigen::Matrix4d wrench_from_thrust;
  for (int i = 0; i < 4; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    wrench_from_thrust(0, i) = 1;                                             // collective thrust
    wrench_from_thrust(1, i) = -d * kMotorY[ui];                              // roll torque
    wrench_from_thrust(2, i) = d * kMotorX[ui];                               // pitch torque
    wrench_from_thrust(3, i) = kMotorSpin[ui] * params_.torque_per_thrust_m;  // yaw torque
  }
  thrust_from_wrench_ = wrench_from_thrust.inverse();
}

double Quadrotor::max_thrust() const { return 4 * params_.max_motor_thrust_n; }

double Quadrotor::hover_rotor_speed() const {
  return std::sqrt(params_.mass_kg * params_.gravity / (4 * params_.thrust_coeff));
}

HoverPoint Quadrotor::hover_point() const {
  HoverPoint h;
  h.controls[control_axis::thrust] = 2 * params_.mass_kg * params_.gravity / max_thrust() - 1;
  return h;
}

std::array<double, 4> Quadrotor::rotor_commands(const State& s, const Controls& a) const {
  const QuadrotorParams& P = params_;
  const double roll_set = P.max_tilt_command_rad * clamp1(a[control_axis::roll]);
  const double pitch_set = -P.max_tilt_command_rad * clamp1(a[control_axis::pitch]);
  const double yaw_rate_set = P.max_yaw_rate_command * clamp1(a[control_axis::yaw]);
  const double thrust = max_thrust() * (clamp1(a[control_axis::thrust]) + 1) / 2;
  const double p_set = P.attitude_gain * (roll_set - s.attitude.roll);
  const double q_set = P.attitude_gain * (pitch_set - s.attitude.pitch);
  Eigen::Vector4d wrench;
  wrench << thrust, P.ixx * P.rate_gain * (p_set - s.w_B.x()), P.iyy * P.rate_gain * (q_set - s.w_B.y()),
      P.izz * P.yaw_rate_gain * (yaw_rate_set - s.w_B.z());
  const Eigen::Vector4d motor_thrust = thrust_from_wrench_ * wrench;
  std::array<double, 4> command;
  for (int i = 0; i < 4; ++i)
    command[static_cast<std::size_t>(i)] =
        std::sqrt(std::clamp(motor_thrust[i], 0.0, P.max_motor_thrust_n) / P.thrust_coeff);
  return command;
}

Quadrotor::Derivative Quadrotor::derivative(const State& s, const std::array<double, 4>& rotor_command,
                                            const Vec3& wind_W) const {
  const QuadrotorParams& P = params_;
  const double d = P.arm_m / std::numbers::sqrt2;
  double thrust = 0, speed_sum = 0;
  Vec3 torque = Vec3::Zero();
  Derivative out;
  for (std::size_t i = 0; i < 4; ++i) {
    const double w = s.rotor_speed[i];
    const double f = P.thrust_coeff * w * w;
    thrust += f;
    speed_sum += w;
    torque += Vec3(-d * kMotorY[i] * f, d * kMotorX[i] * f, kMotorSpin[i] * P.torque_per_thrust_m * f);
    out.rotor_accel[i] = (rotor_command[i] - w) / P.motor_tau;
  }
  const Mat3 r_WB = rotation_world_from_body(s.attitude);
  const Vec3 air_B = s.v_B - r_WB.transpose() * wind_W;
  // Rotor drag against the airspeed, growing with the rotors' speed [F15].
  const Vec3 drag_B = -speed_sum * Vec3(P.drag_xy * air_B.x(), P.drag_xy * air_B.y(), P.drag_z * air_B.z());
  const Vec3 force_B = Vec3(0, 0, -thrust) + drag_B;
  const Vec3 gravity_B = r_WB.transpose() * Vec3(0, 0, P.gravity);
  const Vec3 inertia(P.ixx, P.iyy, P.izz);
  out.p_dot_W = r_WB * s.v_B;
  out.v_dot_B = force_B / P.mass_kg + gravity_B - s.w_B.cross(s.v_B);
  out.w_dot_B = (torque - s.w_B.cross(inertia.cwiseProduct(s.w_B))).cwiseQuotient(inertia);
  out.euler_rates = euler_rates_from_body_rates(s.attitude, s.w_B);
  return out;
}

Quadrotor::State Quadrotor::step(const State& s, const Controls& a, std::span<const double> p) const {
  if (s.crash != CrashReason::kNone) return s;
  const QuadrotorParams& P = params_;
  State x = s;
  const Vec3 wind_W = P.conditions.mean_wind_W + s.gust_W;
  const double h = P.dt / P.substeps;
  for (int k = 0; k < P.substeps; ++k) {
    // The onboard controller ticks once per substep; its rotor commands hold over the substep (RK4).
    const std::array<double, 4> command = rotor_commands(x, a);
    const Derivative k1 = derivative(x, command, wind_W);
    const Derivative k2 = derivative(advance(x, k1, h / 2), command, wind_W);
    const Derivative k3 = derivative(advance(x, k2, h / 2), command, wind_W);
    const Derivative k4 = derivative(advance(x, k3, h), command, wind_W);
    Derivative sum;
    sum.p_dot_W = rk4_mean<Vec3>(k1.p_dot_W, k2.p_dot_W, k3.p_dot_W, k4.p_dot_W);
    sum.v_dot_B = rk4_mean<Vec3>(k1.v_dot_B, k2.v_dot_B, k3.v_dot_B, k4.v_dot_B);
    sum.euler_rates = rk4_mean<Vec3>(k1.euler_rates, k2.euler_rates, k3.euler_rates, k4.euler_rates);
    sum.w_dot_B = rk4_mean<Vec3>(k1.w_dot_B, k2.w_dot_B, k3.w_dot_B, k4.w_dot_B);
    for (std::size_t i = 0; i < 4; ++i)
      sum.rotor_accel[i] =
          rk4_mean(k1.rotor_accel[i], k2.rotor_accel[i], k3.rotor_accel[i], k4.rotor_accel[i]);
    x = advance(x, sum, h);
  }
  x.attitude.yaw = wrap_angle(x.attitude.yaw);
  x.time = s.time + P.dt;
  disturbances_.step(P.dt, p, x.gust_W, x.estimate_error);
  check_crash(x);
  return x;
}

void Quadrotor::check_crash(State& s) const {
  s.crash =
      rigid_body_crash(true_logged_state(s), s.attitude, s.w_B, params_.max_tilt_rad, params_.max_rate_rad_s);
}

Quadrotor::State Quadrotor::initial_state(std::span<const double> p0) const {
  const QuadrotorParams& P = params_;
  State s;
  s.attitude = {0.0, 0.0, wrap_angle(P.conditions.start_yaw)};
  s.rotor_speed.fill(hover_rotor_speed());
  draw_start(P.conditions, disturbances_, p0, s);
  return s;
}

LoggedState true_logged_state(const QuadrotorState& s) {
  return logged_state_of(s.p_W, s.attitude, s.v_B, s.w_B);
}

LoggedState Quadrotor::observe(const State& s) const {
  return with_estimate_error(true_logged_state(s), s.estimate_error);
}

std::unique_ptr<SimulatedFlight> Quadrotor::start_flight(std::span<const double> p0) const {
  return std::make_unique<ModelFlight<Quadrotor>>(*this, p0);
}

}  // namespace pegasus::heli
