#pragma once
// Gymnasium's Pendulum-v1 as a deterministic simulative model g(s, a, p) (thesis §4.2.1), for the side by
// side race with RLtools (issue 7).
//
// Dynamics, constants and update order are those of gymnasium/envs/classic_control/pendulum.py: a rod of
// mass m = 1 kg and length l = 1 m under gravity g = 10 m/s^2, a torque u clipped to +-2 N m, and every
// dt = 0.05 s a semi-implicit Euler step
//   thetadot' = clip(thetadot + (3 g / (2 l) sin(theta) + 3 / (m l^2) u) dt, -8, 8),
//   theta'    = theta + thetadot' dt                    (the new rate; theta is never wrapped),
// with the reward of the state being left
//   R(s, a) = -(angle_normalize(theta)^2 + 0.1 thetadot^2 + 0.001 u^2),   u the clipped torque,
// and angle_normalize(x) = ((x + pi) mod 2 pi) - pi with Python's floor modulo, in [-pi, pi).
// Angles: radians, theta = 0 upright, positive counter-clockwise. An episode is 200 steps (Gymnasium's
// TimeLimit); nothing is terminal. The start is theta ~ U[-pi, pi], thetadot ~ U[-1, 1]: the two uniforms
// of the initial state, p0 = (p_theta, p_thetadot), map to pi (2 p_theta - 1) and 2 p_thetadot - 1. The
// steps draw no noise (noise_dim 0): all the randomness of Pendulum-v1 is in its start.
//
// Deviation from Gymnasium, below its own resolution: Gymnasium's action box is float32, so its torque is
// rounded to float before the step; here the torque stays double.
#include <cmath>
#include <numbers>
#include <span>

#include "pegasus/models/action_space.hpp"

namespace pegasus {

struct PendulumConstants {
  static constexpr double g = 10.0;                        // m/s^2 (Pendulum-v1's default)
  static constexpr double m = 1.0;                         // kg
  static constexpr double l = 1.0;                         // m
  static constexpr double dt = 0.05;                       // s
  static constexpr double max_speed = 8.0;                 // rad/s: thetadot is clipped to +-max_speed
  static constexpr double max_torque = 2.0;                // N m: u is clipped to +-max_torque
  static constexpr double start_angle = std::numbers::pi;  // theta0 ~ U[-start_angle, start_angle]
  static constexpr double start_speed = 1.0;               // thetadot0 ~ U[-start_speed, start_speed]
  static constexpr int episode_steps = 200;                // Gymnasium's TimeLimit
};

// Gymnasium's angle_normalize: ((x + pi) mod 2 pi) - pi with the modulo of Python (and numpy), whose
// result takes the sign of the divisor; in [-pi, pi).
inline double pendulum_angle_normalize(double x) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  double r = std::fmod(x + std::numbers::pi, two_pi);
  if (r < 0.0) r += two_pi;
  return r - std::numbers::pi;
}

struct PendulumState {
  double theta = 0.0;      // rad from upright, counter-clockwise, not wrapped
  double theta_dot = 0.0;  // rad/s
};

// Gymnasium's observation (cos theta, sin theta, thetadot).
struct PendulumObservation {
  double cos_theta = 1.0, sin_theta = 0.0, theta_dot = 0.0;
};

class Pendulum {
 public:
  using State = PendulumState;
  using Action = double;  // torque (N m); clipped to +-max_torque by the step
  using Observation = PendulumObservation;
  using K = PendulumConstants;

  int state_dim() const { return 2; }
  int noise_dim() const { return 0; }
  int initial_noise_dim() const { return 2; }

  State initial_state(std::span<const double> p0) const {
    return {K::start_angle * (2.0 * p0[0] - 1.0), K::start_speed * (2.0 * p0[1] - 1.0)};
  }

  static double clip_torque(double u) {
    return u < -K::max_torque ? -K::max_torque : (u > K::max_torque ? K::max_torque : u);
  }

  // One step of pendulum.py, in its order of operations (so that the doubles agree bit for bit).
  State step(const State& s, const Action& a, std::span<const double> /*p*/) const {
    const double u = clip_torque(a);
    double theta_dot =
        s.theta_dot +
        (3.0 * K::g / (2.0 * K::l) * std::sin(s.theta) + 3.0 / (K::m * K::l * K::l) * u) * K::dt;
    theta_dot =
        theta_dot < -K::max_speed ? -K::max_speed : (theta_dot > K::max_speed ? K::max_speed : theta_dot);
    return {s.theta + theta_dot * K::dt, theta_dot};
  }

  double reward(const State& s, const Action& a) const {
    const double u = clip_torque(a);
    const double th = pendulum_angle_normalize(s.theta);
    return -(th * th + 0.1 * s.theta_dot * s.theta_dot + 0.001 * (u * u));
  }

  bool terminal(const State& /*s*/) const { return false; }
  Observation observe(const State& s) const { return {std::cos(s.theta), std::sin(s.theta), s.theta_dot}; }
  ActionSpace action_space() const;
};

}  // namespace pegasus
