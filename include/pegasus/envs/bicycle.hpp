#pragma once
// Randlov and Alstrom's bicycle (ICML 1998) as a deterministic simulative model g(s, a, p) (thesis §4.6).
//
// The equations, constants and update order are those of Randlov and Alstrom's C simulator (bike.c): a
// bicycle at constant speed v = 10 km/h whose rider applies a torque T to the handlebars and displaces the
// centre of mass sideways by d. Every step of dt = 0.01 s:
//   1. turning radii from the handlebar angle theta at the start of the step (front tyre r_f = l/|sin|,
//      back tyre r_b = l/|tan|, centre of mass r_CM = sqrt((l-c)^2 + l^2/tan^2); 9999999 m when theta = 0);
//   2. phi = omega + atan(d/h), the tilt of the combined centre of mass;
//      omega'' = (h M g sin(phi) - cos(phi) (I_dc sigma' theta' + sgn(theta) v^2 (M_d R (1/r_f + 1/r_b)
//                 + M h / r_CM))) / I_bike;   theta'' = (T - I_dv sigma' omega') / I_dl;
//   3. semi-implicit Euler: omega' += omega'' dt, then omega += omega' dt (the new rate); the same for
//      theta; theta is clipped to +-1.3963 rad (80 degrees; its rate is kept, as in the original);
//   4. the front tyre moves v dt along psi + theta + sgn(psi + theta) asin(v dt / (2 r_f)), the back tyre
//      along psi + sgn(psi) asin(v dt / (2 r_b)) (theta the new angle, psi the old heading; a half-step
//      correction for the arc of the turn, signs as the original writes them);
//   5. when rounding has changed the wheelbase by more than 1 cm, the back tyre is moved back to distance l;
//   6. the heading psi is recomputed from the two tyre positions.
// Angles: radians. omega > 0 is a lean to the left, theta > 0 steers left, and psi is the angle of the
// frame (back tyre to front tyre) from the +y axis, counter-clockwise, in (-pi, pi]: psi = 0 rides north
// (+y), psi = -pi/2 east (+x). Positions are world-frame metres.
//
// Deviations from bike.c, all below the simulator's own resolution: the state is double (bike.c keeps
// float), pi is exact (bike.c: 3.1415927), and sgn(0) = 0 (bike.c's `sign` comes from a header that is not
// public; the value at exactly 0 only reaches a 1e-9 correction term, and sgn(0) = 0 keeps the model
// exactly mirror-symmetric).
//
// The randomness is bike.c's: a uniform displacement of +-2 cm added to d, here noise (2 p - 1) with p the
// single uniform of the step. The bicycle falls when |omega| > pi/15: an absorbing state with reward
// fall_reward. A goal is either a circle (1 km away, 10 m radius, as in bike.c) whose entry ends the ride,
// or a direction at infinity (training "infinitely far" from the goal, §4.6 footnote 15): then only the
// angle to the goal is defined, and progress is measured along that direction.
//
// Continuous-time discounting (footnote 9 of §4.4): event_fraction(s, a, s') is the fraction of the step at
// which the fall (|omega| = pi/15, omega interpolated linearly) or the goal entry (front tyre on the
// circle, moved linearly) happened, so the fall penalty is discounted by gamma^(t + tau) and U-hat changes
// continuously with the moment of the fall.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "pegasus/models/action_space.hpp"

