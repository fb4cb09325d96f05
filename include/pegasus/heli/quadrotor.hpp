#pragma once
// The ground-truth quadrotor: a 6-DOF model of the Crazyflie 2.0 nano quadrotor with the constants Förster
// identified ("System Identification of the Crazyflie 2.0 Nano Quadrocopter", ETH Zürich, 2015, below
// [F15]), flown through its onboard angle-mode controller, stepped at 50 Hz. It is the second aircraft of
// the pipeline (ground_truth.hpp): the learning side sees only its logs, as for the helicopter.
//
// Elements (frames and angles: frames.hpp; X configuration, motors 45 degrees off the body axes):
//   - four rotors, thrust k_f w^2 and drag torque k_m w^2 each, rotor speeds w_i following their commands as
//     first-order lags (the motor time constant);
//   - rotor drag: a force -K (sum of rotor speeds) v_rel_B against the airspeed, diagonal K [F15];
//   - the onboard controller the Crazyflie firmware flies in angle mode, run at every substep (500 Hz):
//     attitude error to a rate set point, rate error to an angular acceleration, and a mixer from collective
//     thrust and torques to rotor speeds within the motors' range;
//   - gravity, the ground at z = 0, Dryden-style gusts and Gauss-Markov state-estimate errors (as the
//     helicopter's; the sizes are chosen for a motion-capture or Lighthouse-tracked nano quadrotor).
// All randomness comes from the uniforms p of a step; a step allocates nothing.
//
// Controls a in [-1, 1]^4 on the pipeline's axes: a1 pitch set point (+: nose down, -a1 * max_tilt_command),
// a2 roll set point (+: roll right), a3 collective thrust ((a3 + 1) / 2 of the motors' full thrust), a4 yaw
// rate set point (+: yaw right).
#include <array>
#include <memory>
#include <span>
#include <string>

#include "pegasus/heli/ground_truth.hpp"
#include "pegasus/models/action_space.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {

struct QuadrotorParams {
  // --- Rigid body [F15] ---
  double mass_kg = 0.028;     // [F15] m, with battery
  double ixx = 16.571710e-6;  // [F15] I_xx, kg m^2
  double iyy = 16.655602e-6;  // [F15] I_yy, kg m^2
  double izz = 29.261652e-6;  // [F15] I_zz, kg m^2
  double arm_m = 0.046;       // [F15] motor to centre of mass, m
  double gravity = 9.81;      // m/s^2
  // --- Rotors ---
  double thrust_coeff =
      2.88e-8;  // k_f, N per (rad/s)^2 ([F15] as gym-pybullet-drones' cf2x: 3.16e-10 N/rpm^2)
  double torque_per_thrust_m = 0.005964552;  // [F15] drag torque per thrust, m (the firmware's THRUST2TORQUE)
  double max_motor_thrust_n = 0.1597;        // [F15] PWM-to-thrust map at full PWM, N per motor
  double motor_tau = 0.0125;                 // rotor speed's first-order lag, s (CrazyS's time_constant_up)
  // Rotor drag [F15]: K_aero, kg/rad, force per (rotor speed sum * airspeed) in B.
  double drag_xy = 9.1785e-7;
  double drag_z = 10.311e-7;
  // --- Onboard angle-mode controller (chosen to fly like the firmware's defaults) ---
  double max_tilt_command_rad = 0.5236;  // roll and pitch set points at full stick (cfclient: 30 degrees)
  double max_yaw_rate_command = 3.491;   // yaw rate set point at full stick, rad/s (cfclient: 200 deg/s)
  double attitude_gain = 6.0;            // rate set point per rad of attitude error, 1/s (firmware's Kp 6)
  double rate_gain = 25.0;               // angular acceleration per rad/s of rate error, 1/s
  double yaw_rate_gain = 10.0;           // yaw acceleration per rad/s of yaw rate error, 1/s
  // --- Disturbances and start (ground_truth.hpp) ---
  FlightConditions conditions{.mean_wind_W = Vec3::Zero(),
                              .gust_sigma = 0.2,  // m/s
                              .gust_tau = 1.0,    // s
                              .est_sigma_pos = 0.01,
                              .est_sigma_vel = 0.02,
                              .est_sigma_angle = 0.005,
                              .est_sigma_rate = 0.02,
                              .est_tau = 0.1,  // correlation time of the estimator's error, s
                              .start_p_W = Vec3(0.0, 0.0, -2.0),  // hover 2 m above the ground
                              .start_yaw = 0.0,
                              .start_pos_sigma = 0.0,
                              .start_vel_sigma = 0.0};
  // --- Crash limits ---
  double max_tilt_rad = 1.0;   // |roll| or |pitch| beyond this: crash
  double max_rate_rad_s = 20;  // |p|, |q| or |r| beyond this: crash
  // --- Integration ---
  double dt = 0.02;   // one control step, s (50 Hz)
  int substeps = 10;  // onboard controller ticks and RK4 steps per control step (500 Hz)

