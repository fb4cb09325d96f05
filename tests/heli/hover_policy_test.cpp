// The hover policy class of §5.3 (Fig 5.4, Eqs 5.7-5.8): layout, clipping, trim output, channel signs.
#include "pegasus/heli/hover_policy.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace pegasus::heli {
namespace {

HeliObservation at_target(SetPoint target = {}) {
  HeliObservation o;
  o.target = target;
  o.state = {target.x, target.y, target.z, 0, 0, target.yaw, 0, 0, 0, 0, 0, 0};
  return o;
}

TEST(HoverPolicy, HasThirtyFourNamedParametersChannelByChannel) {
  const HoverPolicy pi;
  ASSERT_EQ(pi.parameters().size(), 34u);
  EXPECT_EQ(pi.parameters()[0].name, "a1.bias");
  EXPECT_EQ(pi.parameters()[8].name, "a1.out_linear");
  EXPECT_EQ(pi.parameters()[9].name, "a2.bias");
  EXPECT_EQ(pi.parameters()[18].name, "a3.bias");
  EXPECT_EQ(pi.parameters()[25].name, "a3.out_linear");
  EXPECT_EQ(pi.parameters()[33].name, "a4.out_linear");
  EXPECT_EQ(HoverPolicy::index(0, HoverPolicy::kAtt), 5);
  EXPECT_EQ(HoverPolicy::index(2, HoverPolicy::kOutLinear), 25);
  EXPECT_EQ(HoverPolicy::index(3, HoverPolicy::kVel), 30);
  EXPECT_THROW(HoverPolicy::index(2, HoverPolicy::kAtt), std::invalid_argument);
}

TEST(HoverPolicy, ZeroErrorAtTrimGivesTheTrimControls) {
  HoverPolicyInit init;
  init.trim = {0.01, 0.036, 0.18, 0.19};
  init.trim_roll = 0.078;
  const HoverPolicy pi(init);
  const Theta theta = pi.parameters().initial();
  for (const SetPoint sp : {SetPoint{}, SetPoint{5, -3, -20, 2.5}}) {
    HeliObservation o = at_target(sp);
    o.state[3] = init.trim_roll;
    const Controls a = pi.act(theta, o);
    for (std::size_t c = 0; c < 4; ++c) EXPECT_NEAR(a[c], init.trim[c], 1e-12) << c;
  }
}

TEST(HoverPolicy, MatchesEquations57And58) {
  const HoverPolicy pi;
  Theta w = pi.parameters().initial();
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = 0.1 + 0.01 * static_cast<double>(i);
  HeliObservation o = at_target();
  o.state[0] = 0.7;   // x error (yaw 0, level: body = world)
  o.state[4] = 0.05;  // pitch: rotates the error into the body frame
  o.state[6] = 0.3;   // xdot
  const HoverInputs in = hover_inputs(o);
  const double ex = std::cos(0.05) * 0.7 - std::sin(0.05) * 0.0;  // x_B = R^T (p - p*) with z error 0
  const double u = std::cos(0.05) * 0.3;
  EXPECT_NEAR(in.error[0], ex, 1e-15);
  EXPECT_NEAR(in.velocity[0], u, 1e-15);
  const double t1 = w[0] + w[1] * ex + w[2] * std::tanh(w[3] * ex) + w[4] * u + w[5] * 0.05;
  const double a1 = w[6] * std::tanh(w[7] * t1) + w[8] * t1;
  EXPECT_NEAR(HoverPolicy::unclipped(w, in)[0], a1, 1e-15);
  // Collective: 8 weights from index 18, no attitude input.
  const double ez = in.error[2], wz = in.velocity[2];
  const double t3 = w[18] + w[19] * ez + w[20] * std::tanh(w[21] * ez) + w[22] * wz;
  EXPECT_NEAR(HoverPolicy::unclipped(w, in)[2], w[23] * std::tanh(w[24] * t3) + w[25] * t3, 1e-15);
}

TEST(HoverPolicy, OutputsAreClippedToTheUnitBox) {
  const HoverPolicy pi;
  Theta w = pi.parameters().initial();
  for (std::size_t c = 0; c < 4; ++c)
    w[static_cast<std::size_t>(HoverPolicy::index(static_cast<int>(c), HoverPolicy::kOutLinear))] = 1000;
  HeliObservation o = at_target();
  o.state = {30, -30, 20, 0.3, -0.3, 2.0, 5, -5, 5, 1, 1, 3};
  const Controls a = pi.act(w, o);
  for (double x : a) {
    EXPECT_LE(x, 1.0);
    EXPECT_GE(x, -1.0);
    EXPECT_EQ(std::abs(x), 1.0);
  }
  o.state[0] = std::nan("");
  for (double x : pi.act(w, o)) EXPECT_FALSE(std::isnan(x));
}

TEST(HoverPolicy, EachChannelPushesBackTowardsTheSetPoint) {
  const HoverPolicy pi;
  const Theta theta = pi.parameters().initial();
  const Controls trim = pi.act(theta, at_target());
  auto delta = [&](int index, double value, int channel) {
    HeliObservation o = at_target();
    o.state[static_cast<std::size_t>(index)] += value;
    return pi.act(theta, o)[static_cast<std::size_t>(channel)] - trim[static_cast<std::size_t>(channel)];
  };
  EXPECT_LT(delta(0, 1.0, 0), 0);   // ahead of the set point: cyclic back
  EXPECT_LT(delta(6, 1.0, 0), 0);   // moving forward: cyclic back
  EXPECT_GT(delta(4, 0.1, 0), 0);   // nose up: cyclic forward
  EXPECT_LT(delta(1, 1.0, 1), 0);   // right of the set point: cyclic left
  EXPECT_LT(delta(7, 1.0, 1), 0);   // moving right: cyclic left
  EXPECT_LT(delta(3, 0.1, 1), 0);   // rolled right: cyclic left
  EXPECT_GT(delta(2, 1.0, 2), 0);   // below the set point (z down): more collective
  EXPECT_GT(delta(8, 1.0, 2), 0);   // sinking: more collective
  EXPECT_LT(delta(5, 0.2, 3), 0);   // yawed right of the heading: tail left
  EXPECT_LT(delta(11, 0.5, 3), 0);  // yawing right: tail left
}

TEST(HoverPolicy, YawErrorWrapsAndErrorsAreInTheBodyFrame) {
  const HoverPolicy pi;
  const Theta theta = pi.parameters().initial();
  HeliObservation a = at_target({0, 0, -10, 0.01});
  a.state[5] = 2 * std::numbers::pi - 0.01;
  EXPECT_NEAR(hover_inputs(a).error[3], -0.02, 1e-12);
  HeliObservation b = at_target({0, 0, -10, 0.01});
  b.state[5] = -0.01;
  for (std::size_t c = 0; c < 4; ++c) EXPECT_NEAR(pi.act(theta, a)[c], pi.act(theta, b)[c], 1e-12);
  // Facing east (yaw pi/2), a helicopter 1 m north of its set point is 1 m to its left: y_B error -1.
  HeliObservation e = at_target({0, 0, -10, std::numbers::pi / 2});
  e.state[0] = 1.0;
  const HoverInputs in = hover_inputs(e);
  EXPECT_NEAR(in.error[0], 0.0, 1e-12);
  EXPECT_NEAR(in.error[1], -1.0, 1e-12);
}

// The integral term (issue 15): four weights after the networks, fed the flight's error integral rotated into
// the body frame like the error; without it (34 weights) the integral changes nothing.
TEST(HoverPolicy, IntegralTermAddsFourWeightsFedTheIntegralInTheBodyFrame) {
  const HoverPolicyInit init{.integral_seconds = 4};
  const HoverPolicy pi(init);
  ASSERT_EQ(pi.parameters().size(), 38u);
  EXPECT_TRUE(pi.has_integral());
  EXPECT_FALSE(HoverPolicy().has_integral());
  const std::array<double, 4> gains = {init.k_pos, init.k_pos_lat, init.k_alt, init.k_yaw};
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(pi.parameters()[34 + c].name, "a" + std::to_string(c + 1) + ".int");
    EXPECT_EQ(pi.parameters()[34 + c].initial, gains[c] / 4);  // the PI rule k_i = k_p / T_i
  }
  Theta w = pi.parameters().initial();
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = 0.1 + 0.01 * static_cast<double>(i);
  // Facing east (yaw pi/2): an integral of 2 m s north is 2 m s to the body's left (y_B = -2).
  HeliObservation o = at_target({0, 0, -10, std::numbers::pi / 2});
  o.integral = {2, 0, 0.5, -0.3};
  const HoverInputs in = hover_inputs(o);
  EXPECT_NEAR(in.integral[0], 0.0, 1e-15);
  EXPECT_NEAR(in.integral[1], -2.0, 1e-15);
  EXPECT_NEAR(in.integral[2], 0.5, 1e-15);
  EXPECT_EQ(in.integral[3], -0.3);
  // A linear output network (out_tanh_gain 0, out_linear 1): a_c = t_c, so the term adds int * I_c to it.
  for (int c = 0; c < 4; ++c) {
    w[static_cast<std::size_t>(HoverPolicy::index(c, HoverPolicy::kOutTanhGain))] = 0;
    w[static_cast<std::size_t>(HoverPolicy::index(c, HoverPolicy::kOutLinear))] = 1;
  }
  HoverInputs none = in;
  none.integral = {};
  const Controls with = HoverPolicy::unclipped(w, in), without = HoverPolicy::unclipped(w, none);
  for (std::size_t c = 0; c < 4; ++c)
    EXPECT_NEAR(with[c] - without[c], w[34 + c] * in.integral[c], 1e-15) << c;
  const Theta w34(w.begin(), w.begin() + 34);
  EXPECT_EQ(HoverPolicy::unclipped(w34, in), without);  // the thesis's class ignores it
}

