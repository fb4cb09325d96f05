#include "pegasus/heli/path_observer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "pegasus/core/error.hpp"

namespace pegasus::heli {

bool PathObserverOptions::IsValid(std::string* error) const {
  auto bad = [&](const char* field, double v, const char* expected) {
    if (error) *error = fmt::format("{}: expected {}, got {}", field, expected, v);
    return false;
  };
  if (!(std::isfinite(yaw_length) && yaw_length > 0))
    return bad("yaw_length", yaw_length, "a number > 0 (m per rad)");
  if (!(std::isfinite(spacing) && spacing > 0 && spacing <= 1))
    return bad("spacing", spacing, "a number in (0, 1] m");
  if (!(std::isfinite(window) && window >= 2 * spacing))
    return bad("window", window, "a number of m >= 2 spacing");
  return true;
}

PathObserver::PathObserver(const Trajectory& trajectory, PathObserverOptions options) : options_(options) {
  std::string error;
  if (!options_.IsValid(&error)) throw InputError("path observer: " + error);
  const double yl = options_.yaw_length;
  auto add = [&](double t, bool force) {
    const TrajectoryPoint sp = trajectory.at(t);
    if (!vertices_.empty()) {
      const Vertex& last = vertices_.back();
      const double d =
          std::sqrt((sp.p_W - last.p_W).squaredNorm() + yl * yl * (sp.yaw - last.yaw) * (sp.yaw - last.yaw));
      if (d < 1e-9 || (!force && d < options_.spacing)) return;
      vertices_.push_back({sp.p_W, sp.yaw, last.progress + d, t, sp.v_W});
    } else {
      vertices_.push_back({sp.p_W, sp.yaw, 0.0, t, sp.v_W});
    }
  };
  // Fine steps in time; a vertex whenever the set point has moved `spacing` since the last, and at every
  // leg's end so that corners are vertices.
  constexpr double kDt = 0.005;
  add(0.0, true);
  for (const auto& leg : trajectory.legs()) {
    const double end = leg.t0 + leg.duration;
    for (double t = leg.t0 + kDt; t < end - 1e-12; t += kDt) add(t, false);
    add(end, true);
  }
  if (vertices_.size() < 2) {  // a path that never moves: one zero-length segment
    vertices_.push_back(vertices_.back());
  }
}

PathProjection PathObserver::point_on(int segment, double u) const {
  const Vertex& a = vertices_[static_cast<std::size_t>(segment)];
  const Vertex& b = vertices_[static_cast<std::size_t>(segment) + 1];
  PathProjection p;
  p.segment = segment;
  p.progress = a.progress + u * (b.progress - a.progress);
  p.p_W = a.p_W + u * (b.p_W - a.p_W);
  p.yaw = a.yaw + u * (b.yaw - a.yaw);
  p.v_W = a.v_W + u * (b.v_W - a.v_W);
  p.time = a.time + u * (b.time - a.time);
  return p;
}

PathProjection PathObserver::start() const { return point_on(0, 0.0); }

double PathObserver::distance2(const Vec3& p_W, double yaw, const PathProjection& on_path) const {
  const double e = options_.yaw_length * wrap_angle(yaw - on_path.yaw);
  return (p_W - on_path.p_W).squaredNorm() + e * e;
}

PathProjection PathObserver::update(const PathProjection& last, const Vec3& p_W, double yaw) const {
  const double yl = options_.yaw_length, limit = last.progress + options_.window;
  const int n = segments();
  PathProjection best = last;
  double best_d2 = distance2(p_W, yaw, last);
  for (int j = last.segment; j < n && vertices_[static_cast<std::size_t>(j)].progress <= limit; ++j) {
    const Vertex& a = vertices_[static_cast<std::size_t>(j)];
    const Vertex& b = vertices_[static_cast<std::size_t>(j) + 1];
    const Vec3 dp = b.p_W - a.p_W;
    const double dyaw = yl * (b.yaw - a.yaw);
    const double len2 = dp.squaredNorm() + dyaw * dyaw;
    // The measured yaw unwrapped next to the vertex's, so the projection on a pirouette sees the short way.
    const double qyaw = yl * wrap_angle(yaw - a.yaw);
    double u = len2 > 0 ? ((p_W - a.p_W).dot(dp) + qyaw * dyaw) / len2 : 0.0;
    const double lo = j == last.segment && b.progress > a.progress
                          ? (last.progress - a.progress) / (b.progress - a.progress)
                          : 0.0;
    double hi = 1.0;
    if (b.progress > limit) hi = std::max(lo, (limit - a.progress) / (b.progress - a.progress));
    u = std::clamp(u, lo, hi);
    const PathProjection candidate = point_on(j, u);
    const double d2 = distance2(p_W, yaw, candidate);
    if (d2 < best_d2) {
      best_d2 = d2;
      best = candidate;
    }
  }
  return best;
}

}  // namespace pegasus::heli
