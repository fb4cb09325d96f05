// Manoeuvre trajectories (thesis §5.4, Fig 5.8) and the path observer: sizes, speed and acceleration limits,
// smoothness, the geometry each manoeuvre promises, exact projection of points on the path, monotone
// progress, and the loop-back of III.2.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/path_observer.hpp"
#include "pegasus/heli/trajectory.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::heli;
constexpr double kPi = std::numbers::pi;

// Length of the position path, summed from fine samples.
double position_length(const Trajectory& t) {
  double len = 0;
  Vec3 last = t.at(0).p_W;
  for (double s = 0.001; s <= t.duration() + 1e-9; s += 0.001) {
    const Vec3 p = t.at(s).p_W;
    len += (p - last).norm();
    last = p;
  }
  return len;
}

class EveryManeuver : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryManeuver, RespectsSpeedAccelerationAndYawRateLimits) {
  const TrajectoryLimits limits;
  const Trajectory t = maneuver_trajectory(GetParam());
  constexpr double dt = 0.005;
  Vec3 v_prev = t.at(0).v_W, a_prev = Vec3::Zero();
  double max_speed = 0, max_accel = 0, max_yaw_rate = 0, max_jerk_step = 0;
  for (double s = dt; s <= t.duration(); s += dt) {
    const TrajectoryPoint a = t.at(s - dt), b = t.at(s);
    // The analytic velocity is the derivative of the position (central difference at the midpoint).
    const Vec3 fd = (b.p_W - a.p_W) / dt;
    EXPECT_LT((fd - t.at(s - dt / 2).v_W).norm(), 1e-3) << "t = " << s;
    max_speed = std::max(max_speed, b.v_W.norm());
    max_yaw_rate = std::max(max_yaw_rate, std::abs(b.yaw_rate));
    const Vec3 accel = (b.v_W - v_prev) / dt;
    max_accel = std::max(max_accel, std::abs(b.v_W.norm() - v_prev.norm()) / dt);  // along the path
    max_jerk_step = std::max(max_jerk_step, (accel - a_prev).norm());
    v_prev = b.v_W;
    a_prev = accel;
  }
  EXPECT_LE(max_speed, limits.speed + 1e-9);
  // Every manoeuvre reaches the speed limit somewhere (the figure-eight's 1 m circles: the nose's limit).
  const double peak = GetParam() == "figure8" ? std::min(limits.speed, limits.yaw_rate * 1.0) : limits.speed;
  EXPECT_GT(max_speed, 0.99 * peak);
  EXPECT_LE(max_accel, limits.accel * 1.01);
  EXPECT_LE(max_yaw_rate, limits.yaw_rate + 1e-9);
  // Smooth: the acceleration changes little from one 5 ms step to the next (no jumps at leg boundaries).
  EXPECT_LT(max_jerk_step, 0.05);
  // Starts and ends at rest.
  EXPECT_LT(t.at(0).v_W.norm(), 1e-12);
  EXPECT_LT(t.at(t.duration()).v_W.norm(), 1e-12);
}

TEST_P(EveryManeuver, EndsAtTheStartWithTheNoseNorth) {
  const Trajectory t = maneuver_trajectory(GetParam());
  EXPECT_LT((t.at(t.duration()).p_W - t.start_W()).norm(), 1e-9);
  EXPECT_NEAR(wrap_angle(t.at(t.duration()).yaw), 0.0, 1e-9);
}

TEST_P(EveryManeuver, ProjectionOfPointsOnThePathIsExactAndProgressMonotone) {
  const Trajectory t = maneuver_trajectory(GetParam());
  const PathObserver obs(t);
  PathProjection p = obs.start();
  double last = 0;
  for (double s = 0; s <= t.duration(); s += 0.02) {
    const TrajectoryPoint q = t.at(s);
    p = obs.update(p, q.p_W, wrap_angle(q.yaw));
    ASSERT_GE(p.progress, last);
    last = p.progress;
    // Vertices are exact; between them the polyline's chord error on a 10 m circle is below 2e-4 m.
    EXPECT_LT((p.p_W - q.p_W).norm(), 2e-3) << "t = " << s;
    EXPECT_LT(std::abs(wrap_angle(p.yaw - q.yaw)), 2e-3) << "t = " << s;
  }
  EXPECT_NEAR(p.progress, obs.length(), 1e-9);
}

TEST_P(EveryManeuver, ProgressIsMonotoneAndCompleteOnAWobblyFlight) {
  // A flight that wanders up to 0.84 m off the path and 0.3 rad off in yaw.
  const Trajectory t = maneuver_trajectory(GetParam());
  const PathObserver obs(t);
  PathProjection p = obs.start();
  double last = 0, worst = 0;
  for (double s = 0; s <= t.duration(); s += 0.02) {
    const TrajectoryPoint q = t.at(s);
    const Vec3 off(0.5 * std::sin(1.3 * s), 0.6 * std::cos(0.7 * s), 0.3 * std::sin(2.1 * s));
    p = obs.update(p, q.p_W + off, wrap_angle(q.yaw + 0.3 * std::sin(0.9 * s)));
    ASSERT_GE(p.progress, last);
    last = p.progress;
    worst = std::max(worst, (p.p_W - (q.p_W + off)).norm());
  }
  EXPECT_LE(worst, 0.9);  // |offset| <= 0.84 m, and the yaw offset trades off at most 0.3 m
  EXPECT_GT(p.progress, obs.length() - 0.5);
}

