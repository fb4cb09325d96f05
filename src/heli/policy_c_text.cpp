// The C text of the helicopter classes (policies/c_text.hpp), registered with their controllers
// (policy_file.cpp): the hover and manoeuvre networks as hover_policy.cpp, maneuver_policy.cpp and
// vehicle/frames.cpp compute them. codegen/c_policy.cpp assembles it (and wraps it in an aircraft's own
// terms, c_policy_vehicle.cpp).
#include <fmt/format.h>

#include <numbers>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/policies/c_text.hpp"

namespace pegasus::heli {
namespace {

using codegen::c_double;
using codegen::c_table;
using codegen::ClassText;
using codegen::comment_text;
using codegen::fill;

// ---- Helicopter classes (hover, maneuver) --------------------------------------------------------------

// The hover networks and their inputs, as heli/hover_policy.cpp and vehicle/frames.cpp compute them.
constexpr const char* kHeliCommon = R"(static const double kPi = @PI@;
static const double kTwoPi = @TWO_PI@;

/* vehicle/frames.cpp wrap_angle: into (-pi, pi]. */
static double wrap_angle(double a) {
  double r = remainder(a, kTwoPi);
  if (r <= -kPi) r += kTwoPi;
  return r;
}

static double clamp(double x, double lo, double hi) { return x < lo ? lo : (hi < x ? hi : x); }

/* A NaN output becomes 0 rather than travelling on to the aircraft (HoverPolicy::act). */
static double clip_control(double x) { return isnan(x) ? 0.0 : clamp(x, -1.0, 1.0); }

/* heli/hover_policy.cpp hover_inputs: the position error and velocity rotated into the body frame,
 * R_BW = R_WB^T with R_WB = R_z(yaw) R_y(pitch) R_x(roll). The products sum as Eigen's 3x3 product does
 * (rows 0 and 1 left to right, row 2 as a0 + (a1 + a2)). With an error integral (integral_w not 0), its
 * position part likewise (zeros when it is all zero). */
static void hover_inputs(const double* s, const double* target, const double* integral_w, double* error,
                         double* velocity, double* attitude, double* integral_b) {
  const double cf = cos(s[3]), sf = sin(s[3]);
  const double ct = cos(s[4]), st = sin(s[4]);
  const double cp = cos(s[5]), sp = sin(s[5]);
  const double r00 = ct * cp, r01 = sf * st * cp - cf * sp, r02 = cf * st * cp + sf * sp;
  const double r10 = ct * sp, r11 = sf * st * sp + cf * cp, r12 = cf * st * sp - sf * cp;
  const double r20 = -st, r21 = sf * ct, r22 = cf * ct;
  const double dx = s[0] - target[0], dy = s[1] - target[1], dz = s[2] - target[2];
  error[0] = r00 * dx + r10 * dy + r20 * dz;
  error[1] = r01 * dx + r11 * dy + r21 * dz;
  error[2] = r02 * dx + (r12 * dy + r22 * dz);
  error[3] = wrap_angle(s[5] - target[3]);
  velocity[0] = r00 * s[6] + r10 * s[7] + r20 * s[8];
  velocity[1] = r01 * s[6] + r11 * s[7] + r21 * s[8];
  velocity[2] = r02 * s[6] + (r12 * s[7] + r22 * s[8]);
  velocity[3] = s[11];
  attitude[0] = s[4];
  attitude[1] = s[3];
  if (integral_w) {
    const double* i = integral_w;
    integral_b[0] = integral_b[1] = integral_b[2] = integral_b[3] = 0;
    if (i[0] != 0 || i[1] != 0 || i[2] != 0 || i[3] != 0) {
      integral_b[0] = r00 * i[0] + r10 * i[1] + r20 * i[2];
      integral_b[1] = r01 * i[0] + r11 * i[1] + r21 * i[2];
      integral_b[2] = r02 * i[0] + (r12 * i[1] + r22 * i[2]);
      integral_b[3] = i[3];
    }
  }
}

/* heli/hover_policy.cpp HoverPolicy::unclipped (Eqs 5.7-5.8): per channel c,
 *   t = bias + err e + err_tanh_gain tanh(err_tanh_in e) + vel v (+ att g for a1, a2) (+ int I_c),
 *   a = out_tanh_gain tanh(out_tanh_in t) + out_linear t. */
static void hover_networks(const double* w, const double* error, const double* velocity,
                           const double* attitude, const double* integral, double* a) {
  static const int offset[4] = {0, 9, 18, 26};
  int c;
  for (c = 0; c < 4; ++c) {
    const double* k = w + offset[c];
    const double e = error[c];
    double t = k[0] + k[1] * e + k[2] * tanh(k[3] * e) + k[4] * velocity[c];
    if (c < 2) {
      t += k[5] * attitude[c];
    } else {
      --k; /* no attitude weight: the out_* weights sit one place earlier */
    }
    if (integral) t += w[34 + c] * integral[c];
    a[c] = k[6] * tanh(k[7] * t) + k[8] * t;
  }
}

static int all_finite(const double* x, int n) {
  int i;
  for (i = 0; i < n; ++i)
    if (!isfinite(x[i])) return 0;
  return 1;
}
)";

const std::vector<std::string> kHeliObservationNames = {"time",      "x",          "y",       "z",    "roll",
                                                        "pitch",     "yaw",        "xdot",    "ydot", "zdot",
                                                        "roll_rate", "pitch_rate", "yaw_rate"};
const std::vector<std::string> kHeliObservationUnits = {"s since the flight (manoeuvre) began",
                                                        "m, world frame W north-east-down",
                                                        "m, W",
                                                        "m, W (z < 0 is above the ground)",
                                                        "rad, Z-Y-X Euler angle",
                                                        "rad, Z-Y-X Euler angle",
                                                        "rad, Z-Y-X Euler angle, any wrap",
                                                        "m/s, W",
                                                        "m/s, W",
                                                        "m/s, W",
                                                        "rad/s, d(roll)/dt",
                                                        "rad/s, d(pitch)/dt",
                                                        "rad/s, d(yaw)/dt"};
const std::vector<std::string> kHeliActionNames = {"a1", "a2", "a3", "a4"};
// By the axis each drives (heli::kControlAxisNames), as for any aircraft; the X-Cell's names in brackets.
const std::vector<std::string> kHeliActionUnits = {
    "pitch in [-1, 1] (+: nose down, accelerate forward; the X-Cell's longitudinal cyclic)",
    "roll in [-1, 1] (+: roll right; the X-Cell's lateral cyclic)",
    "thrust in [-1, 1] (+: more thrust, climb; the X-Cell's main collective)",
    "yaw in [-1, 1] (+: yaw right; the X-Cell's tail collective)"};

std::string heli_description(const std::string& what) {
  return what +
         "\n * The observation is exactly what `pegasus heli control` reads as a 13-field line (time, then "
         "the"
         "\n * flight log's 12 state columns of vehicle/flight_log.hpp); the action is its output line.";
}

ClassText heli_class(const heli::PolicyFile& file, const std::vector<double>& hover_weights) {
  ClassText t;
  t.class_name = file.class_name;  // the registered name the file gives, whichever text it uses
  t.observation_names = kHeliObservationNames;
  t.observation_units = kHeliObservationUnits;
  t.action_names = kHeliActionNames;
  t.action_units = kHeliActionUnits;
  t.safe = fmt::format("the trim controls of the policy file, {}, {}, {}, {}", file.trim[0], file.trim[1],
                       file.trim[2], file.trim[3]);
  t.has_target = true;
  t.body =
      fill(kHeliCommon, {{"PI", c_double(std::numbers::pi)}, {"TWO_PI", c_double(2 * std::numbers::pi)}});
  t.body += "\n" + c_table("kWeights", hover_weights, file.names);
  t.body += c_table("kTrim", {file.trim.begin(), file.trim.end()}, {"a1", "a2", "a3", "a4"});
  return t;
}

// The integral term's integrator (heli/hover_policy.cpp ErrorIntegrator::advanced) and the act with memory.
constexpr const char* kHoverIntegral = R"(
/* heli/hover_policy.cpp ErrorIntegrator::advanced: I <- clamp(I + dt e, -limit, limit) per axis, e the error
 * of the state reached (a non-finite one adds nothing). */
static void advance_integral(double* integral, const double* s) {
  double e[4];
  int i;
  e[0] = s[0] - kTarget[0];
  e[1] = s[1] - kTarget[1];
  e[2] = s[2] - kTarget[2];
  e[3] = wrap_angle(s[5] - kTarget[3]);
  for (i = 0; i < 4; ++i) {
    const double limit = i < 3 ? kIntegral[1] : kIntegral[2];
    if (isfinite(e[i])) integral[i] = clamp(integral[i] + kIntegral[0] * e[i], -limit, limit);
  }
}

void @NAME@_reset(@NAME@_memory* memory) {
  int i;
  for (i = 0; i < 4; ++i) memory->integral[i] = 0;
  memory->started = 0;
}

int @NAME@_act(@NAME@_memory* memory, const double* observation, double* action) {
  double error[4], velocity[4], attitude[2], integral[4];
  int c;
  if (!all_finite(observation, 13)) {
    for (c = 0; c < 4; ++c) action[c] = kTrim[c];
    return 1;
  }
  /* heli/policy_file.cpp HoverController::act: 0 at the flight's first call, then one period's error each. */
  if (memory->started) {
    advance_integral(memory->integral, observation + 1);
  } else {
    @NAME@_reset(memory);
    memory->started = 1;
  }
  hover_inputs(observation + 1, kTarget, memory->integral, error, velocity, attitude, integral);
  hover_networks(kWeights, error, velocity, attitude, integral, action);
  for (c = 0; c < 4; ++c) action[c] = clip_control(action[c]);
  return 0;
}
)";

}  // namespace

