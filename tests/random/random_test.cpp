// The random folder: the counter-based generator and its streams, the learners' block stream (whose vector
// paths must equal Random123's scalar Philox), seed derivation, and the normal quantile.
#include <Random123/philox.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include "pegasus/core/instruction_set.hpp"
#include "pegasus/random/block_stream.hpp"
#include "pegasus/random/counter_rng.hpp"
#include "pegasus/random/normal_quantile.hpp"
#include "pegasus/random/seed.hpp"

namespace pegasus {
namespace {

// A stream's whole state is (seed, stream, position): one started at position p continues exactly where
// one that drew p numbers is, which is what checkpoints rely on.
TEST(UniformStream, ResumesFromItsPositionAndStaysInsideTheOpenInterval) {
  UniformStream a(7, 2);
  std::vector<double> xs(301);
  for (auto& x : xs) x = a.next();
  for (const std::uint64_t start : {1u, 2u, 3u, 150u, 299u}) {
    UniformStream b(7, 2, start);
    for (std::uint64_t i = start; i < xs.size(); ++i) ASSERT_EQ(b.next(), xs[i]) << start;
  }
  EXPECT_EQ(a.position(), 301u);
  // The extremes of 53 bits: the bottom cell's midpoint, and the top one's, which rounds to 1 (a tie, to
  // even); the cell below the top stays below 1. normal_quantile takes both ends.
  EXPECT_EQ(CounterRng::to_unit(0, 0), 0x1.0p-54);
  EXPECT_EQ(CounterRng::to_unit(0xffffffffu, 0xffffffffu), 1.0);
  EXPECT_EQ(CounterRng::to_unit(0xffffffffu, 0xfffff7ffu), 1.0 - 0x1.0p-52);
  EXPECT_TRUE(std::isfinite(normal_quantile(CounterRng::to_unit(0xffffffffu, 0xffffffffu))));
  EXPECT_TRUE(std::isfinite(normal_quantile(CounterRng::to_unit(0, 0))));
}

// SplitMix64's finaliser is a bijection of 64-bit words and the counter enters as seed + golden * (c + 1), so
// one seed's derived seeds never repeat for distinct counters.
TEST(MixSeed, DistinctCountersGiveDistinctSeeds) {
  std::set<std::uint64_t> seen;
  for (std::uint64_t c = 0; c < 100000; ++c) seen.insert(mix_seed(42, c));
  EXPECT_EQ(seen.size(), 100000u);
  EXPECT_NE(mix_seed(42, 0), mix_seed(43, 0));
}

TEST(BlockUniformStream, IsAPureFunctionOfSeedStreamAndPosition) {
  BlockUniformStream a(42, 3);
  std::vector<double> xs(1000);
  for (auto& x : xs) x = a.next();
  EXPECT_EQ(a.position(), 1000u);
  for (std::uint64_t start : {0u, 1u, 63u, 64u, 65u, 517u}) {
    BlockUniformStream b(42, 3, start);
    for (std::uint64_t i = start; i < 1000; ++i) ASSERT_EQ(b.next(), xs[i]) << start;
  }
  BlockUniformStream other_stream(42, 4), other_seed(43, 3);
  EXPECT_NE(other_stream.next(), xs[0]);
  EXPECT_NE(other_seed.next(), xs[0]);
  double mean = 0.0;
  for (double x : xs) {
    EXPECT_GT(x, 0.0);
    EXPECT_LT(x, 1.0);
    mean += x / 1000.0;
  }
  EXPECT_NEAR(mean, 0.5, 0.03);
}

// The vector Philox paths must give Random123's scalar numbers bit for bit: BlockUniformStream's numbers,
// and so every learner's results, may not depend on the CPU.
TEST(BlockUniformStream, VectorPhiloxPathsMatchScalarPhiloxBitForBit) {
  const r123::Philox4x32 philox;
  for (const std::uint64_t seed : {0ull, 42ull, 0xfedcba9876543210ull}) {
    for (const std::uint64_t first : {0ull, 5ull, 0xffffffe0ull, 0x1234567890ull}) {
      // Counters crossing 2^32 exercise the second counter word; odd counts exercise the tails.
      for (const int calls : {1, 3, 4, 7, 8, 15, 16, 31, 32, 33, 64, 67}) {
        std::vector<double> want(static_cast<std::size_t>(4 * calls));
        const r123::Philox4x32::key_type key = {
            {static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}};
        for (int j = 0; j < calls; ++j) {
          const std::uint64_t c = first + static_cast<std::uint64_t>(j);
          const auto r = philox(
              {{static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(c >> 32), 9u, kBlockStreamDomain}},
              key);
          for (int w = 0; w < 4; ++w)
            want[static_cast<std::size_t>(4 * j + w)] =
                (static_cast<double>(r[static_cast<std::size_t>(w)]) + 0.5) * 0x1.0p-32;
        }
        for (const InstructionSet path : supported_instruction_sets()) {
          std::vector<double> got(want.size(), -1.0);
          detail::philox_uniforms(path, key[0], key[1], first, 9u, kBlockStreamDomain, calls, got.data());
          for (std::size_t i = 0; i < want.size(); ++i)
            ASSERT_EQ(got[i], want[i]) << "path " << instruction_set_name(path) << " seed " << seed
                                       << " first " << first << " calls " << calls << " index " << i;
        }
      }
    }
  }
  // And the stream itself (whatever path this CPU picks) is the scalar Philox stream.
  BlockUniformStream s(77, 5, 3);
  const auto r = philox({{0u, 0u, 5u, kBlockStreamDomain}}, r123::Philox4x32::key_type{{77u, 0u}});
  EXPECT_EQ(s.next(), (static_cast<double>(r[3]) + 0.5) * 0x1.0p-32);
  const auto r1 = philox({{1u, 0u, 5u, kBlockStreamDomain}}, r123::Philox4x32::key_type{{77u, 0u}});
  EXPECT_EQ(s.next(), (static_cast<double>(r1[0]) + 0.5) * 0x1.0p-32);
}

TEST(NormalQuantile, InvertsTheCdf) {
  for (double u : {1e-12, 1e-6, 0.01, 0.024, 0.3, 0.5, 0.7, 0.976, 0.999, 1 - 1e-9}) {
    const double x = normal_quantile(u);
    EXPECT_NEAR(0.5 * std::erfc(-x / std::numbers::sqrt2), u, 1e-14 + 1e-12 * u) << u;
  }
  EXPECT_DOUBLE_EQ(normal_quantile(0.5), 0.0);
}

}  // namespace
}  // namespace pegasus
