#pragma once
// The ground-truth helicopter: a nonlinear 6-DOF single-rotor model of a small aerobatic helicopter (the
// MIT X-Cell 60 of Gavrilets, Mettler and Feron, "Nonlinear model for a small-size acrobatic helicopter",
// AIAA 2001-4333, below [GMF01]) stepped at 50 Hz. It plays the real aircraft of thesis chapter 5: the
// learning side only sees its logs and, at the end, flies controllers on it.
//
// Elements (frames and angles: frames.hpp):
//   - main rotor thrust from collective pitch by blade-element theory with momentum-theory inflow, solved
//     by Newton's method at every derivative evaluation ([GMF01] Eqs for C_T and lambda_0);
//   - tip-path-plane flapping (flap_lon, flap_lat) as first-order lags with the stabilizer-bar time
//     constant tau_e, driven by the cyclic servos, the body rates and the flap-back from airspeed (§5.2.2:
//     the Bell-Hiller stabilizer makes cyclic act with a latency);
//   - hub spring moment K_beta and thrust offset h_mr; main-rotor torque; tail-rotor thrust with its own
//     inflow, whose side force makes hover need a small roll to the right (thesis §5 introduction);
//   - a yaw-rate gyro: the tail pitch is fed back from a lagged yaw rate (the extra state of §5.2.2);
//   - fuselage drag in the rotor downwash; servo rate and range limits; gravity; the ground at z = 0;
//   - Dryden-style turbulence: each wind axis a first-order Gauss-Markov process (the Dryden spectrum's
//     low-frequency form), and state-estimate noise as correlated Gauss-Markov errors like the output of
//     the 50 Hz Kalman filter of §5.1.
// All randomness comes from the uniforms p of a step (SimulativeModel, thesis §4.2.1); a step allocates
// nothing.
//
// Controls a in [-1, 1]^4 (§5.1): a1 longitudinal cyclic (+: disc forward, nose down, accelerate forward),
// a2 lateral cyclic (+: disc right, roll right), a3 main collective (+: more thrust, climb), a4 tail
// collective
// (+: more tail thrust, yaw right, i.e. clockwise seen from above).
#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "pegasus/heli/ground_truth.hpp"
#include "pegasus/models/action_space.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "pegasus/vehicle/state.hpp"

namespace pegasus::heli {

// The 12 logged states of §5.1: LoggedState and Controls (vehicle/state.hpp); CrashReason: ground_truth.hpp.

struct AircraftParams {
  // --- Rigid body [GMF01, Table 1] ---
  double mass_kg = 8.2;        // [GMF01] m
  double ixx = 0.18;           // [GMF01] I_xx, kg m^2
  double iyy = 0.34;           // [GMF01] I_yy, kg m^2
  double izz = 0.28;           // [GMF01] I_zz, kg m^2
  double gravity = 9.81;       // m/s^2
  double air_density = 1.204;  // kg/m^3, sea-level pressure at 20 C (the ISA day, 15 C, gives 1.225)
  // --- Main rotor [GMF01] ---
  double omega_mr = 167.0;         // [GMF01] nominal rotor speed, rad/s (1600 rpm)
  double radius_mr = 0.775;        // [GMF01] R_mr, m
  double chord_mr = 0.058;         // [GMF01] c_mr, m
  double lift_slope_mr = 5.5;      // [GMF01] a_mr, 1/rad
  double profile_drag_mr = 0.024;  // [GMF01] C_D0, blade profile drag coefficient
  double hub_height = 0.235;       // [GMF01] h_mr, hub above the centre of mass, m
  double hub_stiffness = 54.0;     // [GMF01] K_beta, effective hub torsional stiffness, N m/rad
  double tau_flap = 0.1;           // [GMF01] tau_e, rotor-with-stabilizer-bar time constant, s
  double a_lon = 4.2;              // [GMF01] A_lon, flapping per longitudinal cyclic, rad/rad
  double b_lat = 4.2;              // [GMF01] B_lat, flapping per lateral cyclic, rad/rad
  double cyclic_max_rad = 0.05;    // cyclic blade pitch at full stick, rad (chosen: 0.21 rad of steady flap)
  double collective_mid_rad = 0.08;   // main collective at a3 = 0, rad (chosen; hover needs about 0.1)
  double collective_span_rad = 0.10;  // main collective change at a3 = +-1, rad
  // --- Tail rotor [GMF01] ---
  double gear_tr = 4.66;        // [GMF01] n_tr, tail/main rotor speed ratio
  double radius_tr = 0.13;      // [GMF01] R_tr, m
  double chord_tr = 0.029;      // [GMF01] c_tr, m
  double lift_slope_tr = 5.0;   // [GMF01] a_tr, 1/rad
  double arm_tr = 0.91;         // [GMF01] l_tr, tail rotor hub behind the centre of mass, m
  double height_tr = 0.08;      // [GMF01] h_tr, tail rotor hub above the centre of mass, m
  double tail_mid_rad = 0.15;   // tail collective at a4 = 0, rad (chosen)
  double tail_span_rad = 0.25;  // tail collective change at a4 = +-1, rad
  // --- Yaw-rate gyro (the X-Cell flies with a rate gyro on the tail servo [GMF01]; gain and lag chosen) ---
  double gyro_gain = 0.08;  // tail pitch per filtered yaw rate, rad per rad/s
  double gyro_tau = 0.05;   // first-order lag of the gyro loop, s
  // --- Fuselage drag, effective flat-plate areas [GMF01] ---
  double fus_area_x = 0.1;   // [GMF01] S_x^fus, m^2
  double fus_area_y = 0.22;  // [GMF01] S_y^fus, m^2
  double fus_area_z = 0.15;  // [GMF01] S_z^fus, m^2
  // --- Servos (chosen: a standard RC servo moves about 60 degrees in 0.15 s) ---
  double servo_rate = 8.0;  // normalised units per second
  // --- Disturbances and start (ground_truth.hpp) ---
  FlightConditions conditions{
      .mean_wind_W = Vec3::Zero(),
      .gust_sigma = 0.5,  // m/s
      .gust_tau = 2.0,    // turbulence correlation time L/V, s
      // State-estimate errors (§5.1: a Kalman filter fusing DGPS with 2 cm resolution, INS and compass)
      .est_sigma_pos = 0.02,               // m
      .est_sigma_vel = 0.03,               // m/s
      .est_sigma_angle = 0.005,            // rad
      .est_sigma_rate = 0.01,              // rad/s
      .est_tau = 0.3,                      // correlation time of the filter's error, s
      .start_p_W = Vec3(0.0, 0.0, -10.0),  // hover 10 m above the ground
      .start_yaw = 0.0,
      .start_pos_sigma = 0.0,
      .start_vel_sigma = 0.0};
  // --- Crash limits ---
  double max_tilt_rad = 1.0;                     // |roll| or |pitch| beyond this: crash
  double max_rate_rad_s = 6.0;                   // |p|, |q| or |r| beyond this: crash
  double max_thrust_coeff_over_solidity = 0.15;  // C_T / sigma beyond this: blade stall, rotor overload
  // --- Integration ---
  double dt = 0.02;  // one control step, s (50 Hz, §5.1)
  int substeps = 2;  // RK4 substeps per control step

