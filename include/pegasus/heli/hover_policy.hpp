#pragma once
// The hover policy class of thesis §5.3 (Fig 5.4, Eqs 5.7-5.8): one small network of sum and tanh nodes per
// control channel, fed by the body-frame position error, velocity and attitude that channel controls.
//
// For channel c with error e, velocity v and attitude angle g (Eq 5.7 for the longitudinal cyclic):
//   t_c = bias + err * e + err_tanh_gain * tanh(err_tanh_in * e) + vel * v + att * g
//   a_c = out_tanh_gain * tanh(out_tanh_in * t_c) + out_linear * t_c          (Eq 5.8)
// clipped to [-1, 1], then to the channel's command limits (HoverPolicyInit::command_lower/upper; [-1, 1]
// unless set: hover training on a global linear model sets them to the controls the logs held, widened by a
// margin, so that the controller never commands what the model extrapolated to). The channels and their
// inputs (frames.hpp: W is north-east-down, B forward-right-down):
//   a1 longitudinal cyclic  e = x_B error   v = xdot_B   g = pitch   (w1..w9 of Eqs 5.7-5.8, in that order)
//   a2 lateral cyclic       e = y_B error   v = ydot_B   g = roll
//   a3 main collective      e = z_B error   v = zdot_B   (no attitude input: 8 weights)
//   a4 tail collective      e = wrap(yaw - yaw*) in (-pi, pi]   v = yaw_rate   (8 weights)
// The position error is (p_W - p*_W) rotated into the body frame, err_B = R_WB^T (p_W - p*_W), and the
// velocity likewise v_B = R_WB^T v_W. As footnote 11 of §5.3 decided, the pitch and roll rates are not
// inputs.
//
// Parameters (34, names "<channel>.<weight>", channel a1..a4, weight as above) are laid out channel by
// channel: a1 at 0..8, a2 at 9..17, a3 at 18..25, a4 at 26..33 (HoverPolicy::offset). The set point may
// change every step: the manoeuvre policy (§5.4) feeds moving set points to this class.
//
// The integral term (not in the thesis; issue 15: without it every learned controller holds a steady offset
// in a steady wind). With an ErrorIntegrator on, four more parameters follow the 34 (names "a1.int" ..
// "a4.int", at 34..37), and each channel adds int * I_c to t_c, where I is the integral over the flight of
// the W-frame position error (m s) and the wrapped yaw error (rad s), each clamped to its limit
// (anti-windup), and the position part rotated into the body frame like the error: I_B = R_WB^T I_W. The
// integral is the flight's memory, not the controller's: the task (training) or the flight
// (heli/policy_file.hpp, ControllerMemory) carries it and hands it over in HeliObservation::integral.
#include <array>
#include <cmath>
#include <span>
#include <string>

#include "pegasus/core/number_setting.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus::heli {

// Where the helicopter should be: position in W (NED, m; z < 0 is above the ground) and heading (rad).
struct SetPoint {
  double x = 0, y = 0, z = -10, yaw = 0;
  bool operator==(const SetPoint&) const = default;
};

// What a helicopter controller sees at one 50 Hz step: the 12 logged states (log column order,
// kLoggedStateNames), the set point of that step, and the error integral so far (ErrorIntegrator; zeros
// without one).
struct HeliObservation {
  LoggedState state{};
  SetPoint target{};
  std::array<double, 4> integral{};  // of x, y, z error in W (m s), of the yaw error (rad s)
};

// The integral term's integrator: I_0 = 0 at the start of a flight, then after every control period dt
// I <- clamp(I + dt * e, -limit, limit) with e the error of the state reached (W-frame position error,
// wrapped yaw error; a non-finite one adds nothing). The one definition the training task and the flown
// controller share.
struct ErrorIntegrator {
  double dt = 0;  // control period, s; 0: no integral term
  // Anti-windup. At the PI rule's int = err / 5 s the limit is worth a 10 m offset: the X-Cell in a steady
  // 4.5 m/s wind needs 3.3 m worth (16.6 m s), and a start error of 1 m decaying over 3 s adds about 3 m s.
  double limit_position = 50;  // |I| per W axis, m s
  double limit_yaw = 10;       // |I_yaw|, rad s
  bool on() const { return dt > 0; }
  std::array<double, 4> advanced(const std::array<double, 4>& integral, const LoggedState& state,
                                 const SetPoint& target) const;
  bool IsValid(std::string* error) const;
  bool operator==(const ErrorIntegrator&) const = default;
};

// The inputs of the four channel networks at one observation.
struct HoverInputs {
  std::array<double, 4> error{};     // x_B, y_B, z_B position error (m), wrapped yaw error (rad)
  std::array<double, 4> velocity{};  // xdot_B, ydot_B, zdot_B (m/s), yaw rate (rad/s)
  std::array<double, 2> attitude{};  // pitch (for a1), roll (for a2), rad
  std::array<double, 4> integral{};  // I_B (x, y, z; m s), I_yaw (rad s); zeros without the term
};
HoverInputs hover_inputs(const HeliObservation& o);