namespace pegasus {

// bike.c's constants (SI units) and the moments of inertia derived from them.
struct BicycleConstants {
  static constexpr double dt = 0.01;       // s
  static constexpr double v = 10.0 / 3.6;  // m/s (10 km/h)
  static constexpr double g = 9.82;        // m/s^2
  static constexpr double dCM = 0.3;       // m: height of the rider's centre of mass above the bicycle's
  static constexpr double c = 0.66;        // m: horizontal distance from front tyre contact to centre of mass
  static constexpr double h = 0.94;        // m: height of the centre of mass
  static constexpr double Mc = 15.0;       // kg: bicycle
  static constexpr double Md = 1.7;        // kg: one tyre
  static constexpr double Mp = 60.0;       // kg: rider
  static constexpr double M = Mc + Mp;     // kg
  static constexpr double R = 0.34;        // m: tyre radius
  static constexpr double l = 1.11;        // m: wheelbase (distance between the tyres' contact points)
  static constexpr double sigma_dot = v / R;  // rad/s: tyre angular velocity
  static constexpr double I_bike = 13.0 / 3.0 * Mc * h * h + Mp * (h + dCM) * (h + dCM);  // kg m^2
  static constexpr double I_dc = Md * R * R;                     // tyre, about its axle
  static constexpr double I_dv = 1.5 * Md * R * R;               // tyre, about a vertical diameter
  static constexpr double I_dl = 0.5 * Md * R * R;               // tyre, about a horizontal diameter
  static constexpr double max_handlebar = 1.3963;                // rad: bike.c's clip (80 degrees)
  static constexpr double straight_radius = 9999999.0;           // m: bike.c's turning radius for theta = 0
  static constexpr double fall_angle = std::numbers::pi / 15.0;  // rad: |omega| beyond this is a fall
  static constexpr double max_torque = 2.0;                      // N m
  static constexpr double max_displacement = 0.02;               // m
  static constexpr double max_noise = 0.02;                      // m: bike.c's noise on the displacement
};

// The bicycle's state. Small and copyable (MuJoCo's data): each rollout owns its own.
struct BicycleState {
  double omega = 0, omega_dot = 0;          // tilt from vertical (rad, > 0 leaning left) and its rate (rad/s)
  double theta = 0, theta_dot = 0;          // handlebar angle (rad, > 0 steering left) and its rate (rad/s)
  double xf = 0, yf = BicycleConstants::l;  // front tyre contact point, world frame (m)
  double xb = 0, yb = 0;                    // back tyre contact point, world frame (m)
  double psi = 0;                           // heading, from +y counter-clockwise, (-pi, pi]
  // sin and cos of the handlebar angle `trig_of`, kept so that a step computes one sine and cosine of
  // theta instead of two; step recomputes them whenever trig_of != theta (a state written by hand).
  double sin_theta = 0, cos_theta = 1, trig_of = 0;
  enum Status : unsigned char { kRiding = 0, kFallen = 1, kAtGoal = 2 };
  Status status = kRiding;
};

// What the policy sees: the bicycle's five variables of Randlov and Alstrom, the angle to the goal being
// the signed angle from the frame's direction to the direction of the goal from the front tyre, in
// (-pi, pi], positive when the goal lies to the left. The distance to the goal is deliberately absent.
struct BicycleObservation {
  double omega = 0, omega_dot = 0, theta = 0, theta_dot = 0, goal_angle = 0;
};

// The goal: a circle, or a direction at infinity.
struct BicycleGoal {
  bool at_infinity = false;
  double x = 1000.0, y = 0.0;  // centre of the circle (m); bike.c: (1000, 0)
  double radius = 10.0;        // m
  double direction = 0.0;      // at infinity: direction of the goal, counter-clockwise from +x (rad)

  static BicycleGoal circle(double x, double y, double radius) { return {false, x, y, radius, 0.0}; }
  static BicycleGoal infinitely_far(double direction) { return {true, 0.0, 0.0, 0.0, direction}; }
};

// The initial-state distribution D: each variable uniform in [-max, max]. The back tyre starts at the
// origin and the frame points at the given angle from the direction of the goal (from the origin).
struct BicycleStart {
  double omega = 0.05;                   // rad (a quarter of the fall angle)
  double omega_dot = 0.1;                // rad/s
  double theta = 0.05;                   // rad
  double theta_dot = 0.2;                // rad/s
  double goal_angle = std::numbers::pi;  // rad: pi = any heading
};

struct BicycleOptions {
  BicycleGoal goal{};
  BicycleStart start{};
  double fall_reward = -100.0;  // reward of the transition into a fall ("a large negative reward", §4.6)
  double goal_reward = 0.0;     // reward of the transition into the goal circle
  double noise = BicycleConstants::max_noise;  // half-width of the uniform noise on d (m)

