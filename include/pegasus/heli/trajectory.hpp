#pragma once
// Trajectories of the AMA Class III competition manoeuvres (thesis §5.4, Fig 5.8) and the set point that
// moves along them: "(x*, y*, z*, omega*) accelerate smoothly along the desired trajectory up to the speed
// limit, and decelerate smoothly at the end".
//
// A trajectory is a list of legs, each flown from rest to rest (corners and pirouettes are flown stopped, as
// a pilot flies them in competition):
//   line      straight from one point to another, yaw held (or the nose on a centre, for III.2's approach)
//   arc       part of a horizontal circle at constant height, the nose on the centre (III.2, "nose-in")
//   turn      a pirouette: yaw changes by a signed angle, position held
//   hold      hover in place for a while (the start, III.2's pause, the end)
// Along a leg of length L (m, or rad for a turn) the set point's speed follows a raised-cosine ramp up to the
// speed limit v, a cruise, and the mirror ramp down: speed(tau) = v/2 (1 - cos(pi tau / T_a)) with
// T_a = pi v / (2 a_max), so the acceleration a_max sin(pi tau / T_a) is continuous and never above a_max. A
// leg too short to reach v peaks at sqrt(2 a_max L / pi).
//
// Frames and units (frames.hpp): world frame W, north-east-down (altitude = -z), metres, seconds; yaw in
// radians, unwrapped along the trajectory (a 360 degree pirouette ends 2 pi from where it began; wrap with
// wrap_angle() when comparing with a measured yaw).
//
// The manoeuvres as flown here (sizes a Class III pilot flies: a 20 m triangle base, a 10 m circle radius, a
// 20 m x 10 m rectangle; speed limit 2.5 m/s, acceleration limit 1 m/s^2, pirouettes at up to 1 rad/s and
// 1 rad/s^2; ManeuverSize and TrajectoryLimits hold every number):
//   III.1  start in hover at the middle of the base of a vertical triangle (base 20 m along x, apex 10 m
//   above
//          the base), nose north (yaw 0); fly backwards 10 m to the south corner; 180 degree pirouette; fly
//          backwards up the first edge to the apex and down the second edge (45 degree climb and descent) to
//          the north corner; 180 degree pirouette (same sense, nose north again); fly backwards to the start.
//   III.2  start at the centre of a horizontal circle of radius 10 m, nose north; fly backwards 10 m south to
//   the
//          circle; pause 2 s; fly the full circle clockwise seen from above (westwards first), the nose
//          always on the centre (yaw turns by 2 pi); stop where the circle began; fly forwards back to the
//          centre.
//   III.3  start at the middle of the bottom edge of a vertical rectangle (20 m along x, 10 m high), nose
//   north;
//          fly forwards 10 m to the north corner; climb 5 m; 360 degree pirouette clockwise (yaw +2 pi);
//          climb 5 m; fly backwards 20 m along the top edge; descend 5 m; 360 degree pirouette
//          counter-clockwise (yaw back by 2 pi); descend 5 m; fly forwards 10 m back to the start.
//   figure8  a horizontal figure-eight for small aircraft (the quadrotor's trajectory; not an AMA manoeuvre):
//          two circles of radius figure_eight_radius that touch at the start, north and south of it. Nose
//          north on the northern circle's centre; fly it clockwise (yaw +2 pi, the nose on its centre), stop
//          at the start, pirouette 180 degrees to face the southern centre, fly that circle
//          counter-clockwise (yaw -2 pi), stop at the start, pirouette back to nose north.
//   Arcs are flown no faster than the pirouette limits let the nose follow: speed <= yaw_rate * radius,
//   acceleration <= yaw_accel * radius (no limit for III.2's 10 m circle at the default limits).
//   Each begins with a 1 s hover and ends with a hover (hold_end_s).
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {

struct TrajectoryLimits {
  double speed = 2.5;      // m/s, set-point speed limit along lines and arcs
  double accel = 1.0;      // m/s^2, set-point acceleration limit along lines and arcs
  double yaw_rate = 1.0;   // rad/s, pirouette rate limit
  double yaw_accel = 1.0;  // rad/s^2, pirouette acceleration limit
  bool IsValid(std::string* error) const;
};

struct TrajectoryLeg {
  enum class Kind { kLine, kArc, kTurn, kHold };
  Kind kind = Kind::kHold;
  Vec3 from_W = Vec3::Zero(), to_W = Vec3::Zero();  // line: end points; others: from_W is the place
  Vec3 centre_W = Vec3::Zero();                     // arc: centre (same height as from_W)
  double sweep = 0;   // arc: angle swept about the centre, rad (+: clockwise seen from above, i.e. N to E)
                      // turn: yaw change, rad (+: clockwise seen from above)
  double yaw0 = 0;    // yaw at the start of the leg (unwrapped)
  double hold_s = 0;  // hold: duration
  // Filled by Trajectory: length (m, or rad for a turn), speed peak, ramp time, duration, start time.
  double length = 0, peak = 0, ramp_s = 0, duration = 0, t0 = 0;
  bool angled() const;  // a line with both a horizontal and a vertical component (where the z delay applies)
};

// The set point at one time: position (W), yaw (unwrapped), and their rates.
struct TrajectoryPoint {
  Vec3 p_W = Vec3::Zero();
  double yaw = 0;
  Vec3 v_W = Vec3::Zero();
  double yaw_rate = 0;
};

class Trajectory {
 public:
  Trajectory(std::string name, std::vector<TrajectoryLeg> legs, TrajectoryLimits limits);
  const std::string& name() const { return name_; }
  const std::vector<TrajectoryLeg>& legs() const { return legs_; }
  const TrajectoryLimits& limits() const { return limits_; }
  double duration() const { return duration_; }
  Vec3 start_W() const { return legs_.front().from_W; }
  double start_yaw() const { return legs_.front().yaw0; }

  // The ideal set point at time t (clamped to [0, duration]).
  TrajectoryPoint at(double t) const;
  // The set point flown by the policy: the ideal one, except that along angled climbs and descents the
  // changes of z* are delayed by z_delay_s (thesis §5.4, the learned delay t): z*(t) = z(0) + sum over legs
  // of the leg's z change at time t - d_leg, with d_leg = z_delay_s on angled legs and 0 elsewhere.
  // Continuous in t.
  TrajectoryPoint delayed(double t, double z_delay_s) const;

  // The ideal path sampled every dt_s from 0 to duration (rows t, x, y, z, yaw) for ideal_path.csv.
  std::vector<std::array<double, 5>> sample(double dt_s) const;

 private:
  double leg_distance(const TrajectoryLeg& leg, double tau) const;  // distance done after tau s into the leg
  double leg_speed(const TrajectoryLeg& leg, double tau) const;
  TrajectoryPoint leg_point(const TrajectoryLeg& leg, double tau) const;
  std::size_t leg_index(double t) const;

  std::string name_;
  std::vector<TrajectoryLeg> legs_;
  TrajectoryLimits limits_;
  double duration_ = 0;
};

// Sizes of the manoeuvres (documented defaults above).
struct ManeuverSize {
  Vec3 start_W{0.0, 0.0, -10.0};   // the start hover, 10 m above the ground
  double triangle_base = 20;       // III.1, m (apex at half the base above it: 45 degree edges)
  double circle_radius = 10;       // III.2, m
  double pause_s = 2;              // III.2: pause on the circle before circling, s
  double rectangle_width = 20;     // III.3, m
  double rectangle_height = 10;    // III.3, m
  double figure_eight_radius = 1;  // figure8: radius of each circle, m
  double hold_start_s = 1;         // hover before the first leg, s
  double hold_end_s = 3;           // hover after the last leg, s
  bool IsValid(std::string* error) const;
};

inline constexpr std::array<std::string_view, 4> kManeuverNames = {"III.1", "III.2", "III.3", "figure8"};
// The AMA Class III manoeuvres of thesis 5.4 (kManeuverNames' first three).
inline constexpr std::array<std::string_view, 3> kClassThreeManeuvers = {"III.1", "III.2", "III.3"};
// "III.1, III.2, III.3 or figure8", for messages.
std::string maneuver_name_list();
// The trajectory of a manoeuvre by name (kManeuverNames); InputError for another name.
Trajectory maneuver_trajectory(std::string_view name, const ManeuverSize& size = {},
                               const TrajectoryLimits& limits = {});

}  // namespace pegasus::heli
