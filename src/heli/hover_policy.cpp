#include "pegasus/heli/hover_policy.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pegasus/core/error.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {
namespace {

constexpr std::array<const char*, 9> kFullNames = {"bias",          "err",         "err_tanh_gain",
                                                   "err_tanh_in",   "vel",         "att",
                                                   "out_tanh_gain", "out_tanh_in", "out_linear"};
constexpr std::array<const char*, 8> kNoAttNames = {"bias", "err",           "err_tanh_gain", "err_tanh_in",
                                                    "vel",  "out_tanh_gain", "out_tanh_in",   "out_linear"};

}  // namespace

std::span<const char* const> hover_weight_names(int channel) {
  if (channel < 2) return kFullNames;
  return kNoAttNames;
}

int HoverPolicy::index(int channel, Weight w) {
  const int base = kOffset[static_cast<std::size_t>(channel)];
  if (channel < 2 || w < kAtt) return base + w;
  if (w == kAtt) throw std::invalid_argument("hover policy: channels a3 and a4 have no attitude weight");
  return base + w - 1;
}

std::array<double, 4> ErrorIntegrator::advanced(const std::array<double, 4>& integral, const LoggedState& s,
                                                const SetPoint& t) const {
  const std::array<double, 4> e = {s[logged::x] - t.x, s[logged::y] - t.y, s[logged::z] - t.z,
                                   wrap_angle(s[logged::yaw] - t.yaw)};
  std::array<double, 4> next{};
  for (std::size_t i = 0; i < 4; ++i) {
    const double limit = i < 3 ? limit_position : limit_yaw;
    // A non-finite estimate adds nothing: one bad sample must not poison the rest of the flight.
    next[i] = std::isfinite(e[i]) ? std::clamp(integral[i] + dt * e[i], -limit, limit) : integral[i];
  }
  return next;
}

