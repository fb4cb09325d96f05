#include "pegasus/heli/trajectory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "../core/validation.hpp"
#include "pegasus/core/error.hpp"

namespace pegasus::heli {
namespace {

constexpr double kPi = std::numbers::pi;

using detail::fail;
using detail::positive_finite;

// Builds a manoeuvre leg by leg, keeping track of where the previous leg ended.
class LegBuilder {
 public:
  LegBuilder(Vec3 start_W, double yaw) : p_(std::move(start_W)), yaw_(yaw) {}
  void hold(double seconds) {
    if (seconds <= 0) return;
    TrajectoryLeg l{
        .kind = TrajectoryLeg::Kind::kHold, .from_W = p_, .to_W = p_, .yaw0 = yaw_, .hold_s = seconds};
    legs_.push_back(l);
  }
  void line_to(const Vec3& to_W) {
    TrajectoryLeg l{.kind = TrajectoryLeg::Kind::kLine, .from_W = p_, .to_W = to_W, .yaw0 = yaw_};
    legs_.push_back(l);
    p_ = to_W;
  }
  void turn(double angle) {
    TrajectoryLeg l{
        .kind = TrajectoryLeg::Kind::kTurn, .from_W = p_, .to_W = p_, .sweep = angle, .yaw0 = yaw_};
    legs_.push_back(l);
    yaw_ += angle;
  }
  void arc(const Vec3& centre_W, double sweep) {
    TrajectoryLeg l{
        .kind = TrajectoryLeg::Kind::kArc, .from_W = p_, .centre_W = centre_W, .sweep = sweep, .yaw0 = yaw_};
    const double a = std::atan2(p_.y() - centre_W.y(), p_.x() - centre_W.x()) + sweep;
    const double r = std::hypot(p_.x() - centre_W.x(), p_.y() - centre_W.y());
    p_ = Vec3(centre_W.x() + r * std::cos(a), centre_W.y() + r * std::sin(a), p_.z());
    l.to_W = p_;
    legs_.push_back(l);
    yaw_ += sweep;
  }
  std::vector<TrajectoryLeg> take() { return std::move(legs_); }

