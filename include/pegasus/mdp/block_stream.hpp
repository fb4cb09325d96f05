#pragma once
// A fast sequential stream of uniforms for tabular learners, drop-in for UniformStream (next(),
// next_below(), seed/stream/position). Like UniformStream it is a pure function of (seed, stream,
// position) through Philox4x32-10 (thesis §4.4 determinism: checkpointable, identical on every thread),
// but it keeps all 128 bits of each Philox call as four 32-bit uniforms and computes them a block at a
// time, which is what lets Sarsa's inner loop reach tens of millions of steps per second. 32 bits of
// resolution are ample for exploration and transition draws (probabilities in the models are multiples of
// 1/20 and 1/|A|).
//
// Its counters use the fourth Philox word kBlockStreamDomain, outside the values of RngDomain, so its
// numbers never coincide with the scenario generator's for the same seed.
#include <Random123/philox.h>

#include <array>
#include <cstdint>

namespace pegasus {

inline constexpr std::uint32_t kBlockStreamDomain = 0x4d445030u;  // "MDP0"

class BlockUniformStream {
 public:
  static constexpr int kCallsPerBlock = 16;
  static constexpr int kBlock = 4 * kCallsPerBlock;

  BlockUniformStream(std::uint64_t seed, std::uint32_t stream, std::uint64_t position = 0)
      : key_{{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32)}},
        seed_(seed),
        stream_(stream) {
    const std::uint64_t call = position / 4;
    next_call_ = call - call % kCallsPerBlock;
    refill();
    index_ = static_cast<int>(position - next_call_ * 4 + static_cast<std::uint64_t>(kBlock));
  }

  // Uniform in the open interval (0, 1): the midpoint of one of 2^32 equal cells.
  double next() {
    if (index_ == kBlock) refill();
    return buffer_[static_cast<std::size_t>(index_++)];
  }
  // Uniform integer in [0, n), n >= 1.
  std::uint64_t next_below(std::uint64_t n) {
    const auto k = static_cast<std::uint64_t>(next() * static_cast<double>(n));
    return k < n ? k : n - 1;
  }

  std::uint64_t seed() const { return seed_; }
  std::uint32_t stream() const { return stream_; }
  std::uint64_t position() const { return (next_call_ - kCallsPerBlock) * 4 + static_cast<std::uint64_t>(index_); }

 private:
  // Out of line, so that next() stays small enough to inline into a learner's step.
  [[gnu::noinline]] void refill() {
    r123::Philox4x32 philox;
    for (int j = 0; j < kCallsPerBlock; ++j) {
      const std::uint64_t c = next_call_ + static_cast<std::uint64_t>(j);
      const r123::Philox4x32::ctr_type ctr = {
          {static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(c >> 32), stream_, kBlockStreamDomain}};
      const auto r = philox(ctr, key_);
      for (int w = 0; w < 4; ++w)
        buffer_[static_cast<std::size_t>(4 * j + w)] = (static_cast<double>(r[static_cast<std::size_t>(w)]) + 0.5) * 0x1.0p-32;
    }
    next_call_ += kCallsPerBlock;
    index_ = 0;
  }

  r123::Philox4x32::key_type key_;
  std::uint64_t seed_;
  std::uint32_t stream_;
  std::uint64_t next_call_ = 0;  // first Philox call of the next block
  int index_ = 0;
  std::array<double, kBlock> buffer_{};
};

}  // namespace pegasus
