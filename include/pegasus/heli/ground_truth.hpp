#pragma once
// A simulated aircraft that plays the real one of thesis chapter 5: the scripted pilot's logs and every
// flight of a learned controller come from one. Two are built in, named by a vehicle file's `[vehicle]
// simulator`: the X-Cell 60 helicopter (aircraft.hpp, "xcell") and the Crazyflie 2.0 quadrotor
// (quadrotor.hpp, "crazyflie2").
//
// Every aircraft takes controls a in [-1, 1]^4 on the pipeline's four axes (each aircraft says what drives
// them): a1 pitch (+: nose down, accelerate forward), a2 roll (+: roll right), a3 thrust (+: climb), a4 yaw
// (+: yaw right, clockwise seen from above).
//
// Randomness follows SimulativeModel's rule (thesis §4.2.1): a flight's start reads initial_noise_dim()
// uniforms, each step step_noise_dim() more, and nothing else is random.
#include <array>
#include <memory>
#include <span>
#include <string>

#include "pegasus/vehicle/frames.hpp"
#include "pegasus/vehicle/state.hpp"

namespace pegasus::heli {

// The most integration substeps per control step a built-in aircraft takes: it bounds the work of one step
// (10^9 made one step run for minutes).
inline constexpr int kMaxSubsteps = 10000;

enum class CrashReason : int {
  kNone = 0,
  kGround,
  kAttitude,
  kRate,
  kRotorOverload,
  kNumerical,
  kModelSupport
};
std::string crash_reason_name(CrashReason r);

// The controls and attitude that hold the aircraft still in calm air.
struct HoverPoint {
  Controls controls{};
  double roll = 0, pitch = 0;
};

// The disturbances every built-in aircraft shares: turbulence, each wind axis a first-order Gauss-Markov
// process (the Dryden spectrum's low-frequency form), and state-estimate errors, each logged state's a
// Gauss-Markov process like a Kalman filter's output error.
struct Disturbances {
  double gust_sigma = 0, gust_tau = 1;                                                   // m/s, s
  double est_sigma_pos = 0, est_sigma_angle = 0, est_sigma_vel = 0, est_sigma_rate = 0;  // m, rad, m/s, rad/s
  double est_tau = 1;                                                                    // s
  // Stationary draws from 3 + kLoggedStates uniforms: the gusts, then the estimate errors.
  void start(std::span<const double> p, Vec3& gust_W, LoggedState& estimate_error) const;
  // One step of dt (exact discretisation) from 3 + kLoggedStates uniforms, in the same order.
  void step(double dt, std::span<const double> p, Vec3& gust_W, LoggedState& estimate_error) const;
};

// Where a flight starts and what disturbs it: the part every built-in aircraft's params share (each with its
// own defaults), and all that the commands' settings change (simulators.hpp). The start state is drawn from
// it by draw_start (src/heli/simulation.hpp), the gusts and estimate errors by its Disturbances.
struct FlightConditions {
  Vec3 mean_wind_W = Vec3::Zero();  // steady wind, m/s in W
  double gust_sigma = 0;            // turbulence standard deviation per axis, m/s
  double gust_tau = 1;              // turbulence correlation time, s
  double est_sigma_pos = 0;         // state-estimate error (standard deviation) in position, m
  double est_sigma_vel = 0;         // in velocity, m/s
  double est_sigma_angle = 0;       // in attitude, rad
  double est_sigma_rate = 0;        // in the body rates, rad/s
  double est_tau = 1;               // correlation time of the estimate's error, s
  Vec3 start_p_W = Vec3::Zero();    // where the flight starts, m in W (NED: z < 0 is above the ground)
  double start_yaw = 0;             // rad
  double start_pos_sigma = 0;       // start position perturbation per axis, m
  double start_vel_sigma = 0;       // start velocity perturbation per axis, m/s

  Disturbances disturbances() const {
    return {gust_sigma, gust_tau, est_sigma_pos, est_sigma_angle, est_sigma_vel, est_sigma_rate, est_tau};
  }
};

// One flight of a simulated aircraft, from its start.
class SimulatedFlight {
 public:
  virtual ~SimulatedFlight() = default;
  virtual LoggedState observe() const = 0;  // what the flight computer sees: the truth plus estimate errors
  virtual LoggedState truth() const = 0;    // the true logged state
  // One step of step_seconds() with the controls clipped to [-1, 1]; after a crash the state stays.
  virtual void step(const Controls& a, std::span<const double> p) = 0;
  virtual CrashReason crash() const = 0;
};

class GroundTruth {
 public:
  virtual ~GroundTruth() = default;
  virtual std::string simulator_name() const = 0;
  virtual double step_seconds() const = 0;
  virtual double gravity() const = 0;
  virtual int initial_noise_dim() const = 0;
  virtual int step_noise_dim() const = 0;
  virtual HoverPoint hover_point() const = 0;
  // A flight from the aircraft's (perturbed) start, drawn from p0 (initial_noise_dim() uniforms).
  virtual std::unique_ptr<SimulatedFlight> start_flight(std::span<const double> p0) const = 0;
};

}  // namespace pegasus::heli