namespace {

// The hover act's last step with the file's command limits (HoverPolicy::act): each output clipped to
// [-1, 1] and then to its channel's limits, in that order, as the C++ does.
void add_command_limits(const heli::HoverPolicyInit& limits, std::string* body) {
  const std::vector<std::string> names = {"a1", "a2", "a3", "a4"};
  *body += c_table("kCommandLower", {limits.command_lower.begin(), limits.command_lower.end()}, names);
  *body += c_table("kCommandUpper", {limits.command_upper.begin(), limits.command_upper.end()}, names);
}

std::string with_command_limits(std::string act) {
  const std::string plain = "action[c] = clip_control(action[c]);";
  const std::string limited =
      "action[c] = clamp(clip_control(action[c]), kCommandLower[c], kCommandUpper[c]);";
  for (std::size_t at = act.find(plain); at != std::string::npos; at = act.find(plain, at + limited.size()))
    act.replace(at, plain.size(), limited);
  return act;
}

}  // namespace

ClassText hover_c_text(const heli::PolicyFile& file, const std::string& source) {
  const heli::ErrorIntegrator integrator = heli::hover_file_integrator(file, source);
  const heli::HoverPolicyInit limits = heli::hover_file_command_limits(file, source);
  const bool limited = limits.has_command_limits();
  const Theta theta = heli::checked_hover_parameters(file, source);
  ClassText t = heli_class(file, theta);
  t.has_memory = integrator.on();
  t.description = heli_description(
      fmt::format("The hover controller of thesis §5.3 (Fig 5.4, Eqs 5.7-5.8) holding the set point x = {}, "
                  "y = {}, z = {} m, yaw = {} rad{}.",
                  file.target.x, file.target.y, file.target.z, file.target.yaw,
                  integrator.on() ? fmt::format(",\n * with the integral term (its integrator steps {} s per "
                                                "call: one call per control period)",
                                                integrator.dt)
                                  : std::string()));
  t.extra_declarations =
      "/* The set point at `time`: x, y, z (m, W north-east-down), yaw (rad). Returns 0. */\n"
      "int @NAME@_target(double time, double* set_point);\n";
  t.body += c_table("kTarget", {file.target.x, file.target.y, file.target.z, file.target.yaw},
                    {"x", "y", "z", "yaw"});
  t.body += R"(
int @NAME@_target(double time, double* set_point) {
  int i;
  (void)time;
  for (i = 0; i < 4; ++i) set_point[i] = kTarget[i];
  return 0;
}
)";
  if (limited) add_command_limits(limits, &t.body);
  const auto act = [&](std::string text) { return limited ? with_command_limits(std::move(text)) : text; };
  if (integrator.on()) {
    t.body += c_table("kIntegral", {integrator.dt, integrator.limit_position, integrator.limit_yaw},
                      {"dt (s)", "limit_position (m s)", "limit_yaw (rad s)"});
    t.body += act(kHoverIntegral);
    return t;
  }
  t.body += act(R"(
int @NAME@_act(const double* observation, double* action) {
  double error[4], velocity[4], attitude[2];
  int c;
  if (!all_finite(observation, 13)) {
    for (c = 0; c < 4; ++c) action[c] = kTrim[c];
    return 1;
  }
  hover_inputs(observation + 1, kTarget, 0, error, velocity, attitude, 0);
  hover_networks(kWeights, error, velocity, attitude, 0, action);
  for (c = 0; c < 4; ++c) action[c] = clip_control(action[c]);
  return 0;
}
)");
  return t;
}

