#pragma once
// Pieces shared by the built-in ground truths (aircraft.cpp, quadrotor.cpp).
#include <cmath>
#include <cstddef>
#include <memory>
#include <span>

#include "pegasus/heli/ground_truth.hpp"
#include "pegasus/random/normal_quantile.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {

// The classical Runge-Kutta weighting (k1 + 2 k2 + 2 k3 + k4) / 6 of each part of a derivative, in this order
// of operations.
template <class T>
T rk4_mean(const T& k1, const T& k2, const T& k3, const T& k4) {
  return (k1 + 2 * k2 + 2 * k3 + k4) / 6;
}

// One Euler step of h along d of the rigid-body part of a state (p_W, v_B, attitude, w_B); the aircraft adds
// its own states.
template <class State, class Derivative>
void advance_rigid_body(State& n, const Derivative& d, double h) {
  n.p_W += h * d.p_dot_W;
  n.v_B += h * d.v_dot_B;
  n.attitude.roll += h * d.euler_rates.x();
  n.attitude.pitch += h * d.euler_rates.y();
  n.attitude.yaw += h * d.euler_rates.z();
  n.w_B += h * d.w_dot_B;
}

// What the flight computer sees: the true logged state plus the estimate's errors, yaw wrapped.
inline LoggedState with_estimate_error(LoggedState truth, const LoggedState& error) {
  for (std::size_t i = 0; i < truth.size(); ++i) truth[i] += error[i];
  truth[logged::yaw] = wrap_angle(truth[logged::yaw]);
  return truth;
}

// The start every aircraft draws from p0 (its initial_noise_dim() uniforms), on a state whose attitude is
// set: the position start_p_W perturbed by start_pos_sigma (uniforms 0-2), the velocity by start_vel_sigma in
// W (3-5), then the stationary gusts and estimate errors (6 on: Disturbances::start).
template <class State>
void draw_start(const FlightConditions& P, const Disturbances& disturbances, std::span<const double> p0,
                State& s) {
  const auto n = [&](int i) { return normal_quantile(p0[static_cast<std::size_t>(i)]); };
  Vec3 v_W;
  for (int i = 0; i < 3; ++i) {
    s.p_W[i] = P.start_p_W[i] + P.start_pos_sigma * n(i);
    v_W[i] = P.start_vel_sigma * n(3 + i);
  }
  s.v_B = body_from_world(s.attitude, v_W);
  disturbances.start(p0.subspan(6), s.gust_W, s.estimate_error);
}

// A ground truth's flight behind the GroundTruth interface: it keeps the model's state and steps it. Model
// has State, initial_state(p0), observe(state) and step(state, controls, p); true_logged_state(state) and
// state.crash give the truth and the crash.
template <class Model>
class ModelFlight final : public SimulatedFlight {
 public:
  ModelFlight(const Model& model, std::span<const double> p0)
      : model_(model), state_(model.initial_state(p0)) {}
  LoggedState observe() const override { return model_.observe(state_); }
  LoggedState truth() const override { return true_logged_state(state_); }
  void step(const Controls& a, std::span<const double> p) override { state_ = model_.step(state_, a, p); }
  CrashReason crash() const override { return state_.crash; }

 private:
  const Model& model_;
  typename Model::State state_;
};

// The crashes every rigid body shares, checked in this order: a state that is not finite, the ground (z >=
// 0), roll or pitch beyond max_tilt_rad, a body rate beyond max_rate_rad_s.
inline CrashReason rigid_body_crash(const LoggedState& truth, const Euler& attitude, const Vec3& w_B,
                                    double max_tilt_rad, double max_rate_rad_s) {
  for (double v : truth)
    if (!std::isfinite(v)) return CrashReason::kNumerical;
  if (truth[logged::z] >= 0) return CrashReason::kGround;
  if (std::abs(attitude.roll) > max_tilt_rad || std::abs(attitude.pitch) > max_tilt_rad)
    return CrashReason::kAttitude;
  if (w_B.cwiseAbs().maxCoeff() > max_rate_rad_s) return CrashReason::kRate;
  return CrashReason::kNone;
}

}  // namespace pegasus::heli
