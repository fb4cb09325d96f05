#pragma once
// The plain transcription of Randlov and Alstrom's bike.c step (their equations, constants and update
// order, one statement per line of theirs, every function from the C library), kept as the reference the
// fast Bicycle::step must match and is benchmarked against.
#include <cmath>
#include <numbers>

#include "pegasus/envs/bicycle.hpp"

namespace pegasus::bicycle_reference {

inline BicycleState step(const Bicycle& bike, const BicycleState& s, double T, double d, double p) {
  using K = BicycleConstants;
  using bicycle_detail::sgn;
  constexpr double pi = std::numbers::pi;
  const double dt = K::dt, v = K::v, g = K::g, c = K::c, h = K::h, Md = K::Md, M = K::M, R = K::R, l = K::l;
  const double sigma_dot = K::sigma_dot, I_bike = K::I_bike, I_dc = K::I_dc, I_dv = K::I_dv, I_dl = K::I_dl;

  T = std::clamp(T, -2.0, 2.0);
  d = std::clamp(d, -0.02, 0.02) + bike.options().noise * (2.0 * p - 1.0);
  double omega = s.omega, omega_dot = s.omega_dot, theta = s.theta, theta_dot = s.theta_dot;
  double xf = s.xf, yf = s.yf, xb = s.xb, yb = s.yb, psi = s.psi;

  double rCM, rf, rb;
  if (theta == 0) {
    rCM = rf = rb = 9999999;
  } else {
    rCM = std::sqrt(std::pow(l - c, 2) + l * l / std::pow(std::tan(theta), 2));
    rf = l / std::fabs(std::sin(theta));
    rb = l / std::fabs(std::tan(theta));
  }
  const double phi = omega + std::atan(d / h);
  const double omega_d_dot =
      (h * M * g * std::sin(phi) -
       std::cos(phi) * (I_dc * sigma_dot * theta_dot +
                        sgn(theta) * v * v * (Md * R * (1.0 / rf + 1.0 / rb) + M * h / rCM))) /
      I_bike;
  const double theta_d_dot = (T - I_dv * omega_dot * sigma_dot) / I_dl;

  omega_dot += omega_d_dot * dt;
  omega += omega_dot * dt;
  theta_dot += theta_d_dot * dt;
  theta += theta_dot * dt;
  if (std::fabs(theta) > 1.3963) theta = sgn(theta) * 1.3963;

  double temp = v * dt / (2 * rf);
  if (temp > 1)
    temp = sgn(psi + theta) * pi / 2;
  else
    temp = sgn(psi + theta) * std::asin(temp);
  xf += v * dt * (-std::sin(psi + theta + temp));
  yf += v * dt * std::cos(psi + theta + temp);

  temp = v * dt / (2 * rb);
  if (temp > 1)
    temp = sgn(psi) * pi / 2;
  else
    temp = sgn(psi) * std::asin(temp);
  xb += v * dt * (-std::sin(psi + temp));
  yb += v * dt * (std::cos(psi + temp));

  temp = std::sqrt((xf - xb) * (xf - xb) + (yf - yb) * (yf - yb));
  if (std::fabs(temp - l) > 0.01) {
    xb += (xb - xf) * (l - temp) / temp;
    yb += (yb - yf) * (l - temp) / temp;
  }
  temp = yf - yb;
  if ((xf == xb) && (temp < 0)) {
    psi = pi;
  } else {
    if (temp > 0)
      psi = std::atan((xb - xf) / temp);
    else
      psi = sgn(xb - xf) * (pi / 2) - std::atan(temp / (xb - xf));
  }

  BicycleState n;
  n.omega = omega;
  n.omega_dot = omega_dot;
  n.theta = theta;
  n.theta_dot = theta_dot;
  n.xf = xf;
  n.yf = yf;
  n.xb = xb;
  n.yb = yb;
  n.psi = psi;
  n.status = std::fabs(omega) > pi / 15 ? BicycleState::kFallen : BicycleState::kRiding;
  if (n.status == BicycleState::kRiding && !bike.goal().at_infinity) {
    const double gx = xf - bike.goal().x, gy = yf - bike.goal().y;
    if (gx * gx + gy * gy <= bike.goal().radius * bike.goal().radius) n.status = BicycleState::kAtGoal;
  }
  return n;
}

}  // namespace pegasus::bicycle_reference