  // "field: expected ..., got ..." on a bad value.
  bool IsValid(std::string* error) const;
};

namespace bicycle_detail {
inline double sgn(double x) { return static_cast<double>((x > 0.0) - (x < 0.0)); }
// Wraps an angle into (-pi, pi]: one addition of 2 pi for the angles the bicycle produces (within 3 pi of
// the range), std::remainder beyond.
inline double wrap_angle(double a) {
  constexpr double pi = std::numbers::pi, two_pi = 2.0 * std::numbers::pi;
  if (a > pi) {
    a = a <= 3.0 * pi ? a - two_pi : std::remainder(a, two_pi);
  } else if (a <= -pi) {
    a = a > -3.0 * pi ? a + two_pi : std::remainder(a, two_pi);
  }
  if (a <= -pi) a += two_pi;  // the remainder's -pi, or rounding at the edge
  return a;
}
// sin(x) for x in [-pi, pi] (angles wrapped by wrap_angle): reflected into [-pi/2, pi/2] and a Taylor series
// to x^21 (first omitted term below 2e-18; the reflection's rounding of pi is 1.2e-16). std::sin beyond.
inline double angle_sin(double x) {
  constexpr double pi = std::numbers::pi;
  if (!(std::abs(x) <= pi)) return std::sin(x);
  if (x > pi / 2) x = pi - x;
  if (x < -pi / 2) x = -pi - x;
  constexpr double f3 = 1.0 / 6, f5 = 1.0 / 120, f7 = 1.0 / 5040, f9 = 1.0 / 362880, f11 = 1.0 / 39916800,
                   f13 = 1.0 / 6227020800.0, f15 = 1.0 / 1307674368000.0, f17 = 1.0 / 355687428096000.0,
                   f19 = 1.0 / 121645100408832000.0, f21 = 1.0 / 51090942171709440000.0;
  const double x2 = x * x;
  return x *
         (1.0 -
          x2 *
              (f3 -
               x2 * (f5 -
                     x2 * (f7 - x2 * (f9 - x2 * (f11 -
                                                 x2 * (f13 -
                                                       x2 * (f15 - x2 * (f17 - x2 * (f19 - x2 * f21))))))))));
}
// sin and cos of a small angle, |x| <= 0.3 (the tilt of the centre of mass, |phi| < pi/15 + atan(0.04/h)
// while riding): Taylor series to x^13 and x^12, whose first omitted terms are below 1e-19; std::sin and
// std::cos beyond.
inline void small_sincos(double x, double& sin_x, double& cos_x) {
  if (!(std::abs(x) <= 0.3)) {
    sin_x = std::sin(x);
    cos_x = std::cos(x);
    return;
  }
  const double x2 = x * x;
  sin_x =
      x * (1.0 - x2 * (1.0 / 6 -
                       x2 * (1.0 / 120 -
                             x2 * (1.0 / 5040 - x2 * (1.0 / 362880 -
                                                      x2 * (1.0 / 39916800 - x2 * (1.0 / 6227020800.0)))))));
  cos_x = 1.0 - x2 * (0.5 - x2 * (1.0 / 24 -
                                  x2 * (1.0 / 720 -
                                        x2 * (1.0 / 40320 - x2 * (1.0 / 3628800 - x2 * (1.0 / 479001600))))));
}
// sin and cos of the handlebar angle, |x| <= 1.4 (the clip is 1.3963): Taylor series to x^19 and x^20, whose
// first omitted terms are below 3e-17 (the series' own rounding is a few units in the last place); std::sin
// and std::cos beyond. Branch-free inside the range and a fraction of a library call's instructions.
inline void handlebar_sincos(double x, double& sin_x, double& cos_x) {
  if (!(std::abs(x) <= 1.4)) {
    sin_x = std::sin(x);
    cos_x = std::cos(x);
    return;
  }
  // 1/k! for k = 2 .. 20.
  constexpr double f2 = 1.0 / 2, f3 = 1.0 / 6, f4 = 1.0 / 24, f5 = 1.0 / 120, f6 = 1.0 / 720, f7 = 1.0 / 5040,
                   f8 = 1.0 / 40320, f9 = 1.0 / 362880, f10 = 1.0 / 3628800, f11 = 1.0 / 39916800,
                   f12 = 1.0 / 479001600, f13 = 1.0 / 6227020800.0, f14 = 1.0 / 87178291200.0,
                   f15 = 1.0 / 1307674368000.0, f16 = 1.0 / 20922789888000.0, f17 = 1.0 / 355687428096000.0,
                   f18 = 1.0 / 6402373705728000.0, f19 = 1.0 / 121645100408832000.0,
                   f20 = 1.0 / 2432902008176640000.0;
  const double x2 = x * x;
  sin_x =
      x *
      (1.0 -
       x2 * (f3 -
             x2 * (f5 -
                   x2 * (f7 - x2 * (f9 - x2 * (f11 - x2 * (f13 - x2 * (f15 - x2 * (f17 - x2 * f19)))))))));
  cos_x =
      1.0 -
      x2 * (f2 -
            x2 * (f4 -
                  x2 * (f6 -
                        x2 * (f8 -
                              x2 * (f10 - x2 * (f12 - x2 * (f14 - x2 * (f16 - x2 * (f18 - x2 * f20)))))))));
}
// bike.c's half-step arc correction turns a tyre by sgn * asin(x), x = v dt / (2 r) >= 0 (pi/2 when x > 1):
// its sine and cosine are sgn * min(x, 1) and sqrt(1 - sin^2), no inverse sine needed.
inline void arc_turn(double sign, double x, double& sin_turn, double& cos_turn) {
  sin_turn = sign * std::min(x, 1.0);
  cos_turn = std::sqrt(1.0 - sin_turn * sin_turn);
}
// atan(x) for the lean of the centre of mass, |x| = |d| / h <= 0.043: the series cut after x^11 is exact to
// 1e-17 for |x| < 0.05; larger arguments (a wider noise option) take the library call.
inline double small_atan(double x) {
  if (std::abs(x) < 0.05) {
    const double x2 = x * x;
    return x * (1.0 - x2 * (1.0 / 3 - x2 * (1.0 / 5 - x2 * (1.0 / 7 - x2 * (1.0 / 9 - x2 * (1.0 / 11))))));
  }
  return std::atan(x);
}
// atan(x) for any x to within one unit in the last place (Moshier's Cephes atan: reduction to |u| <= 0.66 by
// atan(x) = pi/4 + atan((x - 1) / (x + 1)) or pi/2 - atan(1/x), then a degree 4/5 rational function of u^2);
// inlined, about a third of the library call's instructions. Odd: atan(-x) = -atan(x) exactly.
inline double atan_rational(double x) {
  constexpr double P0 = -8.750608600031904122785e-1, P1 = -1.615753718733365076637e1,
                   P2 = -7.500855792314704667340e1, P3 = -1.228866684490136173410e2,
                   P4 = -6.485021904942025371773e1;
  constexpr double Q0 = 2.485846490142306297962e1, Q1 = 1.650270098316988542046e2,
                   Q2 = 4.328810604912902668951e2, Q3 = 4.853903996359136964868e2,
                   Q4 = 1.945506571482613964425e2;
  constexpr double more_bits = 6.123233995736765886130e-17;  // pi/2 - double(pi/2)
  const double a = std::abs(x);
  double base, u, extra;
  if (a > 2.41421356237309504880) {  // tan(3 pi / 8)
    base = std::numbers::pi / 2, u = -1.0 / a, extra = more_bits;
  } else if (a <= 0.66) {
    base = 0.0, u = a, extra = 0.0;
  } else {
    base = std::numbers::pi / 4, u = (a - 1.0) / (a + 1.0), extra = 0.5 * more_bits;
  }
  const double z = u * u;
  const double p = (((P0 * z + P1) * z + P2) * z + P3) * z + P4;
  const double q = ((((z + Q0) * z + Q1) * z + Q2) * z + Q3) * z + Q4;
  return std::copysign(base + ((u * (z * p / q) + u) + extra), x);
}
// Heading psi from the tyre positions, as bike.c computes it.
inline double heading(double xf, double yf, double xb, double yb) {
  const double dy = yf - yb;
  if (xf == xb && dy < 0.0) return std::numbers::pi;
  if (dy > 0.0) return atan_rational((xb - xf) / dy);
  return sgn(xb - xf) * (std::numbers::pi / 2) - atan_rational(dy / (xb - xf));
}

// The steps of Bicycle::step (see the header comment), inlined into it: one step is a few hundred
// instructions and runs billions of times in training (bench/bicycle_bench.cpp).

// 1 / r of the front tyre, the back tyre and the centre of mass for the handlebar angle of s (bike.c:
// r = 9999999 m for theta = 0).
struct InverseRadii {
  double front, back, cm;
};
[[gnu::always_inline]] inline InverseRadii inverse_radii(const BicycleState& s) {
  using K = BicycleConstants;
  double inv_rf = 1.0 / K::straight_radius, inv_rb = inv_rf, inv_rcm = inv_rf;
  if (s.theta != 0.0) {
    double sin_t = s.sin_theta, cos_t = s.cos_theta;
    if (s.trig_of != s.theta) handlebar_sincos(s.theta, sin_t, cos_t);
    const double tan_t = std::abs(sin_t / cos_t);
    inv_rf = std::abs(sin_t) * (1.0 / K::l);
    inv_rb = tan_t * (1.0 / K::l);
    inv_rcm = tan_t / std::sqrt((K::l - K::c) * (K::l - K::c) * tan_t * tan_t + K::l * K::l);
  }
  return {inv_rf, inv_rb, inv_rcm};
}

// The tilt's angular acceleration (omega''), the centre of mass displaced sideways by d.
[[gnu::always_inline]] inline double tilt_acceleration(const BicycleState& s, double d,
                                                       const InverseRadii& r) {
  using K = BicycleConstants;
  const double phi = s.omega + small_atan(d * (1.0 / K::h));
  double sin_phi, cos_phi;
  small_sincos(phi, sin_phi, cos_phi);
  return (K::h * K::M * K::g * sin_phi -
          cos_phi * (K::I_dc * K::sigma_dot * s.theta_dot +
                     sgn(s.theta) * K::v * K::v * (K::Md * K::R * (r.front + r.back) + K::M * K::h * r.cm))) *
         (1.0 / K::I_bike);
}

// The tyres' contact points after one step with the new handlebar angle theta, and its sine and cosine.
struct Tyres {
  double xf, yf, xb, yb;
  double sin_theta, cos_theta;
};
[[gnu::always_inline]] inline Tyres move_tyres(const BicycleState& s, double theta, const InverseRadii& r) {
  using K = BicycleConstants;
  // The frame direction is (-sin psi, cos psi) = (f - b) / |f - b|.
  constexpr double step_length = K::v * K::dt;
  const double fx = s.xf - s.xb, fy = s.yf - s.yb;
  const double inv_len = 1.0 / std::sqrt(fx * fx + fy * fy);
  const double sin_psi = -fx * inv_len, cos_psi = fy * inv_len;
  Tyres t;
  // Front: angle psi + theta + turn, turn = sgn(psi + theta) asin(v dt / (2 r_f)).
  handlebar_sincos(theta, t.sin_theta, t.cos_theta);
  double sin_turn, cos_turn;
  arc_turn(sgn(s.psi + theta), step_length * 0.5 * r.front, sin_turn, cos_turn);
  const double sin_f = t.sin_theta * cos_turn + t.cos_theta * sin_turn;  // of theta + turn
  const double cos_f = t.cos_theta * cos_turn - t.sin_theta * sin_turn;
  t.xf = s.xf - step_length * (sin_psi * cos_f + cos_psi * sin_f);
  t.yf = s.yf + step_length * (cos_psi * cos_f - sin_psi * sin_f);
  // Back: angle psi + turn, turn = sgn(psi) asin(v dt / (2 r_b)).
  arc_turn(sgn(s.psi), step_length * 0.5 * r.back, sin_turn, cos_turn);
  t.xb = s.xb - step_length * (sin_psi * cos_turn + cos_psi * sin_turn);
  t.yb = s.yb + step_length * (cos_psi * cos_turn - sin_psi * sin_turn);
  return t;
}

// The wheelbase kept at l: the back tyre moved along the frame when the length drifted by more than 1 cm
// (the squared length is compared, the square root only taken to correct it).
[[gnu::always_inline]] inline void keep_wheelbase(Tyres& t) {
  using K = BicycleConstants;
  const double ex = t.xf - t.xb, ey = t.yf - t.yb, length2 = ex * ex + ey * ey;
  constexpr double lo2 = (K::l - 0.01) * (K::l - 0.01), hi2 = (K::l + 0.01) * (K::l + 0.01);
  if (length2 < lo2 || length2 > hi2) {
    const double length = std::sqrt(length2);
    t.xb += (t.xb - t.xf) * (K::l - length) / length;
    t.yb += (t.yb - t.yf) * (K::l - length) / length;
  }
}
}  // namespace bicycle_detail

class Bicycle {
 public:
  using State = BicycleState;
  using Action = std::array<double, 2>;  // {T (N m), d (m)}
  using Observation = BicycleObservation;
  using K = BicycleConstants;

