#pragma once
// The scripted "human pilot" of §5.2: a stabilising controller that sees the state estimate 0.2 s late,
// adds its own control noise and acts through a limited bandwidth, and flies frequency sweeps (slowly
// increasing frequency, about 0.1 to 3 Hz) in each of the four channels in turn while holding the aircraft
// with the other three, as well as plain hover.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pegasus/heli/ground_truth.hpp"
#include "pegasus/random/counter_rng.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus::heli {

struct PilotOptions {
  double reaction_delay_s = 0.2;  // the pilot acts on what the estimate said this long ago
  double bandwidth_tau_s = 0.08;  // first-order lag of the pilot's stabilising corrections, s
  double noise_sigma = 0.02;      // pilot control noise (Gauss-Markov), per channel
  double noise_tau_s = 0.5;       // correlation time of that noise, s
  double hover_seconds = 10.0;    // plain hover before the sweeps (and the whole flight if no sweeps)
  bool sweeps = true;             // fly a sweep in each channel in turn after the hover
  double sweep_f0_hz = 0.1, sweep_f1_hz = 3.0;
  std::array<double, 4> sweep_amplitude{0.15, 0.15, 0.15, 0.15};  // per channel
  // Stabilising gains (heading frame): position and velocity to desired attitude, attitude to cyclic.
  double k_pos = 0.25, k_vel = 0.7;       // desired acceleration per m and per m/s
  double k_att = 1.0, k_att_rate = 0.05;  // cyclic per rad of attitude error and per rad/s
  double k_alt = 0.05, k_climb = 0.15;    // collective per m and per m/s
  double k_yaw = 0.4, k_yaw_rate = 0.05;  // tail per rad and per rad/s
  double max_tilt_command = 0.3;          // rad
  // For an aircraft that holds its own attitude (a quadrotor's angle mode): stick per rad of the desired
  // attitude's change from the hover point, added open loop to the pitch and roll channels (0: none).
  double attitude_command_gain = 0;
  bool IsValid(std::string* error) const;
};

// A hand-tuned baseline's gains (heli/baselines.hpp): the pilot's stabilising law below, without the
// pilot's delay, lag, noise and sweeps, with an integral term. A ground truth's registry entry carries its
// own (heli/simulators.hpp).
struct BaselineGains {
  PilotOptions law{};              // the feedback gains (PilotOptions' k_* fields and max_tilt_command)
  std::array<double, 4> k_int{};   // per s of the x, y, z and yaw errors' integrals (hover_feedback)
  double integral_limit_m_s = 20;  // anti-windup: |integral| per axis, m s (yaw: rad s)
};

// The pilot's stabilising law (heading frame, no delay, lag or noise): position and velocity to the desired
// attitude (clamped to max_tilt_command), attitude and rate feedback to the cyclic (or, with
// attitude_command_gain, the desired attitude as the command), altitude and climb rate to the collective,
// heading and yaw rate to the tail. `integral`: the W-frame position error's integral (m s) and the yaw
// error's (rad s), as ErrorIntegrator keeps them (hover_policy.hpp); `k_int` weighs them beside k_pos, k_alt
// and k_yaw (per s; 0: none). The scripted pilot and the hand-tuned baselines (baselines.hpp) share it.
Controls hover_feedback(const HoverPoint& trim, double gravity, const PilotOptions& gains,
                        const LoggedState& s, const LoggedState& hold,
                        const std::array<double, 4>& integral = {}, const std::array<double, 4>& k_int = {});

// The pilot's controller; one per flight (it keeps its delay line and noise state).
class ScriptedPilot {
 public:
  ScriptedPilot(const GroundTruth& aircraft, PilotOptions options, std::uint64_t seed, std::uint32_t stream);
  // Controls for step t (time = t * dt) given the current state estimate; hold point = the start.
  Controls act(const LoggedState& estimate, double time);
  // The sweep channel at a time (-1: hover only) and its open-loop offset.
  int sweep_channel(double time) const;
  double sweep_offset(double time) const;
  void set_total_seconds(double seconds) { total_seconds_ = seconds; }
  // Holds this position (W, m) and heading (rad) instead of where the first estimate put the aircraft.
  void set_hold(double x, double y, double z, double yaw);

 private:
  const GroundTruth& aircraft_;
  PilotOptions o_;
  UniformStream rng_;
  std::vector<LoggedState> delay_;  // ring buffer of past estimates, sized once
  std::size_t head_ = 0, filled_ = 0;
  Controls lagged_{}, noise_{};
  LoggedState hold_{};
  bool have_hold_ = false;
  double total_seconds_ = 60;
};

struct PilotFlight {
  sysid::FlightLog log;            // the 50 Hz estimate and the controls (what the learning side sees)
  std::vector<LoggedState> truth;  // the true states, same rows
  CrashReason crash = CrashReason::kNone;
  double crash_time = -1;
};

// Flies `seconds` of the pilot's plan on the aircraft from its initial state; all randomness from `seed`.
PilotFlight fly_pilot(const GroundTruth& aircraft, const PilotOptions& options, double seconds,
                      std::uint64_t seed);

}  // namespace pegasus::heli