INSTANTIATE_TEST_SUITE_P(Maneuvers, EveryManeuver, ::testing::Values("III.1", "III.2", "III.3", "figure8"),
                         [](const auto& param_info) {
                           std::string name = param_info.param;
                           std::replace(name.begin(), name.end(), '.', '_');
                           return name;
                         });

TEST(ManeuverTrajectory, FigureEightIsTwoNoseInCirclesFlownInOppositeSenses) {
  ManeuverSize size;
  size.figure_eight_radius = 1.5;
  const Trajectory t = maneuver_trajectory("figure8", size, {.speed = 0.5, .accel = 0.5});
  const Vec3 o = t.start_W(), north = o + Vec3(1.5, 0, 0), south = o - Vec3(1.5, 0, 0);
  std::vector<double> arcs;
  for (const auto& leg : t.legs())
    if (leg.kind == TrajectoryLeg::Kind::kArc) arcs.push_back(leg.sweep);
  ASSERT_EQ(arcs.size(), 2u);
  EXPECT_NEAR(arcs[0], 2 * kPi, 1e-12);  // clockwise seen from above
  EXPECT_NEAR(arcs[1], -2 * kPi, 1e-12);
  EXPECT_NEAR(position_length(t), 2 * 2 * kPi * 1.5, 1e-3);
  int on_circle = 0;
  for (double s = 0; s <= t.duration(); s += 0.05) {
    const TrajectoryPoint q = t.at(s);
    EXPECT_NEAR(q.p_W.z(), o.z(), 1e-12);  // level throughout
    const double dn = (q.p_W - north).norm(), ds = (q.p_W - south).norm();
    const Vec3 centre = dn < ds ? north : south;
    const Vec3 to_c = centre - q.p_W;
    if (q.v_W.norm() > 1e-6) {  // moving: on a circle, the nose on its centre, at most the speed limit
      ++on_circle;
      EXPECT_NEAR(to_c.norm(), 1.5, 1e-9);
      EXPECT_NEAR(wrap_angle(std::atan2(to_c.y(), to_c.x()) - q.yaw), 0.0, 1e-9) << "t = " << s;
      EXPECT_LE(q.v_W.norm(), 0.5 + 1e-12);
    }
  }
  EXPECT_GT(on_circle, 2 * 2 * kPi * 1.5 / 0.5 / 0.05 * 0.9);  // both circles at up to 0.5 m/s
}

TEST(ManeuverTrajectory, SizesAndDurationsAreThoseDocumented) {
  const Trajectory t1 = maneuver_trajectory("III.1"), t2 = maneuver_trajectory("III.2"),
                   t3 = maneuver_trajectory("III.3");
  EXPECT_NEAR(position_length(t1), 20 + 2 * std::sqrt(200.0), 1e-3);
  EXPECT_NEAR(position_length(t2), 20 + 2 * kPi * 10, 1e-3);
  EXPECT_NEAR(position_length(t3), 2 * 20 + 2 * 10, 1e-3);
  // Durations: a competition pace of well under two minutes each.
  for (const Trajectory* t : {&t1, &t2, &t3}) {
    EXPECT_GT(t->duration(), 30);
    EXPECT_LT(t->duration(), 90);
  }
  EXPECT_THROW(maneuver_trajectory("III.4"), InputError);
  ManeuverSize bad;
  bad.circle_radius = -1;
  EXPECT_THROW(maneuver_trajectory("III.2", bad), InputError);
}

TEST(ManeuverTrajectory, TriangleIsFlownBackwardsWithTwoHalfPirouettes) {
  const Trajectory t = maneuver_trajectory("III.1");
  int turns = 0;
  for (const auto& leg : t.legs()) {
    if (leg.kind == TrajectoryLeg::Kind::kTurn) {
      ++turns;
      EXPECT_NEAR(std::abs(leg.sweep), kPi, 1e-12);
    }
  }
  EXPECT_EQ(turns, 2);
  double highest = 0;
  for (double s = 0; s <= t.duration(); s += 0.05) {
    const TrajectoryPoint q = t.at(s);
    highest = std::max(highest, -q.p_W.z());
    const Vec3 v_h(q.v_W.x(), q.v_W.y(), 0);
    if (v_h.norm() > 0.1) {  // horizontal motion is always against the nose
      EXPECT_LT(v_h.x() * std::cos(q.yaw) + v_h.y() * std::sin(q.yaw), -0.09) << "t = " << s;
    }
  }
  EXPECT_NEAR(highest, 20, 1e-3);  // apex 10 m above the 10 m base (sampled every 0.05 s)
}

