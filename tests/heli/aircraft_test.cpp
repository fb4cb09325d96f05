// The ground-truth helicopter: frames, trim, control signs, reproducibility, crash detection.
#include "pegasus/heli/aircraft.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "pegasus/heli/pilot.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "support/scenario_noise.hpp"

namespace {

using namespace pegasus::heli;

using pegasus::test_support::mid_range_noise;

TEST(HeliFrames, RotationIsOrthonormalAndMatchesHandCases) {
  const Euler e{0.3, -0.2, 2.5};
  const Mat3 r = rotation_world_from_body(e);
  EXPECT_LT((r * r.transpose() - Mat3::Identity()).norm(), 1e-14);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
  // Yaw 90 degrees: the body's forward axis points east in NED.
  const Vec3 fwd = world_from_body({0, 0, std::numbers::pi / 2}, Vec3(1, 0, 0));
  EXPECT_NEAR(fwd.x(), 0, 1e-15);
  EXPECT_NEAR(fwd.y(), 1, 1e-15);
  // Nose up 90 degrees... small pitch up: forward axis gains an upward (negative z) component.
  EXPECT_LT(world_from_body({0, 0.1, 0}, Vec3(1, 0, 0)).z(), 0);
  // Roll right: the body's right axis points down.
  EXPECT_GT(world_from_body({0.1, 0, 0}, Vec3(0, 1, 0)).z(), 0);
  const Vec3 v_W(1.0, -2.0, 0.5);
  EXPECT_LT((world_from_body(e, body_from_world(e, v_W)) - v_W).norm(), 1e-14);
}

TEST(HeliFrames, EulerRatesRoundTripAndMatchFiniteDifferences) {
  const Euler e{0.2, 0.3, -1.0};
  const Vec3 w_B(0.4, -0.3, 0.7);
  const Vec3 d = euler_rates_from_body_rates(e, w_B);
  EXPECT_LT((body_rates_from_euler_rates(e, d) - w_B).norm(), 1e-14);
  // dR/dt = R [w_B]x: check against the Euler rates by a central difference.
  const double h = 1e-6;
  const Euler ep{e.roll + h * d.x(), e.pitch + h * d.y(), e.yaw + h * d.z()};
  const Euler em{e.roll - h * d.x(), e.pitch - h * d.y(), e.yaw - h * d.z()};
  const Mat3 rdot = (rotation_world_from_body(ep) - rotation_world_from_body(em)) / (2 * h);
  Mat3 skew;
  skew << 0, -w_B.z(), w_B.y(), w_B.z(), 0, -w_B.x(), -w_B.y(), w_B.x(), 0;
  EXPECT_LT((rdot - rotation_world_from_body(e) * skew).norm(), 1e-8);
}

TEST(HeliFrames, WrapAngleLandsInHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrap_angle(std::numbers::pi), std::numbers::pi);
  EXPECT_DOUBLE_EQ(wrap_angle(-std::numbers::pi), std::numbers::pi);
  EXPECT_NEAR(wrap_angle(2 * std::numbers::pi - 0.01), -0.01, 1e-15);
  EXPECT_NEAR(wrap_angle(7 * std::numbers::pi + 0.5), -std::numbers::pi + 0.5, 1e-12);
  for (double a = -20; a < 20; a += 0.37) {
    const double w = wrap_angle(a);
    EXPECT_GT(w, -std::numbers::pi);
    EXPECT_LE(w, std::numbers::pi);
    EXPECT_NEAR(std::remainder(w - a, 2 * std::numbers::pi), 0, 1e-12);
  }
}