 private:
  Vec3 p_;
  double yaw_;
  std::vector<TrajectoryLeg> legs_;
};

}  // namespace

bool TrajectoryLimits::IsValid(std::string* error) const {
  if (!positive_finite(speed) || speed > 20)
    return fail(error, fmt::format("speed: expected a number in (0, 20] m/s, got {}", speed));
  if (!positive_finite(accel) || accel > 20)
    return fail(error, fmt::format("accel: expected a number in (0, 20] m/s^2, got {}", accel));
  if (!positive_finite(yaw_rate) || yaw_rate > 10)
    return fail(error, fmt::format("yaw_rate: expected a number in (0, 10] rad/s, got {}", yaw_rate));
  if (!positive_finite(yaw_accel) || yaw_accel > 20)
    return fail(error, fmt::format("yaw_accel: expected a number in (0, 20] rad/s^2, got {}", yaw_accel));
  return true;
}

bool ManeuverSize::IsValid(std::string* error) const {
  if (!start_W.allFinite() || start_W.z() >= 0)
    return fail(error, "start: expected a finite point above the ground (z < 0)");
  if (!positive_finite(triangle_base) || triangle_base > 200)
    return fail(error, fmt::format("triangle_base: expected a number in (0, 200] m, got {}", triangle_base));
  if (!positive_finite(circle_radius) || circle_radius > 100)
    return fail(error, fmt::format("circle_radius: expected a number in (0, 100] m, got {}", circle_radius));
  if (!(pause_s >= 0 && pause_s <= 60))
    return fail(error, fmt::format("pause_s: expected a number in [0, 60] s, got {}", pause_s));
  if (!positive_finite(rectangle_width) || rectangle_width > 200)
    return fail(error,
                fmt::format("rectangle_width: expected a number in (0, 200] m, got {}", rectangle_width));
  if (!positive_finite(rectangle_height) || rectangle_height > 100)
    return fail(error,
                fmt::format("rectangle_height: expected a number in (0, 100] m, got {}", rectangle_height));
  if (!positive_finite(figure_eight_radius) || figure_eight_radius > 100)
    return fail(error, fmt::format("figure_eight_radius: expected a number in (0, 100] m, got {}",
                                   figure_eight_radius));
  if (!(hold_start_s >= 0 && hold_start_s <= 60))
    return fail(error, fmt::format("hold_start_s: expected a number in [0, 60] s, got {}", hold_start_s));
  if (!(hold_end_s >= 0 && hold_end_s <= 60))
    return fail(error, fmt::format("hold_end_s: expected a number in [0, 60] s, got {}", hold_end_s));
  return true;
}

bool TrajectoryLeg::angled() const {
  if (kind != Kind::kLine) return false;
  const Vec3 d = to_W - from_W;
  return std::hypot(d.x(), d.y()) > 1e-9 && std::abs(d.z()) > 1e-9;
}

Trajectory::Trajectory(std::string name, std::vector<TrajectoryLeg> legs, TrajectoryLimits limits)
    : name_(std::move(name)), limits_(limits) {
  std::string error;
  if (!limits_.IsValid(&error)) throw InputError("trajectory limits: " + error);
  double t = 0;
  for (auto& leg : legs) {
    using K = TrajectoryLeg::Kind;
    double v = limits_.speed, a = limits_.accel;
    switch (leg.kind) {
      case K::kLine:
        leg.length = (leg.to_W - leg.from_W).norm();
        break;
      case K::kArc: {
        const double r = std::hypot(leg.from_W.x() - leg.centre_W.x(), leg.from_W.y() - leg.centre_W.y());
        leg.length = std::abs(leg.sweep) * r;
        // The nose turns with the set point: no faster than the pirouette limits let it.
        v = std::min(v, limits_.yaw_rate * r);
        a = std::min(a, limits_.yaw_accel * r);
        break;
      }
      case K::kTurn:
        leg.length = std::abs(leg.sweep);
        v = limits_.yaw_rate;
        a = limits_.yaw_accel;
        break;
      case K::kHold:
        leg.length = 0;
        break;
    }
    if (leg.kind == K::kHold) {
      leg.duration = leg.hold_s;
    } else {
      if (leg.length <= 1e-12) continue;  // nothing to fly
      // Raised-cosine ramps: ramp distance pi v^2 / (4 a) each; lower the peak when the leg is too short.
      leg.peak = std::min(v, std::sqrt(2 * a * leg.length / kPi));
      leg.ramp_s = kPi * leg.peak / (2 * a);
      const double ramp_distance = leg.peak * leg.ramp_s / 2;
      leg.duration = 2 * leg.ramp_s + std::max(0.0, leg.length - 2 * ramp_distance) / leg.peak;
    }
    leg.t0 = t;
    t += leg.duration;
    legs_.push_back(leg);
  }
  if (legs_.empty()) throw InputError("trajectory " + name_ + ": expected at least one leg");
  duration_ = t;
}

double Trajectory::leg_distance(const TrajectoryLeg& leg, double tau) const {
  if (leg.kind == TrajectoryLeg::Kind::kHold || leg.length <= 0) return 0;
  tau = std::clamp(tau, 0.0, leg.duration);
  const double v = leg.peak, ta = leg.ramp_s;
  auto ramp = [&](double s) { return v / 2 * (s - ta / kPi * std::sin(kPi * s / ta)); };
  if (tau <= ta) return ramp(tau);
  if (tau >= leg.duration - ta) return leg.length - ramp(leg.duration - tau);
  return v * ta / 2 + v * (tau - ta);
}

double Trajectory::leg_speed(const TrajectoryLeg& leg, double tau) const {
  if (leg.kind == TrajectoryLeg::Kind::kHold || leg.length <= 0 || tau <= 0 || tau >= leg.duration) return 0;
  const double v = leg.peak, ta = leg.ramp_s;
  if (tau <= ta) return v / 2 * (1 - std::cos(kPi * tau / ta));
  if (tau >= leg.duration - ta) return v / 2 * (1 - std::cos(kPi * (leg.duration - tau) / ta));
  return v;
}

TrajectoryPoint Trajectory::leg_point(const TrajectoryLeg& leg, double tau) const {
  using K = TrajectoryLeg::Kind;
  TrajectoryPoint sp;
  sp.p_W = leg.from_W;
  sp.yaw = leg.yaw0;
  const double s = leg_distance(leg, tau), ds = leg_speed(leg, tau);
  switch (leg.kind) {
    case K::kLine: {
      const Vec3 dir = (leg.to_W - leg.from_W) / leg.length;
      sp.p_W = leg.from_W + s * dir;
      sp.v_W = ds * dir;
      break;
    }
    case K::kArc: {
      const double r = std::hypot(leg.from_W.x() - leg.centre_W.x(), leg.from_W.y() - leg.centre_W.y());
      const double sign = leg.sweep >= 0 ? 1.0 : -1.0;
      const double a =
          std::atan2(leg.from_W.y() - leg.centre_W.y(), leg.from_W.x() - leg.centre_W.x()) + sign * s / r;
      sp.p_W = Vec3(leg.centre_W.x() + r * std::cos(a), leg.centre_W.y() + r * std::sin(a), leg.from_W.z());
      sp.v_W = sign * ds * Vec3(-std::sin(a), std::cos(a), 0.0);
      sp.yaw = leg.yaw0 + sign * s / r;
      sp.yaw_rate = sign * ds / r;
      break;
    }
    case K::kTurn: {
      const double sign = leg.sweep >= 0 ? 1.0 : -1.0;
      sp.yaw = leg.yaw0 + sign * s;
      sp.yaw_rate = sign * ds;
      break;
    }
    case K::kHold:
      break;
  }
  return sp;
}

std::size_t Trajectory::leg_index(double t) const {
  std::size_t k = 0;
  while (k + 1 < legs_.size() && t >= legs_[k + 1].t0) ++k;
  return k;
}

TrajectoryPoint Trajectory::at(double t) const {
  t = std::clamp(t, 0.0, duration_);
  const std::size_t k = leg_index(t);
  return leg_point(legs_[k], t - legs_[k].t0);
}

TrajectoryPoint Trajectory::delayed(double t, double z_delay_s) const {
  TrajectoryPoint sp = at(t);
  if (z_delay_s == 0) return sp;
  // z*(t) = z(0) + sum of each line's z change at its own (possibly delayed) time.
  double z = legs_.front().from_W.z(), zdot = 0;
  for (const auto& leg : legs_) {
    if (leg.kind != TrajectoryLeg::Kind::kLine) continue;
    const double tau = t - leg.t0 - (leg.angled() ? z_delay_s : 0.0);
    const double dz = leg.to_W.z() - leg.from_W.z();
    z += dz * leg_distance(leg, tau) / leg.length;
    zdot += dz * leg_speed(leg, tau) / leg.length;
  }
  sp.p_W.z() = z;
  sp.v_W.z() = zdot;
  return sp;
}

std::vector<std::array<double, 5>> Trajectory::sample(double dt_s) const {
  if (!positive_finite(dt_s)) throw InputError("trajectory sample: expected a step > 0");
  std::vector<std::array<double, 5>> rows;
  const auto n = static_cast<std::size_t>(std::floor(duration_ / dt_s + 1e-9));
  rows.reserve(n + 2);
  for (std::size_t i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) * dt_s;
    const TrajectoryPoint sp = at(t);
    rows.push_back({t, sp.p_W.x(), sp.p_W.y(), sp.p_W.z(), sp.yaw});
  }
  return rows;
}

