#pragma once
// A double's bits, for tests that promise bit-identical results (EXPECT_EQ on doubles would let -0.0 equal
// 0.0 and never let a NaN equal itself).
#include <bit>
#include <cstdint>

namespace pegasus::test_support {

inline std::uint64_t Bits(double x) { return std::bit_cast<std::uint64_t>(x); }

}  // namespace pegasus::test_support