TEST(HeliFrames, QuaternionsOfAnyLengthGiveTheUnitQuaternionsAngles) {
  const Euler e{0.3, -0.4, 2.8};
  const std::array<double, 4> q = quaternion_from_euler(e);
  for (const double length : {1.0, 1e-150, 3.0, 1e200, 1.7e308}) {
    // 1.7e308 times the unit quaternion: each component is finite but the squared norm is not.
    const Euler back = euler_from_any_quaternion(length * q[0], length * q[1], length * q[2], length * q[3]);
    EXPECT_NEAR(back.roll, e.roll, 1e-12) << length;
    EXPECT_NEAR(back.pitch, e.pitch, 1e-12) << length;
    EXPECT_NEAR(back.yaw, e.yaw, 1e-12) << length;
  }
  EXPECT_TRUE(std::isnan(euler_from_any_quaternion(0, 0, 0, 0).roll));
  EXPECT_TRUE(std::isnan(euler_from_any_quaternion(1, INFINITY, 0, 0).yaw));
  EXPECT_TRUE(std::isnan(euler_from_any_quaternion(NAN, 1, 0, 0).pitch));
}
TEST(HeliAircraft, HoverTrimIsFoundWithSmallRightRollAndExpectedCollective) {
  const Aircraft heli;
  const auto& trim = heli.hover_trim();
  EXPECT_LT(trim.residual, 1e-9);
  // The tail rotor pushes the tail left, so hover needs a small roll to the right (thesis §5 intro).
  EXPECT_GT(trim.roll, 0.01);
  EXPECT_LT(trim.roll, 0.15);
  EXPECT_LT(std::abs(trim.pitch), 0.05);
  const AircraftParams& P = heli.params();
  // Thrust carries the weight; tail thrust times its arm balances the rotor torque.
  // Thrust carries the weight plus the download of the rotor wash on the fuselage, rho/2 S_z v_i^2.
  const double v_i = trim.rotor.inflow_ratio * P.omega_mr * P.radius_mr;
  const double download = 0.5 * P.air_density * P.fus_area_z * v_i * v_i;
  // The tail thrust (along -y of the rolled body) also lifts a little.
  const double lift =
      (trim.rotor.thrust_n * std::cos(trim.roll) + trim.rotor.tail_thrust_n * std::sin(trim.roll)) *
      std::cos(trim.pitch);
  EXPECT_NEAR(lift, P.mass_kg * P.gravity + download, 0.1);
  EXPECT_NEAR(trim.rotor.tail_thrust_n * P.arm_tr, trim.rotor.torque_nm, 0.3);
  // Collective from momentum theory by hand: C_T = W / (rho A (Omega R)^2), lambda = sqrt(C_T / 2),
  // theta0 = 3 (2 C_T / (a sigma) + lambda / 2).
  const double tip = P.omega_mr * P.radius_mr;
  const double ct =
      P.mass_kg * P.gravity / (P.air_density * std::numbers::pi * P.radius_mr * P.radius_mr * tip * tip);
  const double sigma = 2 * P.chord_mr / (std::numbers::pi * P.radius_mr);
  const double theta0 = 3 * (2 * ct / (P.lift_slope_mr * sigma) + std::sqrt(ct / 2) / 2);
  const double theta_trim = P.collective_mid_rad + P.collective_span_rad * trim.controls[2];
  EXPECT_NEAR(theta_trim, theta0, 0.01);
  for (double c : trim.controls) EXPECT_LT(std::abs(c), 0.8);
}

// Holds trim for a moment, then pushes one control and checks which states move which way.
Aircraft::State respond(const Aircraft& heli, int channel, double delta, double seconds) {
  AircraftParams P = heli.params();
  auto p0 = mid_range_noise(Aircraft::kInitialNoise);
  Aircraft::State s = heli.initial_state(p0);
  Controls a = heli.hover_trim().controls;
  a[static_cast<std::size_t>(channel)] += delta;
  const auto p = mid_range_noise(Aircraft::kStepNoise);
  for (int t = 0; t < static_cast<int>(seconds / P.dt); ++t) s = heli.step(s, a, p);
  return s;
}

TEST(HeliAircraft, TrimHoldsStillWithoutDisturbances) {
  AircraftParams P;
  P.conditions.gust_sigma = 0;
  const Aircraft heli(P);
  const auto s = respond(heli, 0, 0.0, 2.0);
  EXPECT_LT((s.p_W - P.conditions.start_p_W).norm(), 1e-6);
  EXPECT_LT(s.w_B.norm(), 1e-6);
}

