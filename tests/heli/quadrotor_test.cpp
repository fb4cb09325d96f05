// The ground-truth quadrotor: hover, the angle-mode set points, the motor lag, rotor drag, reproducibility,
// crash detection, and the pilot flying it through the GroundTruth interface.
#include "pegasus/heli/quadrotor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/simulators.hpp"
#include "support/scenario_noise.hpp"

namespace {

using namespace pegasus::heli;

using pegasus::test_support::mid_range_noise;

// A calm, noise-free quadrotor (uniforms of 0.5 are the Gaussian's median: no draws).
QuadrotorParams calm() {
  QuadrotorParams p;
  p.conditions.gust_sigma = 0;
  p.conditions.est_sigma_pos = p.conditions.est_sigma_vel = p.conditions.est_sigma_angle =
      p.conditions.est_sigma_rate = 0;
  return p;
}

QuadrotorState fly(const Quadrotor& q, const Controls& a, double seconds) {
  QuadrotorState s = q.initial_state(mid_range_noise(Quadrotor::kInitialNoise));
  const auto p = mid_range_noise(Quadrotor::kStepNoise);
  for (int t = 0; t < static_cast<int>(std::lround(seconds / q.params().dt)); ++t) s = q.step(s, a, p);
  return s;
}

TEST(Quadrotor, HoverPointHoldsItStillAndMatchesTheWeight) {
  const Quadrotor q(calm());
  const HoverPoint h = q.hover_point();
  // The collective that carries the weight: (a3 + 1) / 2 of the full thrust.
  EXPECT_NEAR((h.controls[2] + 1) / 2 * q.max_thrust(), q.params().mass_kg * q.params().gravity, 1e-15);
  EXPECT_NEAR(q.params().thrust_coeff * std::pow(q.hover_rotor_speed(), 2) * 4,
              q.params().mass_kg * q.params().gravity, 1e-15);
  const QuadrotorState s = fly(q, h.controls, 10);
  EXPECT_EQ(s.crash, CrashReason::kNone);
  EXPECT_LT((s.p_W - q.params().conditions.start_p_W).norm(), 1e-9);
  EXPECT_LT(s.v_B.norm(), 1e-9);
  EXPECT_LT(s.w_B.norm(), 1e-9);
}

TEST(Quadrotor, AngleModeSettlesOnTheSetPointsWithThePipelineSigns) {
  const Quadrotor q(calm());
  const double tilt = q.params().max_tilt_command_rad;
  // Half stick forward: 0.5 of the full tilt, nose down (negative pitch), and the aircraft accelerates
  // forward; half stick right: roll right, drifting right.
  Controls a = q.hover_point().controls;
  a[0] = 0.5;
  QuadrotorState s = fly(q, a, 1.0);
  EXPECT_NEAR(s.attitude.pitch, -0.5 * tilt, 1e-3 * tilt);
  EXPECT_GT(world_from_body(s.attitude, s.v_B).x(), 1.0);
  a = q.hover_point().controls;
  a[1] = 0.5;
  s = fly(q, a, 1.0);
  EXPECT_NEAR(s.attitude.roll, 0.5 * tilt, 1e-3 * tilt);
  EXPECT_GT(world_from_body(s.attitude, s.v_B).y(), 1.0);
  // The yaw stick sets the yaw rate (+: yaw right, clockwise seen from above: r > 0 in NED).
  a = q.hover_point().controls;
  a[3] = 0.4;
  s = fly(q, a, 1.0);
  EXPECT_NEAR(s.w_B.z(), 0.4 * q.params().max_yaw_rate_command, 1e-3);
  // More collective climbs (z decreases in NED).
  a = q.hover_point().controls;
  a[2] += 0.1;
  s = fly(q, a, 0.5);
  EXPECT_LT(s.p_W.z(), q.params().conditions.start_p_W.z() - 0.1);
}

TEST(Quadrotor, RotorSpeedsLagTheirCommandsByTheMotorTimeConstant) {
  const Quadrotor q(calm());
  QuadrotorState s = q.initial_state(mid_range_noise(Quadrotor::kInitialNoise));
  std::array<double, 4> command;
  command.fill(1.2 * q.hover_rotor_speed());
  // The rotor equation alone, integrated finely over one time constant: 1 - 1/e of the step.
  const double tau = q.params().motor_tau, h = tau / 10000;
  const double w0 = s.rotor_speed[0];
  for (int k = 0; k < 10000; ++k) {
    const auto d = q.derivative(s, command, Vec3::Zero());
    for (std::size_t i = 0; i < 4; ++i) s.rotor_speed[i] += h * d.rotor_accel[i];
  }
  EXPECT_NEAR((s.rotor_speed[0] - w0) / (command[0] - w0), 1 - std::exp(-1.0), 1e-4);
}

TEST(Quadrotor, RotorDragOpposesTheAirspeedInProportionToTheRotorSpeedSum) {
  const Quadrotor q(calm());
  QuadrotorState s = q.initial_state(mid_range_noise(Quadrotor::kInitialNoise));
  std::array<double, 4> command = s.rotor_speed;
  const auto still = q.derivative(s, command, Vec3::Zero());
  s.v_B = Vec3(2.0, -1.0, 0.5);
  const auto moving = q.derivative(s, command, Vec3::Zero());
  const double sum = 4 * q.hover_rotor_speed();
  const Vec3 expected = -sum / q.params().mass_kg *
                        Vec3(q.params().drag_xy * 2.0, q.params().drag_xy * -1.0, q.params().drag_z * 0.5);
  // The drag is the only change in force; w = 0 leaves no Coriolis term.
  EXPECT_LT((moving.v_dot_B - still.v_dot_B - expected).norm(), 1e-12);
  // A wind equal to the velocity removes it.
  const auto drifting = q.derivative(s, command, world_from_body(s.attitude, s.v_B));
  EXPECT_LT((drifting.v_dot_B - still.v_dot_B).norm(), 1e-12);
}

TEST(Quadrotor, SameUniformsSameFlightAndCrashesAreDetected) {
  QuadrotorParams p;
  p.conditions.start_pos_sigma = 0.2;
  const Quadrotor q(p);
  const std::vector<double> p0 = {0.1, 0.9, 0.3, 0.7, 0.2, 0.6, 0.4, 0.8, 0.15, 0.5, 0.5,
                                  0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5,  0.5};
  ASSERT_EQ(static_cast<int>(p0.size()), Quadrotor::kInitialNoise);
  auto a = q.initial_state(p0), b = q.initial_state(p0);
  const std::vector<double> noise = {0.3, 0.8, 0.1, 0.5, 0.5, 0.5, 0.6, 0.4,
                                     0.5, 0.5, 0.5, 0.5, 0.7, 0.2, 0.5};
  for (int t = 0; t < 100; ++t) {
    a = q.step(a, q.hover_point().controls, noise);
    b = q.step(b, q.hover_point().controls, noise);
  }
  EXPECT_EQ(true_logged_state(a), true_logged_state(b));
  EXPECT_EQ(q.observe(a), q.observe(b));
  // No thrust: it falls to the ground and stays there.
  const QuadrotorState fallen = fly(Quadrotor(calm()), {0, 0, -1, 0}, 2);
  EXPECT_EQ(fallen.crash, CrashReason::kGround);
}

TEST(Quadrotor, TheScriptedPilotFliesItsSweepsWithoutCrashing) {
  GroundTruthSettings settings;
  const auto quad = make_ground_truth("crazyflie2", settings);
  EXPECT_EQ(quad->simulator_name(), "crazyflie2");
  const PilotFlight f = fly_pilot(*quad, pilot_options_for("crazyflie2"), 120, 7);
  EXPECT_EQ(f.crash, CrashReason::kNone);
  ASSERT_EQ(f.log.rows(), 6000u);
  // It stays within two metres of its start while every channel is swept.
  double worst = 0;
  for (const auto& s : f.truth)
    worst = std::max(worst, (position_of(s) - Vec3(0, 0, -2)).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 2.0);
  EXPECT_THROW(make_ground_truth("zeppelin", settings), std::invalid_argument);
}

}  // namespace
