#include "pegasus/heli/pilot.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "pegasus/random/normal_quantile.hpp"

namespace pegasus::heli {

bool PilotOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = std::string("pilot: ") + what;
    return false;
  };
  if (!(reaction_delay_s >= 0 && reaction_delay_s <= 2)) return fail("reaction_delay_s must lie in [0, 2]");
  if (!(bandwidth_tau_s > 0 && noise_tau_s > 0)) return fail("time constants must be positive");
  if (!(noise_sigma >= 0)) return fail("noise_sigma must be >= 0");
  if (!(hover_seconds >= 0)) return fail("hover_seconds must be >= 0");
  if (!(sweep_f0_hz > 0 && sweep_f1_hz > sweep_f0_hz)) return fail("need 0 < sweep_f0_hz < sweep_f1_hz");
  return true;
}

Controls hover_feedback(const HoverPoint& trim, double gravity, const PilotOptions& o, const LoggedState& s,
                        const LoggedState& hold, const std::array<double, 4>& integral,
                        const std::array<double, 4>& k_int) {
  const double yaw = s[logged::yaw];
  const double cy = std::cos(yaw), sy = std::sin(yaw);
  // Errors, velocities and the error's integral in the heading frame (x forward, y right, level).
  const double ex_W = s[logged::x] - hold[logged::x], ey_W = s[logged::y] - hold[logged::y];
  const double ex = cy * ex_W + sy * ey_W, ey = -sy * ex_W + cy * ey_W;
  const double vx = cy * s[logged::xdot] + sy * s[logged::ydot],
               vy = -sy * s[logged::xdot] + cy * s[logged::ydot];
  const double ix = cy * integral[0] + sy * integral[1], iy = -sy * integral[0] + cy * integral[1];
  const double g = gravity;
  const double tilt = o.max_tilt_command;
  // Nose up to brake forward motion; roll left to brake rightward motion. (A zero integral adds exactly 0.)
  const double pitch_cmd =
      trim.pitch + std::clamp((o.k_pos * ex + o.k_vel * vx + k_int[0] * ix) / g, -tilt, tilt);
  const double roll_cmd =
      trim.roll - std::clamp((o.k_pos * ey + o.k_vel * vy + k_int[1] * iy) / g, -tilt, tilt);
  Controls fb;
  namespace axis = control_axis;
  fb[axis::pitch] = trim.controls[axis::pitch] + o.k_att * (s[logged::pitch] - pitch_cmd) +
                    o.k_att_rate * s[logged::pitch_rate];
  fb[axis::roll] = trim.controls[axis::roll] + o.k_att * (roll_cmd - s[logged::roll]) -
                   o.k_att_rate * s[logged::roll_rate];
  fb[axis::thrust] = trim.controls[axis::thrust] + o.k_alt * (s[logged::z] - hold[logged::z]) +
                     o.k_climb * s[logged::zdot] + k_int[2] * integral[2];
  fb[axis::yaw] = trim.controls[axis::yaw] + o.k_yaw * wrap_angle(hold[logged::yaw] - yaw) -
                  o.k_yaw_rate * s[logged::yaw_rate] - k_int[3] * integral[3];
  if (o.attitude_command_gain != 0) {
    fb[axis::pitch] -= o.attitude_command_gain * (pitch_cmd - trim.pitch);
    fb[axis::roll] += o.attitude_command_gain * (roll_cmd - trim.roll);
  }
  return fb;
}

ScriptedPilot::ScriptedPilot(const GroundTruth& aircraft, PilotOptions options, std::uint64_t seed,
                             std::uint32_t stream)
    : aircraft_(aircraft), o_(options), rng_(seed, stream) {
  std::string error;
  if (!o_.IsValid(&error)) throw std::invalid_argument(error);
  const auto n = static_cast<std::size_t>(std::lround(o_.reaction_delay_s / aircraft_.step_seconds())) + 1;
  delay_.resize(n);
  lagged_ = aircraft_.hover_point().controls;
}

int ScriptedPilot::sweep_channel(double time) const {
  if (!o_.sweeps || time < o_.hover_seconds) return -1;
  const double each = (total_seconds_ - o_.hover_seconds) / 4;
  if (each <= 0) return -1;
  return std::min(3, static_cast<int>((time - o_.hover_seconds) / each));
}