TEST(ErrorIntegrator, AddsOnePeriodOfErrorClampsAndSkipsNonFiniteErrors) {
  const ErrorIntegrator on{.dt = 0.1, .limit_position = 1, .limit_yaw = 0.5};
  EXPECT_TRUE(on.on());
  EXPECT_FALSE(ErrorIntegrator{}.on());
  const SetPoint target{1, 2, -10, 0.1};
  LoggedState s{};
  s[logged::x] = 3, s[logged::y] = 2, s[logged::z] = -10.5, s[logged::yaw] = 2 * std::numbers::pi + 0.05;
  const auto once = on.advanced({0, 0.95, 0, 0}, s, target);
  EXPECT_DOUBLE_EQ(once[0], 0.2);       // + 0.1 s * 2 m
  EXPECT_DOUBLE_EQ(once[1], 0.95);      // no error in y
  EXPECT_DOUBLE_EQ(once[2], -0.05);     // z error -0.5 m
  EXPECT_NEAR(once[3], -0.005, 1e-12);  // the yaw error wraps: -0.05 rad
  s[logged::y] = 100;
  EXPECT_EQ(on.advanced(once, s, target)[1], 1.0);  // clamped at the limit (anti-windup)
  s[logged::x] = std::nan("");
  EXPECT_EQ(on.advanced(once, s, target)[0], once[0]);  // a bad estimate adds nothing
  std::string why;
  EXPECT_FALSE((ErrorIntegrator{.dt = 0.02, .limit_position = 0}).IsValid(&why));
  EXPECT_EQ(why, "limit_position: expected a finite number > 0 (m s)");
}

}  // namespace
}  // namespace pegasus::heli