  Bicycle() : Bicycle(BicycleOptions{}) {}
  explicit Bicycle(const BicycleOptions& options);  // InputError on invalid options

  const BicycleOptions& options() const { return options_; }
  const BicycleGoal& goal() const { return options_.goal; }

  int state_dim() const { return 9; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 5; }
  ActionSpace action_space() const;

  // s0 from five uniforms: omega, omega', theta, theta', angle to the goal.
  State initial_state(std::span<const double> p0) const;

  // One step of bike.c (see the header comment). Pure; allocates nothing. Written for speed: the same
  // equations as bike.c with identities where they save a library call: the frame direction (-sin psi,
  // cos psi) read from the tyre positions psi is computed from, tan from sin and cos, sin and cos of theta
  // carried to the next step, the sums of angles by the addition formulas, sin(asin x) = x and
  // cos(asin x) = sqrt(1 - x^2) for the arc corrections, and Taylor series (exact to below 1e-16) for the
  // sines and cosines of the bounded angles phi and theta. The plain transcription of bike.c is kept in
  // tests/bicycle as the reference this must match.
  State step(const State& s, const Action& a, std::span<const double> p) const {
    using namespace bicycle_detail;
    const double T = std::clamp(a[0], -K::max_torque, K::max_torque);
    const double d =
        std::clamp(a[1], -K::max_displacement, K::max_displacement) + options_.noise * (2.0 * p[0] - 1.0);

    // 1. Inverse turning radii.
    const InverseRadii r = inverse_radii(s);

    // 2. Accelerations.
    const double omega_dd = tilt_acceleration(s, d, r);
    const double theta_dd = (T - K::I_dv * s.omega_dot * K::sigma_dot) * (1.0 / K::I_dl);

    // 3. Semi-implicit Euler, handlebar clipped. (The new state is kept in locals and written once at the
    // end: written field by field as it is computed, GCC stores it in pieces that the next step's paired
    // loads cannot forward from, about 6% of the step.)
    const double omega_dot = s.omega_dot + omega_dd * K::dt;
    const double omega = s.omega + omega_dot * K::dt;
    const double theta_dot = s.theta_dot + theta_dd * K::dt;
    double theta = s.theta + theta_dot * K::dt;
    if (std::abs(theta) > K::max_handlebar) theta = sgn(theta) * K::max_handlebar;

    // 4. Tyres, 5. wheelbase kept at l.
    Tyres t = move_tyres(s, theta, r);
    keep_wheelbase(t);

    // 6. Heading, and the new state.
    State n;
    n.omega = omega;
    n.omega_dot = omega_dot;
    n.theta = theta;
    n.theta_dot = theta_dot;
    n.xf = t.xf;
    n.yf = t.yf;
    n.xb = t.xb;
    n.yb = t.yb;
    n.psi = heading(t.xf, t.yf, t.xb, t.yb);
    n.sin_theta = t.sin_theta;
    n.cos_theta = t.cos_theta;
    n.trig_of = theta;
    n.status = std::abs(omega) > K::fall_angle ? State::kFallen
               : inside_goal(t.xf, t.yf)       ? State::kAtGoal
                                               : State::kRiding;
    return n;
  }