  bool IsValid(std::string* error) const;
};

struct QuadrotorState {
  Vec3 p_W = Vec3::Zero();              // m
  Vec3 v_B = Vec3::Zero();              // m/s
  Euler attitude{};                     // rad
  Vec3 w_B = Vec3::Zero();              // rad/s
  std::array<double, 4> rotor_speed{};  // rad/s: front-right, back-right, back-left, front-left
  Vec3 gust_W = Vec3::Zero();
  LoggedState estimate_error{};
  double time = 0;
  CrashReason crash = CrashReason::kNone;
};

class Quadrotor final : public GroundTruth {
 public:
  using State = QuadrotorState;
  using Action = Controls;
  using Observation = LoggedState;
  static constexpr int kStepNoise = 3 + kLoggedStates;             // gusts, estimate errors
  static constexpr int kInitialNoise = 3 + 3 + 3 + kLoggedStates;  // position, velocity, gusts, estimate

  explicit Quadrotor(QuadrotorParams params = {});
  const QuadrotorParams& params() const { return params_; }

  // A SimulativeModel (models/model.hpp), as the helicopter's Aircraft: tasks (HoverTask) and the Python
  // batch models run it directly.
  int state_dim() const { return kLoggedStates; }
  int noise_dim() const { return kStepNoise; }
  ActionSpace action_space() const { return ActionSpace::box({-1, -1, -1, -1}, {1, 1, 1, 1}); }
  State initial_state(std::span<const double> p0) const;
  State step(const State& s, const Controls& a, std::span<const double> p) const;
  bool terminal(const State& s) const { return s.crash != CrashReason::kNone; }
  LoggedState observe(const State& s) const;
  // Task rewards belong to the tasks; the bare aircraft pays nothing.
  double reward(const State&, const Action&, const State&) const { return 0.0; }

  // Full thrust of the four motors, N, and the rotor speed that holds the aircraft at rest, rad/s.
  double max_thrust() const;
  double hover_rotor_speed() const;

  // Continuous dynamics with the rotor commands held (exposed for tests).
  struct Derivative {
    Vec3 p_dot_W, v_dot_B, euler_rates, w_dot_B;
    std::array<double, 4> rotor_accel;
  };
  Derivative derivative(const State& s, const std::array<double, 4>& rotor_command, const Vec3& wind_W) const;
  // The onboard controller's rotor speed commands for the controls at a state.
  std::array<double, 4> rotor_commands(const State& s, const Controls& a) const;

  // GroundTruth
  std::string simulator_name() const override { return "crazyflie2"; }
  double step_seconds() const override { return params_.dt; }
  double gravity() const override { return params_.gravity; }
  int initial_noise_dim() const override { return kInitialNoise; }
  int step_noise_dim() const override { return kStepNoise; }
  HoverPoint hover_point() const override;
  std::unique_ptr<SimulatedFlight> start_flight(std::span<const double> p0) const override;

 private:
  void check_crash(State& s) const;
  QuadrotorParams params_;
  Disturbances disturbances_;
  Eigen::Matrix4d thrust_from_wrench_;  // per-motor thrust from (collective, roll, pitch, yaw torque)
};

// The true 12 logged states (Euler angle rates, world velocities) of a quadrotor state.
LoggedState true_logged_state(const QuadrotorState& s);

}  // namespace pegasus::heli
