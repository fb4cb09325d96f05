#pragma once
// Pieces shared by the built-in ground truths (aircraft.cpp, quadrotor.cpp).
#include <cmath>

#include "pegasus/heli/ground_truth.hpp"

namespace pegasus::heli {

// The classical Runge-Kutta weighting (k1 + 2 k2 + 2 k3 + k4) / 6 of each part of a derivative, in this order
// of operations.
template <class T>
T rk4_mean(const T& k1, const T& k2, const T& k3, const T& k4) {
  return (k1 + 2 * k2 + 2 * k3 + k4) / 6;
}

// The crashes every rigid body shares, checked in this order: a state that is not finite, the ground (z >=
// 0), roll or pitch beyond max_tilt_rad, a body rate beyond max_rate_rad_s.
inline CrashReason rigid_body_crash(const LoggedState& truth, const Euler& attitude, const Vec3& w_B,
                                    double max_tilt_rad, double max_rate_rad_s) {
  for (double v : truth)
    if (!std::isfinite(v)) return CrashReason::kNumerical;
  if (truth[logged::z] >= 0) return CrashReason::kGround;
  if (std::abs(attitude.roll) > max_tilt_rad || std::abs(attitude.pitch) > max_tilt_rad)
    return CrashReason::kAttitude;
  if (w_B.cwiseAbs().maxCoeff() > max_rate_rad_s) return CrashReason::kRate;
  return CrashReason::kNone;
}

}  // namespace pegasus::heli
