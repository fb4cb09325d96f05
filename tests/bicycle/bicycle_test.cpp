// The bicycle simulator (Randlov and Alstrom's bike.c) and its policy features.
#include "pegasus/envs/bicycle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "bicycle_reference.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/evaluators/rollout.hpp"
#include "pegasus/random/counter_rng.hpp"

namespace pegasus {
namespace {

using K = BicycleConstants;

BicycleState make_state(double omega, double omega_dot, double theta, double theta_dot, double xb, double yb,
                        double psi) {
  BicycleState s;
  s.omega = omega;
  s.omega_dot = omega_dot;
  s.theta = theta;
  s.theta_dot = theta_dot;
  s.xb = xb;
  s.yb = yb;
  s.xf = xb - K::l * std::sin(psi);
  s.yf = yb + K::l * std::cos(psi);
  s.psi = psi;
  s.trig_of = std::nan("");  // no cached sin/cos: step computes them
  return s;
}

BicycleState step(const Bicycle& bike, const BicycleState& s, double T, double d, double p) {
  return bike.step(s, {T, d}, std::span<const double>(&p, 1));
}

void expect_state_near(const BicycleState& a, const BicycleState& b, double tol, const std::string& where) {
  EXPECT_NEAR(a.omega, b.omega, tol) << where;
  EXPECT_NEAR(a.omega_dot, b.omega_dot, tol) << where;
  EXPECT_NEAR(a.theta, b.theta, tol) << where;
  EXPECT_NEAR(a.theta_dot, b.theta_dot, tol) << where;
  EXPECT_NEAR(a.xf, b.xf, tol) << where;
  EXPECT_NEAR(a.yf, b.yf, tol) << where;
  EXPECT_NEAR(a.xb, b.xb, tol) << where;
  EXPECT_NEAR(a.yb, b.yb, tol) << where;
  EXPECT_NEAR(a.psi, b.psi, tol) << where;
  EXPECT_EQ(a.status, b.status) << where;
}

BicycleState expected(std::initializer_list<double> v) {
  const double* x = v.begin();
  BicycleState s;
  s.omega = x[0], s.omega_dot = x[1], s.theta = x[2], s.theta_dot = x[3];
  s.xf = x[4], s.yf = x[5], s.xb = x[6], s.yb = x[7], s.psi = x[8];
  return s;
}

// Expected values computed by hand (bike.c's statements evaluated one by one in double precision, outside
// this code base): a turning step, a step where psi + theta > pi (bike.c's sign quirk), and a step with a
// straight handlebar (bike.c's 9999999 m radius).
TEST(BicycleDynamics, MatchesHandComputedSteps) {
  const Bicycle bike;
  expect_state_near(step(bike, make_state(0.05, -0.2, 0.3, 1.5, 0.0, 0.0, 0.3), 1.0, 0.01, 0.75),
                    expected({0.047929479474746114, -0.2070520525253889, 0.3165079041997422,
                              1.650790419974218, -0.3441719430655228, 1.0830279187941254,
                              -0.008311547035892949, 0.026505152784727426, 0.30778980878184115}),
                    1e-12, "turning step");
  expect_state_near(step(bike, make_state(-0.1, 0.4, 0.6, -3.0, 3.0, -2.0, 2.9), -2.0, -0.02, 0.1),
                    expected({-0.09627765599568411, 0.3722344004315903, 0.5669841916005156,
                              -3.301580839948436, 2.7434989718952107, -3.1040203248524856, 2.9935853083679533,
                              -2.027026961899876, 2.9134283362853584}),
                    1e-12, "psi + theta > pi");
  expect_state_near(step(bike, make_state(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -0.7), 0.0, 0.0, 0.5),
                    expected({0.0, 0.0, 0.0, 0.0, 0.7329765686199474, 0.8702204441743862, 0.01789493578611033,
                              0.02124561628860393, -0.7}),
                    1e-12, "straight handlebar");
}

TEST(BicycleDynamics, FastStepMatchesThePlainTranscriptionOfBikeC) {
  const Bicycle bike;
  UniformStream rng(7, 0);
  for (int k = 0; k < 2000; ++k) {
    auto u = [&](double lo, double hi) { return lo + (hi - lo) * rng.next(); };
    const BicycleState s = make_state(u(-0.2, 0.2), u(-2, 2), u(-1.39, 1.39), u(-5, 5), u(-50, 50),
                                      u(-50, 50), u(-std::numbers::pi, std::numbers::pi));
    const double T = u(-2, 2), d = u(-0.02, 0.02), p = rng.next();
    expect_state_near(step(bike, s, T, d, p), bicycle_reference::step(bike, s, T, d, p), 1e-12,
                      "random state " + std::to_string(k));
  }
}

// A rollout of the stabilising linear controller: fast and reference stay together for 20 s (2000 steps)
// with the cached sin/cos of theta in use.
TEST(BicycleDynamics, FastRolloutMatchesTheReference) {
  const Bicycle bike;
  const std::array<double, 5> p0 = {0.8, 0.3, 0.6, 0.4, 0.9};
  BicycleState fast = bike.initial_state(p0), slow = fast;
  UniformStream noise(3, 0);
  for (int t = 0; t < 2000; ++t) {
    auto control = [](const BicycleState& s) {
      return std::clamp(10 * s.omega + 5 * s.omega_dot - 5 * s.theta - 0.3 * s.theta_dot, -2.0, 2.0);
    };
    const double p = noise.next();
    fast = step(bike, fast, control(fast), 0.0, p);
    slow = bicycle_reference::step(bike, slow, control(slow), 0.0, p);
    ASSERT_EQ(fast.status, BicycleState::kRiding) << t;
  }
  expect_state_near(fast, slow, 1e-9, "after 2000 steps");
}

// A long ride: 36000 steps (6 minutes, a kilometre) of the 15-feature policy class (the balancing weights)
// stepped by both. Rounding differences of 1e-16 per step are carried along by the dynamics, so the bound
// after a kilometre is looser than a single step's 1e-12: angles and rates 1e-10, positions 1e-7 m (the
// heading error integrated over the path).
TEST(BicycleDynamics, LongRideMatchesTheReference) {
  BicycleOptions options;
  options.goal = BicycleGoal::circle(5000.0, 0.0, 10.0);  // never reached: the whole ride is compared
  const Bicycle bike(options);
  const BicyclePolicy policy = make_bicycle_policy();
  const Theta theta = bicycle_balancing_theta();
  for (int k = 0; k < 2; ++k) {
    UniformStream noise(21 + k, 0);
    std::array<double, 5> p0;
    for (double& p : p0) p = noise.next();
    BicycleState fast = bike.initial_state(p0), slow = fast;
    for (int t = 0; t < 36000; ++t) {
      const double p = noise.next();
      const auto a = policy.act(theta, bike.observe(fast)), b = policy.act(theta, bike.observe(slow));
      fast = bike.step(fast, a, std::span<const double>(&p, 1));
      slow = bicycle_reference::step(bike, slow, b[0], b[1], p);
      ASSERT_EQ(fast.status, BicycleState::kRiding) << t;
      ASSERT_EQ(slow.status, BicycleState::kRiding) << t;
    }
    EXPECT_NEAR(fast.omega, slow.omega, 1e-10);
    EXPECT_NEAR(fast.omega_dot, slow.omega_dot, 1e-10);
    EXPECT_NEAR(fast.theta, slow.theta, 1e-10);
    EXPECT_NEAR(fast.theta_dot, slow.theta_dot, 1e-10);
    EXPECT_NEAR(fast.psi, slow.psi, 1e-10);
    EXPECT_NEAR(fast.xf, slow.xf, 1e-7);
    EXPECT_NEAR(fast.yf, slow.yf, 1e-7);
    EXPECT_NEAR(fast.xb, slow.xb, 1e-7);
    EXPECT_NEAR(fast.yb, slow.yb, 1e-7);
    EXPECT_GT(std::hypot(fast.xf, fast.yf), 100.0);  // it did ride somewhere
  }
}

// The inlined replacements of library functions in the fast step agree with the library to a few units in
// the last place over the ranges the step uses them on, and fall back to it outside.
TEST(BicycleDynamics, InlinedFunctionsMatchTheLibrary) {
  using namespace bicycle_detail;
  UniformStream rng(17, 0);
  for (int k = 0; k < 20000; ++k) {
    const double u = 2.0 * rng.next() - 1.0;
    const double wide = std::ldexp(u, static_cast<int>(60 * rng.next()) - 30);  // 1e-9 .. 1e9
    ASSERT_NEAR(atan_rational(wide), std::atan(wide), 2.3e-16 * std::max(1.0, std::abs(std::atan(wide))))
        << wide;
    ASSERT_EQ(atan_rational(-wide), -atan_rational(wide));
    double s, c;
    handlebar_sincos(1.4 * u, s, c);
    ASSERT_NEAR(s, std::sin(1.4 * u), 4e-16) << 1.4 * u;
    ASSERT_NEAR(c, std::cos(1.4 * u), 4e-16) << 1.4 * u;
    small_sincos(0.3 * u, s, c);
    ASSERT_NEAR(s, std::sin(0.3 * u), 2e-16) << 0.3 * u;
    ASSERT_NEAR(c, std::cos(0.3 * u), 2e-16) << 0.3 * u;
    const double beyond = std::copysign(0.31 + 2.5 * std::abs(u), u);  // beyond the series: the library
    small_sincos(beyond, s, c);
    ASSERT_EQ(s, std::sin(beyond));
    ASSERT_NEAR(angle_sin(std::numbers::pi * u), std::sin(std::numbers::pi * u), 4e-16)
        << std::numbers::pi * u;
    ASSERT_NEAR(small_atan(0.05 * u), std::atan(0.05 * u), 1e-17);
    const double angle = 20.0 * u;
    const double wrapped = wrap_angle(angle);
    ASSERT_GT(wrapped, -std::numbers::pi);
    ASSERT_LE(wrapped, std::numbers::pi);
    ASSERT_NEAR(std::remainder(angle - wrapped, 2.0 * std::numbers::pi), 0.0, 1e-14) << angle;
  }
  EXPECT_EQ(atan_rational(0.0), 0.0);
  EXPECT_EQ(atan_rational(std::numeric_limits<double>::infinity()), std::numbers::pi / 2);
  EXPECT_EQ(wrap_angle(-std::numbers::pi), std::numbers::pi);
  EXPECT_EQ(wrap_angle(3.0 * std::numbers::pi), std::numbers::pi);
}

// Negating T, d and the noise mirrors the motion in the y axis: x -> -x, and every angle changes sign.
TEST(BicycleDynamics, NegatingTheActionsMirrorsTheMotion) {
  BicycleOptions options;
  options.goal = BicycleGoal::circle(0.0, 1000.0, 10.0);  // on the mirror axis
  const Bicycle bike(options);
  BicycleState s = make_state(0.03, 0.1, 0.2, -0.4, 1.0, 2.0, 0.4);
  BicycleState m = make_state(-0.03, -0.1, -0.2, 0.4, -1.0, 2.0, -0.4);
  UniformStream rng(11, 0);
  for (int t = 0; t < 300; ++t) {
    const double T = 4 * rng.next() - 2, d = 0.04 * rng.next() - 0.02, p = rng.next();
    s = step(bike, s, T, d, p);
    m = step(bike, m, -T, -d, 1.0 - p);
    const double tol = 1e-9;
    ASSERT_NEAR(m.omega, -s.omega, tol) << t;
    ASSERT_NEAR(m.omega_dot, -s.omega_dot, tol) << t;
    ASSERT_NEAR(m.theta, -s.theta, tol) << t;
    ASSERT_NEAR(m.theta_dot, -s.theta_dot, tol) << t;
    ASSERT_NEAR(m.xf, -s.xf, tol) << t;
    ASSERT_NEAR(m.yf, s.yf, tol) << t;
    ASSERT_NEAR(m.xb, -s.xb, tol) << t;
    ASSERT_NEAR(m.yb, s.yb, tol) << t;
    ASSERT_NEAR(m.psi, -s.psi, tol) << t;
    ASSERT_NEAR(bike.observe(m).goal_angle, -bike.observe(s).goal_angle, tol) << t;
    ASSERT_EQ(m.status, s.status) << t;
    if (bike.terminal(s)) break;
  }
}

// Left alone (T = 0, d = 0), the bicycle falls within a few seconds from every start.
TEST(BicycleDynamics, AnUnsteeredBicycleFallsWithinAFewSeconds) {
  const Bicycle bike;
  UniformStream rng(5, 0);
  for (int k = 0; k < 50; ++k) {
    std::array<double, 5> p0;
    for (double& p : p0) p = rng.next();
    BicycleState s = bike.initial_state(p0);
    int t = 0;
    for (; t < 1000 && !bike.terminal(s); ++t) s = step(bike, s, 0.0, 0.0, rng.next());
    EXPECT_EQ(s.status, BicycleState::kFallen) << k;
    EXPECT_LT(t * K::dt, 3.0) << k;
    EXPECT_GT(t * K::dt, 0.3) << k;
    EXPECT_GT(std::abs(s.omega), K::fall_angle);
  }
}

TEST(BicycleDynamics, HandlebarIsClippedAt80DegreesAndWheelbaseKept) {
  const Bicycle bike;
  BicycleState s = make_state(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
  double max_theta = 0.0;
  for (int t = 0; t < 200 && !bike.terminal(s); ++t) {
    const BicycleState next = step(bike, s, 2.0, 0.0, 0.5);
    // The front tyre moves exactly v dt per step.
    EXPECT_NEAR(std::hypot(next.xf - s.xf, next.yf - s.yf), K::v * K::dt, 1e-12);
    EXPECT_NEAR(std::hypot(next.xf - next.xb, next.yf - next.yb), K::l, 0.0101);
    max_theta = std::max(max_theta, std::abs(next.theta));
    s = next;
  }
  EXPECT_EQ(max_theta, 1.3963);
}

TEST(BicycleDynamics, InitialStateFollowsTheDistribution) {
  const Bicycle bike;
  const std::array<double, 5> centre = {0.5, 0.5, 0.5, 0.5, 0.5};
  const BicycleState s = bike.initial_state(centre);
  EXPECT_EQ(s.omega, 0.0);
  EXPECT_EQ(s.theta, 0.0);
  EXPECT_NEAR(s.psi, -std::numbers::pi / 2, 1e-15);  // pointing east, at the goal
  EXPECT_NEAR(bike.observe(s).goal_angle, 0.0, 1e-12);
  const std::array<double, 5> quarter = {1.0, 0.0, 1.0, 0.0, 0.25};  // goal 90 degrees to the right
  const BicycleState q = bike.initial_state(quarter);
  EXPECT_NEAR(q.omega, 0.05, 1e-15);
  EXPECT_NEAR(q.omega_dot, -0.1, 1e-15);
  EXPECT_NEAR(q.psi, 0.0, 1e-12);                                        // pointing north, as bike.c starts
  EXPECT_NEAR(bike.observe(q).goal_angle, -std::numbers::pi / 2, 2e-3);  // seen from the front tyre
  EXPECT_NEAR(std::hypot(q.xf - q.xb, q.yf - q.yb), K::l, 1e-15);
}

TEST(BicycleRewards, FallIsAbsorbingWithTheFallRewardAtTheCrossingFraction) {
  const Bicycle bike;
  BicycleState s = make_state(0.2, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
  const BicycleState next = step(bike, s, 0.0, 0.0, 0.5);
  ASSERT_EQ(next.status, BicycleState::kFallen);
  EXPECT_TRUE(bike.terminal(next));
  const Bicycle::Action a = {0.0, 0.0};
  EXPECT_EQ(bike.reward(s, a, next), -100.0);
  const double tau = bike.event_fraction(s, a, next);
  EXPECT_NEAR(s.omega + tau * (next.omega - s.omega), K::fall_angle, 1e-15);
  EXPECT_GT(tau, 0.0);
  EXPECT_LT(tau, 1.0);
  // A riding transition earns nothing and has no event.
  BicycleState upright = make_state(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
  const BicycleState after = step(bike, upright, 0.0, 0.0, 0.5);
  EXPECT_EQ(bike.reward(upright, a, after), 0.0);
  EXPECT_EQ(bike.event_fraction(upright, a, after), 0.0);
}

TEST(BicycleRewards, GoalEntryEndsTheRideAtTheCrossingFraction) {
  BicycleOptions options;
  options.goal = BicycleGoal::circle(0.0, 12.0, 10.0);
  options.goal_reward = 1.0;
  const Bicycle bike(options);
  BicycleState s = make_state(0.0, 0.0, 0.0, 0.0, 0.0, 0.88, 0.0);  // front tyre at y = 1.99, riding north
  const Bicycle::Action a = {0.0, 0.0};
  const BicycleState next = step(bike, s, 0.0, 0.0, 0.5);
  ASSERT_EQ(next.status, BicycleState::kAtGoal);
  EXPECT_EQ(bike.reward(s, a, next), 1.0);
  const double tau = bike.event_fraction(s, a, next);
  EXPECT_NEAR(s.yf + tau * (next.yf - s.yf), 2.0, 1e-9);
  // With gamma^(t + tau) discounting (footnote 9) the reward is gamma^tau at t = 0.
  double ret = 0.0;
  accumulate_transition(bike, s, a, next, 0.9, 1.0, ret);
  EXPECT_NEAR(ret, std::pow(0.9, tau), 1e-15);
}

TEST(BicycleFeatures, AreTheDocumentedFifteen) {
  const BicycleFeatures f;
  ASSERT_EQ(f.size(), 15);
  EXPECT_EQ(BicycleFeatures::names().size(), 15u);
  const BicycleObservation o{.omega = std::numbers::pi / 30,
                             .omega_dot = -0.5,
                             .theta = std::numbers::pi / 8,
                             .theta_dot = 4.0,
                             .goal_angle = -std::numbers::pi / 2};
  std::array<double, 15> x;
  f(o, x);
  const std::array<double, 15> want = {0.5,   0.25, 0.125, -0.5, -0.25, -0.125, 0.5, 0.25,
                                       0.125, 2.0,  4.0,   8.0,  -0.5,  -0.25,  -1.0};
  for (int k = 0; k < 15; ++k) EXPECT_NEAR(x[k], want[k], 1e-15) << BicycleFeatures::names()[k];
}

TEST(BicycleFeatures, PoliciesAreMirrorSymmetricAndZeroWeightsDoNothing) {
  const BicyclePolicy policy = make_bicycle_policy();
  ASSERT_EQ(policy.parameters().size(), 30u);
  EXPECT_EQ(policy.parameters()[0].name, "w.T.omega");
  EXPECT_EQ(policy.parameters()[15].name, "w.d.omega");
  UniformStream rng(9, 0);
  Theta theta(30);
  for (double& w : theta) w = 6 * rng.next() - 3;
  for (int k = 0; k < 100; ++k) {
    const BicycleObservation o{.omega = 0.4 * rng.next() - 0.2,
                               .omega_dot = 2 * rng.next() - 1,
                               .theta = 2.8 * rng.next() - 1.4,
                               .theta_dot = 8 * rng.next() - 4,
                               .goal_angle = 6 * rng.next() - 3};
    const BicycleObservation m{-o.omega, -o.omega_dot, -o.theta, -o.theta_dot, -o.goal_angle};
    const auto a = policy.act(theta, o), b = policy.act(theta, m);
    EXPECT_NEAR(a[0], -b[0], 1e-12);
    EXPECT_NEAR(a[1], -b[1], 1e-14);
    EXPECT_GE(a[0], -2.0);
    EXPECT_LE(a[0], 2.0);
    EXPECT_GE(a[1], -0.02);
    EXPECT_LE(a[1], 0.02);
    const auto zero = policy.act(Theta(30, 0.0), o);
    EXPECT_EQ(zero[0], 0.0);
    EXPECT_EQ(zero[1], 0.0);
  }
}

}  // namespace
}  // namespace pegasus
