#pragma once
// The cross-validation window that identification and the noise fit share (internal to src/sysid).
#include <Eigen/Core>
#include <utility>

#include "pegasus/sysid/body_model.hpp"

namespace pegasus::sysid::detail {

// The rows [lo, hi) within window/2 of row i's time (the data are in time order).
std::pair<Eigen::Index, Eigen::Index> window_rows(const Dataset& d, Eigen::Index i, double window_s);

}  // namespace pegasus::sysid::detail