bool ErrorIntegrator::IsValid(std::string* error) const {
  const auto fail = [&](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (!(dt >= 0 && std::isfinite(dt))) return fail("dt: expected a finite number >= 0 (0: no integral term)");
  if (!(limit_position > 0 && std::isfinite(limit_position)))
    return fail("limit_position: expected a finite number > 0 (m s)");
  if (!(limit_yaw > 0 && std::isfinite(limit_yaw)))
    return fail("limit_yaw: expected a finite number > 0 (rad s)");
  return true;
}

HoverInputs hover_inputs(const HeliObservation& o) {
  const LoggedState& s = o.state;
  const Euler e = attitude_of(s);
  const Mat3 r_BW = rotation_world_from_body(e).transpose();
  const Vec3 err_B =
      r_BW * Vec3(s[logged::x] - o.target.x, s[logged::y] - o.target.y, s[logged::z] - o.target.z);
  const Vec3 v_B = r_BW * velocity_of(s);
  HoverInputs in;
  in.error = {err_B.x(), err_B.y(), err_B.z(), wrap_angle(s[logged::yaw] - o.target.yaw)};
  in.velocity = {v_B.x(), v_B.y(), v_B.z(), s[logged::yaw_rate]};
  in.attitude = {s[logged::pitch], s[logged::roll]};
  const auto& i_W = o.integral;
  if (i_W[0] != 0 || i_W[1] != 0 || i_W[2] != 0 || i_W[3] != 0) {  // a policy without the term skips this
    const Vec3 i_B = r_BW * Vec3(i_W[0], i_W[1], i_W[2]);
    in.integral = {i_B.x(), i_B.y(), i_B.z(), i_W[3]};
  }
  return in;
}

bool command_limits_valid(const Controls& lower, const Controls& upper, std::string* error) {
  for (std::size_t c = 0; c < 4; ++c)
    if (!(lower[c] >= -1 && lower[c] <= upper[c] && upper[c] <= 1)) {
      if (error)
        *error =
            fmt::format("a{}: expected -1 <= lower <= upper <= 1, got [{}, {}]", c + 1, lower[c], upper[c]);
      return false;
    }
  return true;
}

HoverPolicy::HoverPolicy(const HoverPolicyInit& init)
    : command_lower_(init.command_lower), command_upper_(init.command_upper) {
  std::string error;
  if (!command_limits_valid(command_lower_, command_upper_, &error))
    throw std::invalid_argument("hover policy: command limits: " + error);
  const double inf = std::numeric_limits<double>::infinity();
  // Per channel: initial linear gains, and the typical useful change of each weight (the optimizer's scale).
  struct Channel {
    double err, vel, att, att_trim;
    double err_scale, vel_scale;
  };
  const std::array<Channel, 4> ch = {
      Channel{init.k_pos, init.k_vel, init.k_att, init.trim_pitch, 0.02, 0.05},
      Channel{init.k_pos_lat, init.k_vel_lat, init.k_roll, init.trim_roll, 0.02, 0.05},
      Channel{init.k_alt, init.k_climb, 0, 0, 0.02, 0.05},
      Channel{init.k_yaw, init.k_yaw_rate, 0, 0, 0.1, 0.05},
  };
  for (std::size_t c = 0; c < 4; ++c) {
    const auto names = hover_weight_names(static_cast<int>(c));
    const std::string prefix = "a" + std::to_string(c + 1) + ".";
    for (const char* raw : names) {
      const std::string w = raw;
      Parameter p{.name = prefix + w};
      if (w == "bias") {
        // The attitude term is linear around the trim attitude: bias = trim control - att * trim angle.
        p.initial = std::clamp(init.trim[c] - ch[c].att * ch[c].att_trim, -1.0, 1.0);
        p.lower = -1, p.upper = 1, p.scale = 0.02;
      } else if (w == "err") {
        p.initial = ch[c].err, p.scale = ch[c].err_scale;
      } else if (w == "err_tanh_gain") {
        p.initial = 0, p.scale = ch[c].err_scale;
      } else if (w == "err_tanh_in" || w == "out_tanh_in") {
        p.initial = 1, p.lower = -20, p.upper = 20, p.scale = 0.5;
      } else if (w == "vel") {
        p.initial = ch[c].vel, p.scale = ch[c].vel_scale;
      } else if (w == "att") {
        p.initial = ch[c].att, p.scale = 0.2;
      } else if (w == "out_tanh_gain") {
        p.initial = 0, p.scale = 0.05;
      } else {  // out_linear
        p.initial = 1, p.lower = -inf, p.upper = inf, p.scale = 0.1;
      }
      spec_.add(std::move(p));
    }
  }
  if (init.integral_seconds > 0) {
    // Scale: the change of int that moves the channel as much as err's scale does after 5 s of error.
    for (std::size_t c = 0; c < 4; ++c)
      spec_.add({.name = "a" + std::to_string(c + 1) + ".int",
                 .initial = ch[c].err / init.integral_seconds,
                 .scale = ch[c].err_scale / 5});
  }
}

Controls HoverPolicy::unclipped(std::span<const double> w, const HoverInputs& in) {
  Controls a;
  const bool integral = w.size() >= static_cast<std::size_t>(kParameters + kIntegralParameters);
  for (std::size_t c = 0; c < 4; ++c) {
    const double* k = w.data() + kOffset[c];
    const double e = in.error[c];
    double t =
        k[kBias] + k[kErr] * e + k[kErrTanhGain] * std::tanh(k[kErrTanhIn] * e) + k[kVel] * in.velocity[c];
    if (c < 2) {
      t += k[kAtt] * in.attitude[c];
    } else {
      --k;  // no attitude weight: the out_* weights sit one place earlier
    }
    if (integral) t += w[static_cast<std::size_t>(kParameters) + c] * in.integral[c];
    a[c] = k[kOutTanhGain] * std::tanh(k[kOutTanhIn] * t) + k[kOutLinear] * t;
  }
  return a;
}

std::string command_limits_line(const HoverPolicyInit& limits, double margin) {
  std::string channels;
  for (std::size_t c = 0; c < 4; ++c)
    channels += fmt::format("{}a{} [{:.3g}, {:.3g}]", c == 0 ? "" : ", ", c + 1, limits.command_lower[c],
                            limits.command_upper[c]);
  return fmt::format(
      "command limits (the global linear model extrapolates beyond its logs): the logs' controls widened by "
      "{:g}% "
      "of their range per side, {} (--command-margin)",
      100 * margin, channels);
}

Controls HoverPolicy::act(std::span<const double> theta, const HeliObservation& o) const {
  return clip_command(unclipped(theta, hover_inputs(o)), command_lower_, command_upper_);
}

}  // namespace pegasus::heli
