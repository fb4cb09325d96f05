#pragma once
// Deriving seeds from seeds. Every place that turns (run seed, something) into a new seed calls mix_seed,
// so that two uses of one run seed (a flight and a scenario, a stage's optimizer and the next stage's)
// draw from unrelated streams; the counter-based generator itself is in counter_rng.hpp.
#include <cstdint>

namespace pegasus {

// SplitMix64 finaliser: decorrelates (seed, counter) pairs into a new 64-bit seed.
inline std::uint64_t mix_seed(std::uint64_t seed, std::uint64_t counter) {
  std::uint64_t z = seed + 0x9e3779b97f4a7c15ull * (counter + 1);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace pegasus