double ScriptedPilot::sweep_offset(double time) const {
  const int c = sweep_channel(time);
  if (c < 0) return 0;
  const double each = (total_seconds_ - o_.hover_seconds) / 4;
  const double t = time - o_.hover_seconds - c * each;
  // Exponential chirp from f0 to f1 over the segment, faded in and out over 2 s.
  const double k = o_.sweep_f1_hz / o_.sweep_f0_hz;
  const double phase =
      2 * std::numbers::pi * o_.sweep_f0_hz * each / std::log(k) * (std::pow(k, t / each) - 1);
  const double fade = std::clamp(std::min(t, each - t) / 2.0, 0.0, 1.0);
  return o_.sweep_amplitude[static_cast<std::size_t>(c)] * fade * std::sin(phase);
}

void ScriptedPilot::set_hold(double x, double y, double z, double yaw) {
  hold_ = {};
  hold_[logged::x] = x, hold_[logged::y] = y, hold_[logged::z] = z, hold_[logged::yaw] = yaw;
  have_hold_ = true;
}

Controls ScriptedPilot::act(const LoggedState& estimate, double time) {
  const double dt = aircraft_.step_seconds();
  if (!have_hold_) {
    hold_ = estimate;
    have_hold_ = true;
  }
  delay_[head_] = estimate;
  head_ = (head_ + 1) % delay_.size();
  filled_ = std::min(filled_ + 1, delay_.size());
  // The oldest entry is the estimate reaction_delay_s ago (or the first one, early in the flight).
  const LoggedState& s = filled_ < delay_.size() ? delay_[0] : delay_[head_];
  const Controls fb = hover_feedback(aircraft_.hover_point(), aircraft_.gravity(), o_, s, hold_);
  const double lag = 1 - std::exp(-dt / o_.bandwidth_tau_s);
  const double rho = std::exp(-dt / o_.noise_tau_s);
  const double kn = o_.noise_sigma * std::sqrt(1 - rho * rho);
  Controls out;
  const int channel = sweep_channel(time);
  const double sweep = sweep_offset(time);
  for (std::size_t c = 0; c < 4; ++c) {
    lagged_[c] += lag * (fb[c] - lagged_[c]);
    noise_[c] = rho * noise_[c] + kn * normal_quantile(rng_.next());
    out[c] = std::clamp(lagged_[c] + noise_[c] + (static_cast<int>(c) == channel ? sweep : 0.0), -1.0, 1.0);
  }
  return out;
}

PilotFlight fly_pilot(const GroundTruth& aircraft, const PilotOptions& options, double seconds,
                      std::uint64_t seed) {
  const double dt = aircraft.step_seconds();
  const auto steps = static_cast<std::size_t>(std::llround(seconds / dt));
  // Counter families: stream 0 the aircraft's initial state, 1 its per-step noise, 2 the pilot.
  UniformStream init(seed, 0), noise(seed, 1);
  std::vector<double> p(static_cast<std::size_t>(aircraft.initial_noise_dim()));
  for (double& u : p) u = init.next();
  const std::unique_ptr<SimulatedFlight> flight = aircraft.start_flight(p);
  p.resize(static_cast<std::size_t>(aircraft.step_noise_dim()));
  ScriptedPilot pilot(aircraft, options, seed, 2);
  pilot.set_total_seconds(seconds);
  PilotFlight f;
  f.log.time.reserve(steps);
  f.log.states.reserve(steps);
  f.log.controls.reserve(steps);
  f.truth.reserve(steps);
  for (std::size_t t = 0; t < steps; ++t) {
    const double time = static_cast<double>(t) * dt;
    const LoggedState est = flight->observe();
    const Controls a = pilot.act(est, time);
    f.log.time.push_back(time);
    f.log.states.push_back(est);
    f.log.controls.push_back(a);
    f.truth.push_back(flight->truth());
    for (double& u : p) u = noise.next();
    flight->step(a, p);
    if (flight->crash() != CrashReason::kNone) {
      f.crash = flight->crash();
      f.crash_time = time + dt;
      break;
    }
  }
  return f;
}

}  // namespace pegasus::heli
