#pragma once
// Reading ULog's little-endian values from bytes (internal to src/logs: ulog.cpp parses, ulog_values.cpp
// decodes topics' fields).
#include <cstdint>
#include <cstring>

#include "pegasus/logs/ulog.hpp"

namespace pegasus::logs::detail {

template <typename T>
T load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

// One basic value of `type` at p, as a double.
double decode(UlogType type, const std::uint8_t* p);

}  // namespace pegasus::logs::detail