  bool terminal(const State& s) const { return s.status != State::kRiding; }

  Observation observe(const State& s) const {
    // The frame points along psi + pi/2 counter-clockwise from +x.
    const double frame = s.psi + std::numbers::pi / 2;
    const double to_goal = options_.goal.at_infinity
                               ? options_.goal.direction
                               : std::atan2(options_.goal.y - s.yf, options_.goal.x - s.xf);
    return {s.omega, s.omega_dot, s.theta, s.theta_dot, bicycle_detail::wrap_angle(to_goal - frame)};
  }

  double reward(const State& s, const Action&, const State& next) const {
    if (s.status != State::kRiding) return 0.0;
    if (next.status == State::kFallen) return options_.fall_reward;
    if (next.status == State::kAtGoal) return options_.goal_reward;
    return 0.0;
  }

  // tau in [0, 1]: when in the step the fall or the goal entry happened; 0 for other transitions.
  double event_fraction(const State& s, const Action& a, const State& next) const;

  // Progress towards the goal (m), the quantity the shaping potential is proportional to: minus the
  // distance from the front tyre to the goal's centre, or, for a goal at infinity, the front tyre's
  // coordinate along the goal's direction (the same thing up to a constant, infinitely far away).
  double progress(const State& s) const {
    if (options_.goal.at_infinity) return s.xf * goal_cos_ + s.yf * goal_sin_;
    return -std::hypot(s.xf - options_.goal.x, s.yf - options_.goal.y);
  }

 private:
  bool inside_goal(double x, double y) const {
    if (options_.goal.at_infinity) return false;
    const double dx = x - options_.goal.x, dy = y - options_.goal.y;
    return dx * dx + dy * dy <= options_.goal.radius * options_.goal.radius;
  }

  BicycleOptions options_;
  double goal_cos_ = 1.0, goal_sin_ = 0.0;  // of options_.goal.direction
};

// The shaping potential Phi(s) = per_metre * progress(s) (§3, Eq 3.1): with ShapedModel the bicycle earns
// gamma Phi(s') - Phi(s) per step, positive when it moves towards the goal and negative when it moves away
// (§4.6 footnote 15), and the optimal policy of the shaped problem is the unshaped one's (Theorem 1).
struct BicycleProgressPotential {
  Bicycle bicycle;
  double per_metre = 1.0;
  double operator()(const BicycleState& s) const { return per_metre * bicycle.progress(s); }
};

// The distance to the goal, for the non-potential progress bonus of the shaping lesson (§3.1).
struct BicycleGoalDistance {
  Bicycle bicycle;
  double operator()(const BicycleState& s) const { return -bicycle.progress(s); }
};

}  // namespace pegasus