TEST(HeliAircraft, EachControlMovesTheRightStatesWithTheRightSign) {
  AircraftParams P;
  P.conditions.gust_sigma = 0;
  const Aircraft heli(P);
  const auto& trim = heli.hover_trim();
  // Forward cyclic: nose down, then forward speed.
  auto s = respond(heli, 0, 0.1, 0.3);
  EXPECT_LT(s.w_B.y(), 0);
  EXPECT_LT(s.attitude.pitch, trim.pitch);
  s = respond(heli, 0, 0.1, 1.0);
  EXPECT_GT(world_from_body(s.attitude, s.v_B).x(), 0.05);
  // Right cyclic: roll right, then drift right (east at yaw 0).
  s = respond(heli, 1, 0.1, 0.3);
  EXPECT_GT(s.w_B.x(), 0);
  EXPECT_GT(s.attitude.roll, trim.roll);
  s = respond(heli, 1, 0.1, 1.0);
  EXPECT_GT(world_from_body(s.attitude, s.v_B).y(), 0.05);
  // More collective: climb (z decreases, NED).
  s = respond(heli, 2, 0.1, 0.5);
  EXPECT_LT(world_from_body(s.attitude, s.v_B).z(), -0.1);
  EXPECT_LT(s.p_W.z(), P.conditions.start_p_W.z());
  // More tail thrust: yaw right (clockwise from above, r > 0).
  s = respond(heli, 3, 0.1, 0.3);
  EXPECT_GT(s.w_B.z(), 0.05);
  EXPECT_GT(s.attitude.yaw, 0);
}

TEST(HeliAircraft, SeededFlightIsReproducibleAndSeedsDiffer) {
  const Aircraft heli;
  PilotOptions o;
  const auto a = fly_pilot(heli, o, 6.0, 7);
  const auto b = fly_pilot(heli, o, 6.0, 7);
  const auto c = fly_pilot(heli, o, 6.0, 8);
  ASSERT_EQ(a.log.rows(), 300u);
  EXPECT_EQ(a.log.states, b.log.states);
  EXPECT_EQ(a.log.controls, b.log.controls);
  EXPECT_NE(a.log.states.back(), c.log.states.back());
}

TEST(HeliAircraft, CrashesIntoTheGroundWhenCollectiveIsLowered) {
  AircraftParams P;
  P.conditions.start_p_W = Vec3(0, 0, -2);
  const Aircraft heli(P);
  auto s = heli.initial_state(mid_range_noise(Aircraft::kInitialNoise));
  const auto p = mid_range_noise(Aircraft::kStepNoise);
  Controls a = heli.hover_trim().controls;
  a[2] -= 0.3;
  int t = 0;
  for (; t < 1000 && !heli.terminal(s); ++t) s = heli.step(s, a, p);
  EXPECT_EQ(s.crash, CrashReason::kGround);
  EXPECT_LT(t, 150);
  const auto after = heli.step(s, a, p);  // a crashed state is absorbing
  EXPECT_EQ(after.p_W, s.p_W);
}

TEST(HeliPilot, HoldsHoverAndFliesAllFourSweepsWithoutCrashing) {
  const Aircraft heli;
  const auto f = fly_pilot(heli, PilotOptions{}, 120.0, 3);
  EXPECT_EQ(f.crash, CrashReason::kNone) << crash_reason_name(f.crash) << " at " << f.crash_time;
  ASSERT_EQ(f.log.rows(), 6000u);
  double max_dist = 0;
  for (const auto& s : f.truth) max_dist = std::max(max_dist, std::hypot(s[0], s[1], s[2] + 10));
  EXPECT_LT(max_dist, 15.0);
  // Every channel was excited during its own sweep.
  for (int c = 0; c < 4; ++c) {
    double lo = 1, hi = -1;
    for (std::size_t i = 0; i < f.log.rows(); ++i) {
      const double tt = f.log.time[i];
      if (tt > 10 + c * 27.5 + 5 && tt < 10 + (c + 1) * 27.5 - 5) {
        lo = std::min(lo, f.log.controls[i][static_cast<std::size_t>(c)]);
        hi = std::max(hi, f.log.controls[i][static_cast<std::size_t>(c)]);
      }
    }
    EXPECT_GT(hi - lo, 0.08) << c;
  }
}

}  // namespace