TEST(ManeuverTrajectory, NoseInCircleKeepsTheNoseOnTheCentre) {
  const Trajectory t = maneuver_trajectory("III.2");
  const Vec3 c = t.start_W();
  // Legs: hold, out, pause, circle, back, hold.
  ASSERT_EQ(t.legs()[3].kind, TrajectoryLeg::Kind::kArc);
  int on_circle = 0;
  for (double s = t.legs()[2].t0; s <= t.legs()[3].t0 + t.legs()[3].duration; s += 0.05) {
    const TrajectoryPoint q = t.at(s);
    const Vec3 to_c = c - q.p_W;
    {
      ++on_circle;
      EXPECT_NEAR(to_c.norm(), 10, 1e-9);
      EXPECT_NEAR(wrap_angle(std::atan2(to_c.y(), to_c.x()) - q.yaw), 0.0, 1e-9) << "t = " << s;
    }
  }
  EXPECT_GT(on_circle, 400);  // the pause and the 63 m circle
}

TEST(ManeuverTrajectory, RectanglePirouettesAreOppositeFullTurnsHalfwayUp) {
  const Trajectory t = maneuver_trajectory("III.3");
  std::vector<double> sweeps;
  for (const auto& leg : t.legs())
    if (leg.kind == TrajectoryLeg::Kind::kTurn) {
      sweeps.push_back(leg.sweep);
      EXPECT_NEAR(-leg.from_W.z(), 15, 1e-9);  // halfway up the 10 m side of a rectangle based at 10 m
      EXPECT_NEAR(std::abs(leg.from_W.x()), 10, 1e-9);  // on a vertical side
    }
  ASSERT_EQ(sweeps.size(), 2u);
  EXPECT_NEAR(sweeps[0], 2 * kPi, 1e-12);
  EXPECT_NEAR(sweeps[1], -2 * kPi, 1e-12);
}

TEST(ManeuverTrajectory, VerticalSetPointDelayLagsOnlyAngledLegs) {
  const Trajectory t = maneuver_trajectory("III.1");
  constexpr double d = 0.7;
  const TrajectoryLeg* climb = nullptr;
  for (const auto& leg : t.legs())
    if (leg.angled()) {
      climb = &leg;
      break;
    }
  ASSERT_NE(climb, nullptr);
  double last_z = t.delayed(0, d).p_W.z();
  for (double s = 0; s <= t.duration(); s += 0.01) {
    const TrajectoryPoint ideal = t.at(s), late = t.delayed(s, d);
    EXPECT_LT((ideal.p_W.head<2>() - late.p_W.head<2>()).norm(), 1e-12);
    EXPECT_EQ(ideal.yaw, late.yaw);
    EXPECT_LT(std::abs(late.p_W.z() - last_z), 2.5 * 0.01 + 1e-9);  // continuous
    last_z = late.p_W.z();
    if (s > climb->t0 + d && s < climb->t0 + climb->duration) {
      EXPECT_NEAR(late.p_W.z(), t.at(s - d).p_W.z(), 1e-9) << "t = " << s;
    }
  }
  EXPECT_EQ(t.delayed(t.duration(), d).p_W.z(), t.at(t.duration()).p_W.z());
  EXPECT_EQ(t.delayed(12.3, 0).p_W, t.at(12.3).p_W);
}

TEST(PathObserver, IsNotFooledWhereTheNoseInCircleLoopsBack) {
  // III.2 passes the rim point twice (circle start and end) and flies the same radius out and back.
  const Trajectory t = maneuver_trajectory("III.2");
  const PathObserver obs(t);
  // Where the outbound leg ends, the observer is at the rim, not at the circle's end or on the return leg.
  const TrajectoryLeg& out = t.legs()[1];
  ASSERT_EQ(out.kind, TrajectoryLeg::Kind::kLine);
  PathProjection p = obs.start();
  for (double s = 0; s <= out.t0 + out.duration; s += 0.02)
    p = obs.update(p, t.at(s).p_W, wrap_angle(t.at(s).yaw));
  EXPECT_NEAR(p.progress, 10, 1e-6);
  // Hovering at the rim for a long time (the pause and more) does not skip round the circle.
  for (int k = 0; k < 500; ++k) p = obs.update(p, out.to_W, 0.0);
  EXPECT_NEAR(p.progress, 10, 1e-6);
  // On the way back in, the same places are recognised as the end of the path, not its beginning.
  PathProjection q = obs.start();
  for (double s = 0; s <= t.duration(); s += 0.02) {
    q = obs.update(q, t.at(s).p_W, wrap_angle(t.at(s).yaw));
    if (s > t.legs()[4].t0 + 1) {
      EXPECT_GT(q.progress, 10 + 2 * kPi * 10) << "t = " << s;
    }
  }
  // A point far ahead along the path (the far side of the circle) is out of the window: no jump.
  PathProjection r = obs.update(obs.start(), t.start_W() + Vec3(10, 0, 0), kPi);
  EXPECT_LE(r.progress, obs.options().window + 1e-9);
}

TEST(PathObserver, RejectsBadOptions) {
  const Trajectory t = maneuver_trajectory("III.1");
  EXPECT_THROW(PathObserver(t, {.yaw_length = 0}), InputError);
  EXPECT_THROW(PathObserver(t, {.window = 0.01}), InputError);
}

}  // namespace
