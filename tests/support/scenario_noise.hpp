#pragma once
// Noise numbers at the middle of their range (every uniform draw 0.5): the median draw of each of a
// simulator's disturbances, for tests of its deterministic parts.
#include <cstddef>
#include <vector>

namespace pegasus::test_support {

inline std::vector<double> mid_range_noise(int n) {
  return std::vector<double>(static_cast<std::size_t>(n), 0.5);
}

}  // namespace pegasus::test_support
