#include "pegasus/heli/ground_truth.hpp"

#include <cmath>

#include "pegasus/random/normal_quantile.hpp"

namespace pegasus::heli {

std::string crash_reason_name(CrashReason r) {
  switch (r) {
    case CrashReason::kNone:
      return "none";
    case CrashReason::kGround:
      return "ground impact";
    case CrashReason::kAttitude:
      return "attitude limit";
    case CrashReason::kRate:
      return "angular rate limit";
    case CrashReason::kRotorOverload:
      return "rotor overload";
    case CrashReason::kNumerical:
      return "numerical blow-up";
    case CrashReason::kModelSupport:
      return "left the model's support";
  }
  return "unknown";
}

namespace {
double estimate_sigma(const Disturbances& d, int logged_index) {
  const double sig[4] = {d.est_sigma_pos, d.est_sigma_angle, d.est_sigma_vel, d.est_sigma_rate};
  return sig[logged_index / 3];
}
}  // namespace

void Disturbances::start(std::span<const double> p, Vec3& gust_W, LoggedState& estimate_error) const {
  for (int i = 0; i < 3; ++i) gust_W[i] = gust_sigma * normal_quantile(p[static_cast<std::size_t>(i)]);
  for (int i = 0; i < kLoggedStates; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    estimate_error[ui] = estimate_sigma(*this, i) * normal_quantile(p[3 + ui]);
  }
}

void Disturbances::step(double dt, std::span<const double> p, Vec3& gust_W,
                        LoggedState& estimate_error) const {
  const double rho_g = std::exp(-dt / gust_tau);
  const double k_g = gust_sigma * std::sqrt(1 - rho_g * rho_g);
  for (int i = 0; i < 3; ++i)
    gust_W[i] = rho_g * gust_W[i] + k_g * normal_quantile(p[static_cast<std::size_t>(i)]);
  const double rho_e = std::exp(-dt / est_tau);
  const double k_e = std::sqrt(1 - rho_e * rho_e);
  for (int i = 0; i < kLoggedStates; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    estimate_error[ui] =
        rho_e * estimate_error[ui] + estimate_sigma(*this, i) * k_e * normal_quantile(p[3 + ui]);
  }
}

}  // namespace pegasus::heli