  bool IsValid(std::string* error) const;
};

struct AircraftState {
  Vec3 p_W = Vec3::Zero();       // position of the centre of mass in W, m
  Vec3 v_B = Vec3::Zero();       // velocity of the centre of mass expressed in B, m/s
  Euler attitude{};              // rad
  Vec3 w_B = Vec3::Zero();       // body angular rate (p, q, r), rad/s
  double flap_lon = 0;           // tip-path-plane tilt relative to the shaft, + forward, rad
  double flap_lat = 0;           // + right, rad
  double gyro_rate = 0;          // the gyro's lagged yaw rate, rad/s
  Controls servo{};              // actuator positions in [-1, 1]
  Vec3 gust_W = Vec3::Zero();    // turbulence velocity in W, m/s
  LoggedState estimate_error{};  // state estimate minus truth, per logged state
  double time = 0;               // s
  CrashReason crash = CrashReason::kNone;
};

// Forces and rotor quantities at a state (for tests and trim).
struct RotorReport {
  double thrust_n = 0, torque_nm = 0, inflow_ratio = 0, tail_thrust_n = 0, thrust_coeff_over_solidity = 0;
};

class Aircraft final : public GroundTruth {
 public:
  using State = AircraftState;
  using Action = Controls;
  using Observation = LoggedState;

  static constexpr int kStepNoise = 3 + kLoggedStates;             // gusts, estimate errors
  static constexpr int kInitialNoise = 3 + 3 + 3 + kLoggedStates;  // position, velocity, gusts, estimate

  explicit Aircraft(AircraftParams params = {});
  const AircraftParams& params() const { return params_; }

  int state_dim() const { return kLoggedStates; }
  int noise_dim() const { return kStepNoise; }
  int initial_noise_dim() const override { return kInitialNoise; }
  ActionSpace action_space() const;
  // Trimmed hover at params().conditions.start_p_W, perturbed by start_*_sigma, stationary gusts and estimate
  // errors.
  State initial_state(std::span<const double> p0) const;
  // One 50 Hz step with actions clipped to [-1, 1]; a crashed state stays as it is.
  State step(const State& s, const Action& a, std::span<const double> p) const;
  bool terminal(const State& s) const { return s.crash != CrashReason::kNone; }
  // What the flight computer sees: the true logged state plus the Kalman-filter-like estimate error.
  Observation observe(const State& s) const;
  // Task rewards belong to the tasks (hover, manoeuvres); the bare aircraft pays nothing.
  double reward(const State&, const Action&, const State&) const { return 0.0; }

  // The hover trim found by Newton's method: zero linear and angular accelerations at rest.
  struct Trim {
    Controls controls{};
    double roll = 0, pitch = 0;
    double residual = 0;  // largest |acceleration| left, m/s^2 or rad/s^2
    RotorReport rotor{};
  };
  const Trim& hover_trim() const { return trim_; }

  // Continuous dynamics (exposed for tests): time derivative of the integrated part of the state, with
  // servo positions and wind held.
  struct Derivative {
    Vec3 p_dot_W, v_dot_B, euler_rates, w_dot_B;
    double flap_lon_dot, flap_lat_dot, gyro_dot;
  };
  Derivative derivative(const State& s, const Vec3& wind_W, RotorReport* report = nullptr) const;

  // GroundTruth: the same aircraft behind the interface the pilot and flights use.
  std::string simulator_name() const override { return "xcell"; }
  double step_seconds() const override { return params_.dt; }
  double gravity() const override { return params_.gravity; }
  int step_noise_dim() const override { return kStepNoise; }
  HoverPoint hover_point() const override { return {trim_.controls, trim_.roll, trim_.pitch}; }
  std::unique_ptr<SimulatedFlight> start_flight(std::span<const double> p0) const override;

 private:
  Trim find_trim() const;
  void check_crash(State& s) const;
  AircraftParams params_;
  Disturbances disturbances_;
  Trim trim_;
};

// The true 12 logged states (Euler angle rates, world velocities) of an aircraft state.
LoggedState true_logged_state(const AircraftState& s);

}  // namespace pegasus::heli
