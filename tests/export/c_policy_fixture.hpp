#pragma once
// What the C export's tests share (c_policy_test.cpp: the classes bit for bit; c_policy_command_test.cpp: the
// policy files and the command): the fixture, hover policy files, random helicopter states, and bit equality.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>

#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "support/cli_runner.hpp"

namespace pegasus::codegen::c_policy_test {

inline bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

// A hover theta away from the linear start: every tanh path carries weight.
inline Theta perturbed_hover_theta(const heli::HoverPolicy& policy, std::mt19937_64& rng, double spread) {
  std::normal_distribution<double> normal;
  Theta theta = policy.parameters().initial();
  for (std::size_t i = 0; i < theta.size(); ++i) {
    const Parameter& p = policy.parameters()[i];
    theta[i] = std::clamp(theta[i] + spread * p.scale * normal(rng), p.lower, p.upper);
  }
  return theta;
}

inline const heli::HoverPolicyInit kTrimmedInit{.trim = {0.0, 0.036, 0.184, 0.194}};

// `integrator` on: the integral term (38 weights).
// Command limits some channels of a hover file may have (HoverPolicyInit::command_lower/upper): a1 and a3
// limited on both sides, a2 on one, a4 not at all.
inline constexpr heli::Controls kCommandLower{-0.4, -1, -0.25, -1}, kCommandUpper{0.3, 0.6, 0.7, 1};

inline heli::PolicyFile hover_file(std::uint64_t seed, double spread, const heli::SetPoint& target,
                                   const heli::ErrorIntegrator& integrator = {}, bool limited = false) {
  std::mt19937_64 rng(seed);
  heli::HoverPolicyInit init = kTrimmedInit;
  init.integral_seconds = integrator.on() ? 5 : 0;
  if (limited) {
    init.command_lower = kCommandLower;
    init.command_upper = kCommandUpper;
  }
  const heli::HoverPolicy policy(init);
  return heli::hover_policy_file(policy, perturbed_hover_theta(policy, rng, spread), target,
                                 kTrimmedInit.trim, integrator);
}

// Random helicopter states around `around` (m), wide enough to clip, wrap the yaw and turn the body.
inline heli::LoggedState random_state(std::mt19937_64& rng, const heli::SetPoint& around) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return {around.x + 15 * u(rng),
          around.y + 15 * u(rng),
          around.z + 15 * u(rng),
          1.5 * u(rng),
          1.2 * u(rng),
          5.0 * u(rng),
          6 * u(rng),
          6 * u(rng),
          6 * u(rng),
          3 * u(rng),
          3 * u(rng),
          3 * u(rng)};
}

// The manoeuvre class is built into heli's registry (its controller and its C text), as every class the
// export knows, so the fixture registers nothing.
class CPolicyExport : public test_support::TempDirTest {};

}  // namespace pegasus::codegen::c_policy_test
