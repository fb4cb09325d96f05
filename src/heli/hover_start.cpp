// The hover's starting gains from the identified model (issue 15, hover_task.hpp: LqrStart): the mean step
// linearised at the hover, a discounted LQR on it, and the hover class's share of its gain.
#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "pegasus/heli/hover_task.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::heli {
namespace {

using LqrMatrix = Eigen::MatrixXd;

// The LQR's state: the 12 logged states and the 3 extra states; its inputs a1..a4.
constexpr int kLqrStates = kLoggedStates + 3, kLqrInputs = 4;
constexpr auto kLqrRollAt = static_cast<Eigen::Index>(logged::roll),
               kLqrPitchAt = static_cast<Eigen::Index>(logged::pitch),
               kLqrYawAt = static_cast<Eigen::Index>(logged::yaw);

Eigen::Index lqr_column(std::size_t column) { return static_cast<Eigen::Index>(column); }

// The hover at the set point at the logs' trim attitude, heading north (the class's errors are in the body
// frame, and a hover's dynamics do not depend on the heading), the flaps at their equilibrium.
sysid::SimState hover_sim_state(const sysid::ModelStructure& m, const HoverPolicyInit& init,
                                const SetPoint& target) {
  sysid::SimState s0;
  s0.world = {target.x, target.y, target.z, init.trim_roll, init.trim_pitch, 0, 0, 0, 0, 0, 0, 0};
  s0.flap_lon = m.extra.flap_per_a1 * init.trim[0];
  s0.flap_lat = m.extra.flap_per_a2 * init.trim[1];
  return s0;
}

Eigen::VectorXd lqr_state_of(const sysid::SimState& s) {
  Eigen::VectorXd v(kLoggedStates + 3);
  for (int i = 0; i < kLoggedStates; ++i) v[i] = s.world[static_cast<std::size_t>(i)];
  v[12] = s.flap_lon, v[13] = s.flap_lat, v[14] = s.gyro;
  return v;
}

// Adds d to the LQR state's entry j of s.
void bump_lqr_state(sysid::SimState& s, int j, double d) {
  if (j < kLoggedStates)
    s.world[static_cast<std::size_t>(j)] += d;
  else if (j == 12)
    s.flap_lon += d;
  else if (j == 13)
    s.flap_lat += d;
  else
    s.gyro += d;
}

// x' = A x + B u: the model's mean step at s0 and the trim with the local fit there held, by central
// differences (yaw's wrapped).
struct HoverLinearisation {
  LqrMatrix a, b;
};

HoverLinearisation linearise_hover(const sysid::IdentifiedModel& model, const sysid::LocalFit& fit,
                                   const sysid::SimState& s0, const Controls& trim) {
  const sysid::ModelStructure& m = model.structure();
  auto step = [&](const sysid::SimState& s, const Controls& a) {
    const sysid::InputVec x = sysid::sim_input(s, a);
    return lqr_state_of(sysid::sim_advance(m, s, a, model.mean_change(fit, x), model.dt()));
  };
  HoverLinearisation lin{LqrMatrix(kLqrStates, kLqrStates), LqrMatrix(kLqrStates, kLqrInputs)};
  for (int j = 0; j < kLqrStates; ++j) {
    sysid::SimState plus = s0, minus = s0;
    const double h = 1e-5;
    bump_lqr_state(plus, j, h);
    bump_lqr_state(minus, j, -h);
    Eigen::VectorXd d = step(plus, trim) - step(minus, trim);
    d[kLqrYawAt] = wrap_angle(d[kLqrYawAt]);
    lin.a.col(j) = d / (2 * h);
  }
  for (int c = 0; c < kLqrInputs; ++c) {
    Controls plus = trim, minus = trim;
    plus[static_cast<std::size_t>(c)] += 1e-5;
    minus[static_cast<std::size_t>(c)] -= 1e-5;
    Eigen::VectorXd d = step(s0, plus) - step(s0, minus);
    d[kLqrYawAt] = wrap_angle(d[kLqrYawAt]);
    lin.b.col(c) = d / 2e-5;
  }
  return lin;
}

// The reward's weights (Eqs 5.9-5.10 and the attitude and rate terms) as Q and R, each action weight at least
// kLqrMinActionWeight so that the Riccati iteration has a positive definite R.
struct LqrWeights {
  LqrMatrix q, r;
};

LqrWeights lqr_weights(const HoverReward& r, double action_factor) {
  LqrWeights w{LqrMatrix::Zero(kLqrStates, kLqrStates), LqrMatrix::Zero(kLqrInputs, kLqrInputs)};
  LqrMatrix& q = w.q;
  for (std::size_t i = 0; i < 3; ++i) {  // x, y, z; their velocities; roll, pitch and yaw rates
    const auto pos = static_cast<Eigen::Index>(logged::x + i),
               vel = static_cast<Eigen::Index>(logged::xdot + i),
               rate = static_cast<Eigen::Index>(logged::roll_rate + i);
    q(pos, pos) = r.alpha_pos[i];
    q(vel, vel) = r.alpha_vel[i];
    // At the level hover body rates are the Euler-angle rates, and the quaternion's vector part half the
    // Euler angles: a judged cost's terms enter Q as their linearisation there.
    q(rate, rate) = r.alpha_rate[i] + r.alpha_body_rate[i];
  }
  q(kLqrRollAt, kLqrRollAt) = r.alpha_attitude[0] + r.alpha_quaternion[0] / 4;
  q(kLqrPitchAt, kLqrPitchAt) = r.alpha_attitude[1] + r.alpha_quaternion[1] / 4;
  q(kLqrYawAt, kLqrYawAt) = r.alpha_yaw + r.alpha_quaternion[2] / 4;
  for (int c = 0; c < kLqrInputs; ++c)
    w.r(c, c) = action_factor * std::max(r.alpha_action[static_cast<std::size_t>(c)],
                                         HoverTrainingOptions::kLqrMinActionWeight);
  return w;
}

// The discounted Riccati recursion to its fixed point, P = Q + g A'PA - g^2 A'PB (R + g B'PB)^-1 B'PA, and
// its gain K (u = -K x) in *k; false when it does not converge.
bool discounted_lqr_gain(const HoverLinearisation& lin, const LqrWeights& w, double gamma, LqrMatrix* k) {
  const LqrMatrix &a_mat = lin.a, &b_mat = lin.b, &q = w.q, &rr = w.r;
  LqrMatrix p = q;
  k->resize(kLqrInputs, kLqrStates);
  bool converged = false;
  for (int it = 0; it < 20000 && !converged; ++it) {
    const LqrMatrix bp = b_mat.transpose() * p;
    *k = (rr + gamma * bp * b_mat).ldlt().solve(gamma * bp * a_mat);
    const LqrMatrix next = q + gamma * a_mat.transpose() * p * (a_mat - b_mat * *k);
    const LqrMatrix sym = 0.5 * (next + next.transpose());
    if (!sym.allFinite()) break;
    converged = (sym - p).norm() <= 1e-10 * std::max(1.0, sym.norm());
    p = sym;
  }
  return converged;
}

double spectral_radius_of(const LqrMatrix& mat) { return mat.eigenvalues().cwiseAbs().maxCoeff(); }

// The hover class's wiring: u = -K x restricted to each channel's inputs (a1..a4 are rows 0..3).
HoverPolicyInit hover_class_gains(const HoverPolicyInit& init, const LqrMatrix& k) {
  const auto at = lqr_column;
  HoverPolicyInit g = init;
  g.k_pos = -k(0, at(logged::x)), g.k_vel = -k(0, at(logged::xdot)), g.k_att = -k(0, at(logged::pitch));
  g.k_pos_lat = -k(1, at(logged::y)), g.k_vel_lat = -k(1, at(logged::ydot)),
  g.k_roll = -k(1, at(logged::roll));
  g.k_alt = -k(2, at(logged::z)), g.k_climb = -k(2, at(logged::zdot));
  g.k_yaw = -k(3, at(logged::yaw)), g.k_yaw_rate = -k(3, at(logged::yaw_rate));
  return g;
}

// The hover class's gains g as a matrix on the LQR's state (u = wired x).
LqrMatrix hover_class_wiring(const HoverPolicyInit& g) {
  const auto at = lqr_column;
  LqrMatrix wired = LqrMatrix::Zero(kLqrInputs, kLqrStates);
  wired(0, at(logged::x)) = g.k_pos, wired(0, at(logged::xdot)) = g.k_vel,
           wired(0, at(logged::pitch)) = g.k_att;
  wired(1, at(logged::y)) = g.k_pos_lat, wired(1, at(logged::ydot)) = g.k_vel_lat,
           wired(1, at(logged::roll)) = g.k_roll;
  wired(2, at(logged::z)) = g.k_alt, wired(2, at(logged::zdot)) = g.k_climb;
  wired(3, at(logged::yaw)) = g.k_yaw, wired(3, at(logged::yaw_rate)) = g.k_yaw_rate;
  return wired;
}

// The integral states I' = I + dt (p' - p*) (x, y, z, yaw rows of the next state) and u += K_i I with
// K_i = K_p / T_i per channel; T_i doubles from `seconds` until the augmented loop is stable (a slow integral
// is safe). Returns the last T_i tried, doubled once more when none was stable, and its radius in *radius.
double stable_integral_seconds(const LqrMatrix& closed, const LqrMatrix& b_mat, const HoverPolicyInit& g,
                               double dt, double seconds, double* radius) {
  constexpr int n = kLqrStates, ni = 4;
  const auto at = lqr_column;
  const std::array<Eigen::Index, ni> error_rows = {at(logged::x), at(logged::y), at(logged::z), kLqrYawAt};
  const std::array<double, ni> k_err = {g.k_pos, g.k_pos_lat, g.k_alt, g.k_yaw};
  for (int doubling = 0; doubling <= 10; ++doubling, seconds *= 2) {
    LqrMatrix aug = LqrMatrix::Zero(n + ni, n + ni);
    aug.topLeftCorner(n, n) = closed;
    for (int c = 0; c < ni; ++c)
      aug.block(0, n + c, n, 1) = b_mat.col(c) * (k_err[static_cast<std::size_t>(c)] / seconds);
    for (int i = 0; i < ni; ++i) {
      aug.block(n + i, 0, 1, n + ni) = dt * aug.block(error_rows[static_cast<std::size_t>(i)], 0, 1, n + ni);
      aug(n + i, n + i) += 1;
    }
    *radius = spectral_radius_of(aug);
    if (*radius < 1) break;
  }
  return seconds;
}

// lqr_hover_init on `model` itself.
LqrStart lqr_hover_init_on(const sysid::IdentifiedModel& model, const HoverTrainingOptions& o) {
  LqrStart out;
  out.init = hover_init_from_model(model);
  out.init.integral_seconds = o.integral_seconds;
  const HoverPolicyInit& init = out.init;
  const sysid::SimState s0 = hover_sim_state(model.structure(), init, o.target);
  const sysid::LocalFit fit = model.regression().fit(sysid::sim_input(s0, init.trim));
  if (fit.singular) {
    out.reason = "the local fit at the hover is singular";
    return out;
  }
  const HoverLinearisation lin = linearise_hover(model, fit, s0, init.trim);
  if (!lin.a.allFinite() || !lin.b.allFinite()) {
    out.reason = "the linearised model is not finite";
    return out;
  }
  const LqrWeights weights = lqr_weights(hover_reward_for(model, o), o.lqr_action_factor);
  const double gamma = std::pow(o.gamma, 50 * model.dt());  // per model step
  LqrMatrix k;
  const bool converged = discounted_lqr_gain(lin, weights, gamma, &k);
  out.open_loop_radius = spectral_radius_of(lin.a);
  if (!converged) {
    out.reason = "the Riccati iteration did not converge";
    return out;
  }
  HoverPolicyInit g = hover_class_gains(init, k);
  const LqrMatrix closed = lin.a + lin.b * hover_class_wiring(g);
  out.spectral_radius = spectral_radius_of(closed);
  if (!(out.spectral_radius < 1)) {
    out.reason = fmt::format(
        "the hover class's share of the LQR gains does not hold the linear model (spectral radius {:.4g})",
        out.spectral_radius);
    return out;
  }
  if (o.integral_seconds > 0) {
    const double seconds =
        stable_integral_seconds(closed, lin.b, g, model.dt(), o.integral_seconds, &out.integral_radius);
    if (!(out.integral_radius < 1)) {
      out.reason = fmt::format(
          "the LQR gains with an integral term as slow as {:.4g} s do not hold the linear model (spectral "
          "radius {:.4g})",
          seconds / 2, out.integral_radius);
      return out;
    }
    g.integral_seconds = out.integral_seconds = seconds;
  }
  out.init = g;
  out.used = true;
  return out;
}

}  // namespace

LqrStart lqr_hover_init(const sysid::IdentifiedModel& model, const HoverTrainingOptions& o) {
  if (!o.lqr_gains_from_alternative) return lqr_hover_init_on(model, o);
  // The other class's linearisation, with the same trim (the same data).
  if (const auto other = model.alternative()) return lqr_hover_init_on(*other, o);
  LqrStart none;
  none.init = hover_init_from_model(model);
  none.reason = "the model records no other model class (identify chose none)";
  return none;
}

}  // namespace pegasus::heli