namespace {

// The trajectory's legs and the set point along them, as heli/trajectory.cpp computes them.
constexpr const char* kTrajectory = R"(
enum { kLine = 0, kArc = 1, kTurn = 2, kHold = 3 };
struct leg {
  int kind, angled;
  double from[3], to[3], centre[3]; /* m, W */
  double sweep, yaw0;               /* rad */
  double length, peak, ramp_s, duration, t0;
};

/* Distance done after tau s into a leg (raised-cosine ramps, a cruise, the mirror ramp). */
static double leg_distance(const struct leg* l, double tau) {
  double v, ta;
  if (l->kind == kHold || l->length <= 0) return 0;
  tau = clamp(tau, 0.0, l->duration);
  v = l->peak;
  ta = l->ramp_s;
  if (tau <= ta) return v / 2 * (tau - ta / kPi * sin(kPi * tau / ta));
  if (tau >= l->duration - ta) {
    const double s = l->duration - tau;
    return l->length - v / 2 * (s - ta / kPi * sin(kPi * s / ta));
  }
  return v * ta / 2 + v * (tau - ta);
}

static double leg_speed(const struct leg* l, double tau) {
  const double v = l->peak, ta = l->ramp_s;
  if (l->kind == kHold || l->length <= 0 || tau <= 0 || tau >= l->duration) return 0;
  if (tau <= ta) return v / 2 * (1 - cos(kPi * tau / ta));
  if (tau >= l->duration - ta) return v / 2 * (1 - cos(kPi * (l->duration - tau) / ta));
  return v;
}

/* The set point tau s into a leg: p (m, W), yaw (unwrapped), v (m/s, W), yaw rate. */
static void leg_point(const struct leg* l, double tau, double* p, double* yaw, double* v, double* yaw_rate) {
  const double s = leg_distance(l, tau), ds = leg_speed(l, tau);
  int i;
  for (i = 0; i < 3; ++i) {
    p[i] = l->from[i];
    v[i] = 0;
  }
  *yaw = l->yaw0;
  *yaw_rate = 0;
  if (l->kind == kLine) {
    for (i = 0; i < 3; ++i) {
      const double dir = (l->to[i] - l->from[i]) / l->length;
      p[i] = l->from[i] + s * dir;
      v[i] = ds * dir;
    }
  } else if (l->kind == kArc) {
    const double r = hypot(l->from[0] - l->centre[0], l->from[1] - l->centre[1]);
    const double sign = l->sweep >= 0 ? 1.0 : -1.0;
    const double a = atan2(l->from[1] - l->centre[1], l->from[0] - l->centre[0]) + sign * s / r;
    const double speed = sign * ds;
    p[0] = l->centre[0] + r * cos(a);
    p[1] = l->centre[1] + r * sin(a);
    p[2] = l->from[2];
    v[0] = speed * -sin(a);
    v[1] = speed * cos(a);
    v[2] = speed * 0.0;
    *yaw = l->yaw0 + sign * s / r;
    *yaw_rate = sign * ds / r;
  } else if (l->kind == kTurn) {
    const double sign = l->sweep >= 0 ? 1.0 : -1.0;
    *yaw = l->yaw0 + sign * s;
    *yaw_rate = sign * ds;
  }
}

/* Trajectory::delayed: the ideal set point at t, except that on angled climbs and descents z* lags by the
 * learned delay (thesis §5.4). */
static void trajectory_point(double t, double z_delay, double* p, double* yaw, double* v, double* yaw_rate) {
  const double tc = clamp(t, 0.0, kDuration);
  int k = 0;
  double z, zdot;
  while (k + 1 < kLegCount && tc >= kLegs[k + 1].t0) ++k;
  leg_point(&kLegs[k], tc - kLegs[k].t0, p, yaw, v, yaw_rate);
  if (z_delay == 0) return;
  z = kLegs[0].from[2];
  zdot = 0;
  for (k = 0; k < kLegCount; ++k) {
    const struct leg* l = &kLegs[k];
    double tau, dz;
    if (l->kind != kLine) continue;
    tau = t - l->t0 - (l->angled ? z_delay : 0.0);
    dz = l->to[2] - l->from[2];
    z += dz * leg_distance(l, tau) / l->length;
    zdot += dz * leg_speed(l, tau) / l->length;
  }
  p[2] = z;
  v[2] = zdot;
}

int @NAME@_target(double time, double* set_point) {
  double p[3], yaw, v[3], yaw_rate;
  trajectory_point(time, kZDelay, p, &yaw, v, &yaw_rate);
  set_point[0] = p[0];
  set_point[1] = p[1];
  set_point[2] = p[2];
  set_point[3] = wrap_angle(yaw);
  return 0;
}

/* heli/maneuver_policy.cpp ManeuverPolicy::act. */
int @NAME@_act(const double* observation, double* action) {
  double p[3], yaw, v[3], yaw_rate, target[4], state[12], error[4], velocity[4], attitude[2];
  double tail, coll;
  int c;
  if (!all_finite(observation, 13)) {
    for (c = 0; c < 4; ++c) action[c] = kTrim[c];
    return 1;
  }
  trajectory_point(observation[0], kZDelay, p, &yaw, v, &yaw_rate);
  target[0] = p[0];
  target[1] = p[1];
  target[2] = p[2];
  target[3] = wrap_angle(yaw);
  for (c = 0; c < 12; ++c) state[c] = observation[1 + c];
  if (kFeedforward != 0) {
    state[6] -= kFeedforward * v[0];
    state[7] -= kFeedforward * v[1];
    state[8] -= kFeedforward * v[2];
    state[11] -= kFeedforward * yaw_rate;
  }
  hover_inputs(state, target, 0, error, velocity, attitude, 0);
  hover_networks(kWeights, error, velocity, attitude, 0, action);
  tail = action[3] - kTrim[3];
  coll = action[2] - kTrim[2];
  action[1] += kTailToLat * tail;
  action[3] += kCollToTail * coll;
  for (c = 0; c < 4; ++c) action[c] = clip_control(action[c]);
  return 0;
}
)";