// The starting weights: a linear controller (all tanh gains 0, out_linear 1) around a trim estimate. The
// default gains hold a hover on the identified model; `trim` and the trim attitude should come from the
// flight logs (hover_init_from_model in hover_task.hpp), since the learning side never sees the ground
// truth's trim.
struct HoverPolicyInit {
  Controls trim{0, 0, 0, 0};             // controls that hold a hover
  double trim_roll = 0, trim_pitch = 0;  // attitude at that hover, rad
  // Linear gains (the signs a stabilising controller needs with the control conventions of aircraft.hpp).
  double k_pos = -0.025;      // a1 per m of x_B error
  double k_vel = -0.07;       // a1 per m/s of xdot_B
  double k_att = 1.0;         // a1 per rad of pitch
  double k_pos_lat = -0.025;  // a2 per m of y_B error
  double k_vel_lat = -0.07;   // a2 per m/s of ydot_B
  double k_roll = -1.0;       // a2 per rad of roll
  double k_alt = 0.05;        // a3 per m of z_B error (z down: below the set point -> more collective)
  double k_climb = 0.15;      // a3 per m/s of zdot_B
  double k_yaw = -0.4;        // a4 per rad of yaw error
  double k_yaw_rate = -0.05;  // a4 per rad/s of yaw rate
  // The integral term: none when 0; else each channel's int weight starts at its error gain / this (the
  // classic PI rule k_i = k_p / T_i).
  double integral_seconds = 0;
  // The command limits: each output is clipped to [command_lower[c], command_upper[c]] after [-1, 1]
  // (command_limits_valid). The weights' start does not depend on them.
  Controls command_lower{-1, -1, -1, -1};
  Controls command_upper{1, 1, 1, 1};
  // Limits other than [-1, 1] on some channel.
  bool has_command_limits() const {
    return command_lower != Controls{-1, -1, -1, -1} || command_upper != Controls{1, 1, 1, 1};
  }
};

// -1 <= lower[c] <= upper[c] <= 1 for each channel; else false, with "a2: ..." in *error.
bool command_limits_valid(const Controls& lower, const Controls& upper, std::string* error);
// The last step of every helicopter policy's act (HoverPolicy, ManeuverPolicy): a NaN output becomes 0 rather
// than travelling on to the aircraft, then each is clipped to [-1, 1] and to its channel's command limits.
// Inline, as one clamp per channel to the intersection of the two ranges (the same value as clamping to each
// in turn), written on values rather than std::clamp's references so that it compiles to branch-free min and
// max: it runs at every step of every flight and evaluation (bench/heli_bench.cpp BM_HeliHoverPolicyAct).
inline Controls clip_command(Controls a, const Controls& lower, const Controls& upper) {
  for (std::size_t c = 0; c < 4; ++c) {
    const double lo = lower[c] > -1.0 ? lower[c] : -1.0;
    const double hi = upper[c] < 1.0 ? upper[c] : 1.0;
    const double x = std::isnan(a[c]) ? 0.0 : a[c];
    const double at_least_lo = x < lo ? lo : x;
    a[c] = hi < at_least_lo ? hi : at_least_lo;
  }
  return a;
}
// The training runs' line for the command limits a global linear model's logs give (hover_command_limits,
// widened by `margin` of each control's range): "command limits (...): ..., a1 [-0.4, 0.3], a2 ...".
std::string command_limits_line(const HoverPolicyInit& limits, double margin);
// The margin hover and manoeuvre training widen the logged range by (HoverTrainingOptions::command_margin).
// 100 or more: every limit past [-1, 1], no limits.
inline constexpr double kDefaultCommandMargin = 0.5, kMaxCommandMargin = 100;
// The margin as a setting of hover's and maneuver's training options (their VisitFields).
inline constexpr NumberSetting kCommandMarginSetting{
    "command_margin",
    0,
    kMaxCommandMargin,
    false,
    "",
    "on a global linear model, the policy's commands stay within the range each control held in the logs, "
    "widened by this fraction of its width per side (the model extrapolates beyond them; a locally weighted "
    "model crashes off its data instead); 100: [-1, 1]"};

class HoverPolicy {
 public:
  using Observation = HeliObservation;
  using Action = Controls;
  static constexpr int kParameters = 34;         // the four networks
  static constexpr int kIntegralParameters = 4;  // a1.int .. a4.int after them, with the integral term
  static constexpr std::array<int, 4> kOffset = {0, 9, 18, 26};  // first parameter of each channel
  static constexpr std::array<int, 4> kWeights = {9, 9, 8, 8};   // parameters of each channel
  // Index of a weight within a channel (a3 and a4 have no kAtt; their out_* weights shift down by one).
  enum Weight : int {
    kBias = 0,
    kErr,
    kErrTanhGain,
    kErrTanhIn,
    kVel,
    kAtt,
    kOutTanhGain,
    kOutTanhIn,
    kOutLinear
  };
  // The parameter index of weight w of channel c (0..3).
  static int index(int channel, Weight w);

  explicit HoverPolicy(const HoverPolicyInit& init = {});
  const ParameterSpec& parameters() const { return spec_; }
  bool has_integral() const { return spec_.size() > kParameters; }
  const Controls& command_lower() const { return command_lower_; }
  const Controls& command_upper() const { return command_upper_; }
  bool has_command_limits() const {
    return HoverPolicyInit{.command_lower = command_lower_, .command_upper = command_upper_}
        .has_command_limits();
  }

  // The clipped controls (a NaN output becomes 0 first).
  Controls act(std::span<const double> theta, const HeliObservation& o) const;
  // The network outputs before clipping; the integral term's weights are used when theta has them.
  static Controls unclipped(std::span<const double> theta, const HoverInputs& in);

 private:
  ParameterSpec spec_;
  Controls command_lower_{-1, -1, -1, -1}, command_upper_{1, 1, 1, 1};
};

// The weight names of a channel in layout order ("bias", "err", ...).
std::span<const char* const> hover_weight_names(int channel);

}  // namespace pegasus::heli
