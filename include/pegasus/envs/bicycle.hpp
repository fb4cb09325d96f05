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
  static constexpr double dt = 0.01;        // s
  static constexpr double v = 10.0 / 3.6;   // m/s (10 km/h)
  static constexpr double g = 9.82;         // m/s^2
  static constexpr double dCM = 0.3;        // m: height of the rider's centre of mass above the bicycle's
  static constexpr double c = 0.66;         // m: horizontal distance from front tyre contact to centre of mass
  static constexpr double h = 0.94;         // m: height of the centre of mass
  static constexpr double Mc = 15.0;        // kg: bicycle
  static constexpr double Md = 1.7;         // kg: one tyre
  static constexpr double Mp = 60.0;        // kg: rider
  static constexpr double M = Mc + Mp;      // kg
  static constexpr double R = 0.34;         // m: tyre radius
  static constexpr double l = 1.11;         // m: wheelbase (distance between the tyres' contact points)
  static constexpr double sigma_dot = v / R;                                    // rad/s: tyre angular velocity
  static constexpr double I_bike = 13.0 / 3.0 * Mc * h * h + Mp * (h + dCM) * (h + dCM);  // kg m^2
  static constexpr double I_dc = Md * R * R;                                    // tyre, about its axle
  static constexpr double I_dv = 1.5 * Md * R * R;                              // tyre, about a vertical diameter
  static constexpr double I_dl = 0.5 * Md * R * R;                              // tyre, about a horizontal diameter
  static constexpr double max_handlebar = 1.3963;          // rad: bike.c's clip (80 degrees)
  static constexpr double straight_radius = 9999999.0;     // m: bike.c's turning radius for theta = 0
  static constexpr double fall_angle = std::numbers::pi / 15.0;  // rad: |omega| beyond this is a fall
  static constexpr double max_torque = 2.0;                // N m
  static constexpr double max_displacement = 0.02;         // m
  static constexpr double max_noise = 0.02;                // m: bike.c's noise on the displacement
};

