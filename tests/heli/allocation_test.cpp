// Stepping the ground-truth aircraft allocates nothing (STYLE.md: no heap allocation in a step).
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <new>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/random/counter_rng.hpp"

long pegasus_test_allocation_count();  // allocation_counter_test.cpp

namespace {

TEST(HeliAllocation, AircraftStepDoesNotAllocate) {
  const pegasus::heli::Aircraft heli;
  std::array<double, pegasus::heli::Aircraft::kInitialNoise> p0;
  p0.fill(0.5);
  auto s = heli.initial_state(p0);
  pegasus::UniformStream rng(3, 0);
  std::array<double, pegasus::heli::Aircraft::kStepNoise> p{};
  const long before = pegasus_test_allocation_count();
  for (int t = 0; t < 2000; ++t) {
    for (double& u : p) u = rng.next();
    s = heli.step(s, heli.hover_trim().controls, p);
  }
  const auto obs = heli.observe(s);
  EXPECT_EQ(pegasus_test_allocation_count(), before);
  EXPECT_TRUE(std::isfinite(obs[0]));
}

}  // namespace