const char* leg_kind(heli::TrajectoryLeg::Kind k) {
  using K = heli::TrajectoryLeg::Kind;
  switch (k) {
    case K::kLine:
      return "kLine";
    case K::kArc:
      return "kArc";
    case K::kTurn:
      return "kTurn";
    case K::kHold:
      return "kHold";
  }
  return "kHold";
}

}  // namespace

ClassText maneuver_c_text(const heli::PolicyFile& file, const std::string& source) {
  const heli::CheckedManeuverPolicy checked = heli::checked_maneuver_policy(file, source);
  const heli::ManeuverPolicy& policy = checked.policy;
  const Theta& theta = checked.theta;
  ClassText t =
      heli_class(file, std::vector<double>(theta.begin(), theta.begin() + heli::ManeuverPolicy::kHover));
  const heli::Trajectory& trajectory = policy.trajectory();
  t.description = heli_description(fmt::format(
      "The manoeuvre controller of thesis §5.4 (Fig 5.9) flying AMA Class III manoeuvre {} ({:.2f} s,\n"
      " * {} legs) from ({}, {}, {}) m: the hover networks fed a set point moving along the trajectory,\n"
      " * with the couplings of Fig 5.9; after the end it holds the end point.",
      comment_text(trajectory.name()), trajectory.duration(), trajectory.legs().size(), file.target.x,
      file.target.y, file.target.z));
  t.extra_declarations =
      "/* The set point at `time` (s since the manoeuvre began): x, y, z (m, W north-east-down), yaw (rad,\n"
      " * wrapped to (-pi, pi]). Returns 0. */\n"
      "int @NAME@_target(double time, double* set_point);\n";
  auto constant = [](const char* name, double value, const std::string& what) {
    return fmt::format("static const double {} = {}; /* {}: {} */\n", name, c_double(value), what, value);
  };
  t.body += constant("kTailToLat", theta[heli::ManeuverPolicy::kTailToLat], "couple.tail_to_lat");
  t.body += constant("kCollToTail", theta[heli::ManeuverPolicy::kCollToTail], "couple.coll_to_tail");
  t.body += constant("kZDelay", policy.z_delay(theta), "z_delay, s (0: not learned)");
  t.body += constant("kFeedforward", policy.feedforward(theta), "feedforward (0: not used)");
  t.body += constant("kDuration", trajectory.duration(), "trajectory duration, s");
  std::string legs;
  for (const auto& l : trajectory.legs()) {
    legs += fmt::format(
        "    {{{}, {}, {{{}, {}, {}}}, {{{}, {}, {}}}, {{{}, {}, {}}}, {}, {}, {}, {}, {}, {}, {}}},\n",
        leg_kind(l.kind), l.angled() ? 1 : 0, c_double(l.from_W.x()), c_double(l.from_W.y()),
        c_double(l.from_W.z()), c_double(l.to_W.x()), c_double(l.to_W.y()), c_double(l.to_W.z()),
        c_double(l.centre_W.x()), c_double(l.centre_W.y()), c_double(l.centre_W.z()), c_double(l.sweep),
        c_double(l.yaw0), c_double(l.length), c_double(l.peak), c_double(l.ramp_s), c_double(l.duration),
        c_double(l.t0));
  }
  // The struct must come before the table: split the trajectory text at its first function.
  const std::string trajectory_text = kTrajectory;
  const std::size_t functions = trajectory_text.find("/* Distance done");
  t.body += trajectory_text.substr(0, functions);
  t.body +=
      fmt::format("enum {{ kLegCount = {} }};\nstatic const struct leg kLegs[kLegCount] = {{\n{}}};\n\n",
                  trajectory.legs().size(), legs);
  // The manoeuvre's act ends as the hover's does, with the file's command limits where it has any.
  const heli::HoverPolicyInit& limits = policy.init();
  if (!limits.has_command_limits()) {
    t.body += trajectory_text.substr(functions);
    return t;
  }
  add_command_limits(limits, &t.body);
  t.body += with_command_limits(trajectory_text.substr(functions));
  return t;
}

}  // namespace pegasus::heli
