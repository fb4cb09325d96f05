#include "pegasus/evaluators/horizon.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "pegasus/core/error.hpp"

namespace pegasus {
namespace {

TEST(EpsilonHorizon, MatchesTheThesisFormula) {
  // §4.2.2: H = ceil(log_gamma(eps (1 - gamma) / (2 Rmax))).
  EXPECT_EQ(epsilon_horizon(0.9, 0.1, 1.0), 51);     // log_0.9(0.005) = 50.29
  EXPECT_EQ(epsilon_horizon(0.5, 0.01, 1.0), 9);     // log_0.5(0.0025) = 8.64
  EXPECT_EQ(epsilon_horizon(0.99, 0.01, 1.0), 986);  // log_0.99(5e-5) = 985.4
  for (double gamma : {0.3, 0.9, 0.99, 0.999}) {
    for (double eps : {1e-3, 0.1, 1.0}) {
      const double exact = std::log(eps * (1 - gamma) / 2.0) / std::log(gamma);
      EXPECT_EQ(epsilon_horizon(gamma, eps, 1.0), static_cast<std::int64_t>(std::max(1.0, std::ceil(exact))));
    }
  }
}

TEST(EpsilonHorizon, TruncationErrorIsAtMostHalfEpsilon) {
  for (double gamma : {0.5, 0.9, 0.99}) {
    const double rmax = 3, eps = 0.01;
    const auto h = epsilon_horizon(gamma, eps, rmax);
    EXPECT_LE(std::pow(gamma, static_cast<double>(h)) * rmax / (1 - gamma), eps / 2 * (1 + 1e-12));
    EXPECT_GT(std::pow(gamma, static_cast<double>(h - 1)) * rmax / (1 - gamma), eps / 2);
  }
}

TEST(EpsilonHorizon, IsAtLeastOneStep) { EXPECT_EQ(epsilon_horizon(0.5, 100, 1), 1); }

TEST(EpsilonHorizon, RejectsInputsOutsideTheirRange) {
  EXPECT_THROW(epsilon_horizon(1.0, 0.1, 1), InputError);
  EXPECT_THROW(epsilon_horizon(0.0, 0.1, 1), InputError);
  EXPECT_THROW(epsilon_horizon(NAN, 0.1, 1), InputError);
  EXPECT_THROW(epsilon_horizon(0.9, 0.0, 1), InputError);
  EXPECT_THROW(epsilon_horizon(0.9, 0.1, -1), InputError);
  EXPECT_THROW(epsilon_horizon(1 - 1e-16, 1e-300, 1), InputError);
  try {
    epsilon_horizon(1.5, 0.1, 1);
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "gamma: expected a number in (0, 1), got 1.5");
  }
}

}  // namespace
}  // namespace pegasus
