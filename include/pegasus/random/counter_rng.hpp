#pragma once
// Counter-based uniform random numbers (Philox4x32-10 from Random123). A number is a pure function of
// (seed, counter), so any thread or process can compute any scenario's noise directly: random access,
// nothing stored, identical everywhere (thesis §4.4; ARCHITECTURE.md determinism rule 1).
#include <Random123/philox.h>

#include <array>
#include <cstdint>

namespace pegasus {

// Which family of numbers a counter belongs to, so that unrelated uses of one seed never collide.
enum class RngDomain : std::uint32_t {
  kStepNoise = 0,     // p_t of scenario i: counter (i, t, block)
  kInitialNoise = 1,  // the uniforms that draw s0 of scenario i
  kModelHash = 2,     // per-(s, a) keys of the hashed model wrapper (§4.6)
  kStream = 3,        // sequential streams (Monte Carlo, hill climbing, trajectory trees)
  kPermutation = 4,   // stratification permutations
};

class CounterRng {
 public:
  explicit CounterRng(std::uint64_t seed)
      : key_{{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}} {}

  // Two uniforms in the open interval (0, 1), each with 53 random bits.
  std::array<double, 2> uniform2(RngDomain domain, std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    const r123::Philox4x32::ctr_type ctr = {{a, b, c, static_cast<std::uint32_t>(domain)}};
    const auto r = philox_(ctr, key_);
    return {to_unit(r[0], r[1]), to_unit(r[2], r[3])};
  }

  // Raw 64 random bits.
  std::uint64_t bits64(RngDomain domain, std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    const r123::Philox4x32::ctr_type ctr = {{a, b, c, static_cast<std::uint32_t>(domain)}};
    const auto r = philox_(ctr, key_);
    return (static_cast<std::uint64_t>(r[0]) << 32) | r[1];
  }

  // 53 bits -> (0, 1]: the midpoint of one of 2^53 equal cells, rounded to a double, so 0 never occurs; the
  // top cell's midpoint 1 - 2^-54 rounds to 1 (a tie, to even), once in 2^53 draws. Every user of a uniform
  // takes 1 (normal_quantile clamps it to the open interval; next_below to n - 1). A check mapping it below 1
  // measured 11-15% slower on the bicycle's scenario-noise benchmarks (A/B, medians of 5), so there is none.
  static double to_unit(std::uint32_t hi, std::uint32_t lo) {
    const std::uint64_t x = ((static_cast<std::uint64_t>(hi) << 32) | lo) >> 11;
    return (static_cast<double>(x) + 0.5) * 0x1.0p-53;
  }

 private:
  r123::Philox4x32::key_type key_;
  r123::Philox4x32 philox_;
};

// A sequential stream of uniforms drawn from one counter family; its whole state is (seed, stream,
// position), so it can be checkpointed and resumed exactly.
class UniformStream {
 public:
  UniformStream(std::uint64_t seed, std::uint32_t stream, std::uint64_t position = 0)
      : rng_(seed), seed_(seed), stream_(stream), position_(position) {}

  double next() {
    const std::uint64_t block = position_ / 2;
    if (block != cached_block_) {  // one Philox call yields two uniforms
      cached_ = rng_.uniform2(RngDomain::kStream, static_cast<std::uint32_t>(block),
                              static_cast<std::uint32_t>(block >> 32), stream_);
      cached_block_ = block;
    }
    return cached_[position_++ % 2];
  }
  // Uniform integer in [0, n), n >= 1 (multiply-shift; the bias is below 2^-40 for n < 2^13).
  std::uint64_t next_below(std::uint64_t n) {
    const double u = next();
    const auto k = static_cast<std::uint64_t>(u * static_cast<double>(n));
    return k < n ? k : n - 1;
  }

  std::uint64_t seed() const { return seed_; }
  std::uint32_t stream() const { return stream_; }
  std::uint64_t position() const { return position_; }

 private:
  CounterRng rng_;
  std::uint64_t seed_;
  std::uint32_t stream_;
  std::uint64_t position_;
  std::uint64_t cached_block_ = ~std::uint64_t{0};
  std::array<double, 2> cached_{};
};

}  // namespace pegasus
