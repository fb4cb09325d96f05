#pragma once
// The "external observer" of thesis §5.4: it looks at the helicopter's actual position and heading and
// decides which part of the ideal path the helicopter is flying through, giving the projection (x_p, y_p,
// z_p, omega_p) the manoeuvre reward penalises deviation from, and the progress along the path the shaping
// potential grows with.
//
// The path is the trajectory's legs as a dense polyline in (x, y, z, yaw_length * yaw): pirouettes are
// progress too (a pirouette does not move the position), and holds add nothing. Progress is the arc length of
// that polyline (m, a pirouette counting yaw_length m per rad). The observer keeps the last progress and
// searches only the part of the path from there to `window` m further for the nearest point; progress
// therefore never goes back, and where the path passes the same place twice (III.2 flies out along a radius
// and back along it, and ends its circle where it began; III.3 ends where it began) the observer is not
// fooled into jumping to the other pass: that lies more than a window ahead or behind.
//
// Yaw distances wrap (the measured yaw is in (-pi, pi], the path's yaw is unwrapped).
#include <vector>

#include "pegasus/heli/trajectory.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {

struct PathObserverOptions {
  double yaw_length = 1.0;  // m of path per rad of yaw (pirouettes), and the yaw weight of the projection
  double window = 4.0;      // m of path searched ahead of the last progress
  double spacing = 0.1;     // m between polyline vertices (arcs: chord error spacing^2 / (8 R))
  bool IsValid(std::string* error) const;
};

// Where on the path the observer puts the helicopter.
struct PathProjection {
  double progress = 0;      // m along the path (monotone)
  int segment = 0;          // polyline segment holding it
  Vec3 p_W = Vec3::Zero();  // the projected position
  double yaw = 0;           // the projected yaw (unwrapped)
  Vec3 v_W = Vec3::Zero();  // the ideal set-point velocity there
  double time = 0;          // the ideal time there (when the ideal set point passes this point)
};

class PathObserver {
 public:
  PathObserver(const Trajectory& trajectory, PathObserverOptions options = {});

  // The start of the path.
  PathProjection start() const;
  // The nearest point of the path to (p_W, yaw) at or ahead of `last` and within the window.
  PathProjection update(const PathProjection& last, const Vec3& p_W, double yaw) const;
  // The squared distance in the observer's metric: |p - p_path|^2 + (yaw_length * wrap(yaw - yaw_path))^2.
  double distance2(const Vec3& p_W, double yaw, const PathProjection& on_path) const;

  double length() const { return vertices_.back().progress; }
  const PathObserverOptions& options() const { return options_; }
  int segments() const { return static_cast<int>(vertices_.size()) - 1; }

  struct Vertex {
    Vec3 p_W;
    double yaw;       // unwrapped
    double progress;  // m
    double time;      // ideal time, s
    Vec3 v_W;         // ideal velocity, m/s
  };
  const std::vector<Vertex>& vertices() const { return vertices_; }

 private:
  PathProjection point_on(int segment, double u) const;
  PathObserverOptions options_;
  std::vector<Vertex> vertices_;
};

}  // namespace pegasus::heli