// The bicycle's state. Small and copyable (MuJoCo's data): each rollout owns its own.
struct BicycleState {
  double omega = 0, omega_dot = 0;  // tilt from vertical (rad, > 0 leaning left) and its rate (rad/s)
  double theta = 0, theta_dot = 0;  // handlebar angle (rad, > 0 steering left) and its rate (rad/s)
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
  double omega = 0.05;              // rad (a quarter of the fall angle)
  double omega_dot = 0.1;           // rad/s
  double theta = 0.05;              // rad
  double theta_dot = 0.2;           // rad/s
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
// Wraps an angle into (-pi, pi].
inline double wrap_angle(double a) {
  constexpr double two_pi = 2.0 * std::numbers::pi;
  if (a > std::numbers::pi || a <= -std::numbers::pi) {
    a = std::remainder(a, two_pi);
    if (a <= -std::numbers::pi) a += two_pi;
  }
  return a;
}
// sin and cos of the arc corrections, |x| <= asin(0.036): Taylor series whose first omitted term is below
// 1e-17 relative; std::sin and std::cos beyond.
inline void tiny_sincos(double x, double& sin_x, double& cos_x) {
  if (std::abs(x) > 0.04) {
    sin_x = std::sin(x);
    cos_x = std::cos(x);
    return;
  }
  const double x2 = x * x;
  sin_x = x * (1.0 - x2 * (1.0 / 6 - x2 * (1.0 / 120 - x2 * (1.0 / 5040))));
  cos_x = 1.0 - x2 * (0.5 - x2 * (1.0 / 24 - x2 * (1.0 / 720 - x2 * (1.0 / 40320))));
}
// bike.c's half-step arc correction: asin(x) for x <= 1, pi/2 beyond (v dt / (2 r) never exceeds 0.036).
// x is v dt / (2 r) >= 0, at most 0.036 at bike.c's speed: there the odd Taylor series of asin, cut after x^9,
// is exact to 2e-16, and saves a library call per tyre.
inline double arc_correction(double x) {
  if (x < 0.05) {
    const double x2 = x * x;
    return x * (1.0 + x2 * (1.0 / 6 + x2 * (3.0 / 40 + x2 * (5.0 / 112 + x2 * (35.0 / 1152)))));
  }
  return x > 1.0 ? std::numbers::pi / 2 : std::asin(x);
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
// Heading psi from the tyre positions, as bike.c computes it.
inline double heading(double xf, double yf, double xb, double yb) {
  const double dy = yf - yb;
  if (xf == xb && dy < 0.0) return std::numbers::pi;
  if (dy > 0.0) return std::atan((xb - xf) / dy);
  return sgn(xb - xf) * (std::numbers::pi / 2) - std::atan(dy / (xb - xf));
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
  // equations as bike.c with trigonometric identities where they save a library call: the frame direction
  // (-sin psi, cos psi) read from the tyre positions psi is computed from, tan from sin and cos, sin and cos
  // of theta carried to the next step, the sums of angles by the addition formulas, short Taylor series
  // for the sines of the tiny arc corrections. The plain
  // transcription of bike.c is kept in tests/bicycle as the reference this must match.
  State step(const State& s, const Action& a, std::span<const double> p) const {
    using namespace bicycle_detail;
    const double T = std::clamp(a[0], -K::max_torque, K::max_torque);
    const double d = std::clamp(a[1], -K::max_displacement, K::max_displacement) + options_.noise * (2.0 * p[0] - 1.0);

    // 1. Inverse turning radii (bike.c: r = 9999999 m for theta = 0).
    double inv_rf = 1.0 / K::straight_radius, inv_rb = inv_rf, inv_rcm = inv_rf;
    if (s.theta != 0.0) {
      double sin_t = s.sin_theta, cos_t = s.cos_theta;
      if (s.trig_of != s.theta) {
        sin_t = std::sin(s.theta);
        cos_t = std::cos(s.theta);
      }
      const double tan_t = std::abs(sin_t / cos_t);
      inv_rf = std::abs(sin_t) * (1.0 / K::l);
      inv_rb = tan_t * (1.0 / K::l);
      inv_rcm = tan_t / std::sqrt((K::l - K::c) * (K::l - K::c) * tan_t * tan_t + K::l * K::l);
    }

    // 2. Accelerations.
    const double phi = s.omega + small_atan(d * (1.0 / K::h));
    const double sin_phi = std::sin(phi), cos_phi = std::cos(phi);
    const double omega_dd =
        (K::h * K::M * K::g * sin_phi -
         cos_phi * (K::I_dc * K::sigma_dot * s.theta_dot +
                    sgn(s.theta) * K::v * K::v * (K::Md * K::R * (inv_rf + inv_rb) + K::M * K::h * inv_rcm))) *
        (1.0 / K::I_bike);
    const double theta_dd = (T - K::I_dv * s.omega_dot * K::sigma_dot) * (1.0 / K::I_dl);

    // 3. Semi-implicit Euler, handlebar clipped.
    State n;
    n.omega_dot = s.omega_dot + omega_dd * K::dt;
    n.omega = s.omega + n.omega_dot * K::dt;
    n.theta_dot = s.theta_dot + theta_dd * K::dt;
    n.theta = s.theta + n.theta_dot * K::dt;
    if (std::abs(n.theta) > K::max_handlebar) n.theta = sgn(n.theta) * K::max_handlebar;

    // 4. Tyres. The frame direction is (-sin psi, cos psi) = (f - b) / |f - b|.
    constexpr double step_length = K::v * K::dt;
    const double fx = s.xf - s.xb, fy = s.yf - s.yb;
    const double inv_len = 1.0 / std::sqrt(fx * fx + fy * fy);
    const double sin_psi = -fx * inv_len, cos_psi = fy * inv_len;
    // Front: angle psi + theta + turn, turn = sgn(psi + theta) asin(v dt / (2 r_f)).
    n.sin_theta = std::sin(n.theta);
    n.cos_theta = std::cos(n.theta);
    n.trig_of = n.theta;
    const double front_turn = sgn(s.psi + n.theta) * arc_correction(step_length * 0.5 * inv_rf);
    double sin_turn, cos_turn;
    tiny_sincos(front_turn, sin_turn, cos_turn);
    const double sin_f = n.sin_theta * cos_turn + n.cos_theta * sin_turn;  // of theta + turn
    const double cos_f = n.cos_theta * cos_turn - n.sin_theta * sin_turn;
    n.xf = s.xf - step_length * (sin_psi * cos_f + cos_psi * sin_f);
    n.yf = s.yf + step_length * (cos_psi * cos_f - sin_psi * sin_f);
    // Back: angle psi + turn, turn = sgn(psi) asin(v dt / (2 r_b)).
    const double back_turn = sgn(s.psi) * arc_correction(step_length * 0.5 * inv_rb);
    tiny_sincos(back_turn, sin_turn, cos_turn);
    n.xb = s.xb - step_length * (sin_psi * cos_turn + cos_psi * sin_turn);
    n.yb = s.yb + step_length * (cos_psi * cos_turn - sin_psi * sin_turn);

    // 5. Wheelbase kept at l.
    const double length = std::sqrt((n.xf - n.xb) * (n.xf - n.xb) + (n.yf - n.yb) * (n.yf - n.yb));
    if (std::abs(length - K::l) > 0.01) {
      n.xb += (n.xb - n.xf) * (K::l - length) / length;
      n.yb += (n.yb - n.yf) * (K::l - length) / length;
    }

    // 6. Heading.
    n.psi = heading(n.xf, n.yf, n.xb, n.yb);

    n.status = std::abs(n.omega) > K::fall_angle ? State::kFallen
               : inside_goal(n.xf, n.yf)         ? State::kAtGoal
                                                 : State::kRiding;
    return n;
  }

  bool terminal(const State& s) const { return s.status != State::kRiding; }

  Observation observe(const State& s) const {
    // The frame points along psi + pi/2 counter-clockwise from +x.
    const double frame = s.psi + std::numbers::pi / 2;
    const double to_goal = options_.goal.at_infinity ? options_.goal.direction
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
    if (options_.goal.at_infinity)
      return s.xf * std::cos(options_.goal.direction) + s.yf * std::sin(options_.goal.direction);
    return -std::hypot(s.xf - options_.goal.x, s.yf - options_.goal.y);
  }

 private:
  bool inside_goal(double x, double y) const {
    if (options_.goal.at_infinity) return false;
    const double dx = x - options_.goal.x, dy = y - options_.goal.y;
    return dx * dx + dy * dy <= options_.goal.radius * options_.goal.radius;
  }

  BicycleOptions options_;
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