std::string maneuver_name_list() {
  std::string list;
  for (std::size_t i = 0; i < kManeuverNames.size(); ++i)
    list += (i == 0 ? "" : i + 1 == kManeuverNames.size() ? " or " : ", ") + std::string(kManeuverNames[i]);
  return list;
}

Trajectory maneuver_trajectory(std::string_view name, const ManeuverSize& size,
                               const TrajectoryLimits& limits) {
  std::string error;
  if (!size.IsValid(&error)) throw InputError("manoeuvre size: " + error);
  const Vec3 o = size.start_W;
  LegBuilder b(o, 0.0);
  b.hold(size.hold_start_s);
  if (name == "III.1") {
    // Vertical triangle in the x-z plane; nose north, every edge flown backwards.
    const double h = size.triangle_base / 2;
    const Vec3 south = o + Vec3(-h, 0, 0), north = o + Vec3(h, 0, 0), apex = o + Vec3(0, 0, -h);
    b.line_to(south);
    b.turn(kPi);  // nose south
    b.line_to(apex);
    b.line_to(north);
    b.turn(kPi);  // nose north again
    b.line_to(o);
  } else if (name == "III.2") {
    // Nose-in circle: out backwards to the circle, pause, circle with the nose on the centre, forwards home.
    const Vec3 rim = o + Vec3(-size.circle_radius, 0, 0);
    b.line_to(rim);
    b.hold(size.pause_s);
    b.arc(o, 2 * kPi);
    b.line_to(o);
  } else if (name == "III.3") {
    // Vertical rectangle in the x-z plane with opposite pirouettes halfway up and down the vertical sides.
    const double w = size.rectangle_width / 2, hh = size.rectangle_height;
    b.line_to(o + Vec3(w, 0, 0));
    b.line_to(o + Vec3(w, 0, -hh / 2));
    b.turn(2 * kPi);
    b.line_to(o + Vec3(w, 0, -hh));
    b.line_to(o + Vec3(-w, 0, -hh));
    b.line_to(o + Vec3(-w, 0, -hh / 2));
    b.turn(-2 * kPi);
    b.line_to(o + Vec3(-w, 0, 0));
    b.line_to(o);
  } else if (name == "figure8") {
    // Two nose-in circles touching at the start, flown in opposite senses with a pirouette between them.
    const double r = size.figure_eight_radius;
    b.arc(o + Vec3(r, 0, 0), 2 * kPi);
    b.turn(kPi);  // nose on the southern centre
    b.arc(o + Vec3(-r, 0, 0), -2 * kPi);
    b.turn(-kPi);  // nose north again
  } else {
    throw InputError(fmt::format("manoeuvre name: expected {}, got \"{}\"", maneuver_name_list(), name));
  }
  b.hold(size.hold_end_s);
  return Trajectory(std::string(name), b.take(), limits);
}

}  // namespace pegasus::heli
