#pragma once
// A flight log read at a model's rate, as the predictions and the noise filter step along it (internal to
// src/sysid).
#include <fmt/format.h>

#include <array>
#include <cstddef>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::sysid::detail {

// A log at a model's rate: its rows per model step and the extra states along it.
struct LogAtRate {
  std::size_t step;  // log rows per model step
  std::vector<std::array<double, 3>> extra;
};

// Log rows per model step of dt; InputError unless the log's rate is a multiple of the model's.
inline std::size_t rows_per_step(double dt, const FlightLog& log) {
  const std::size_t k = log_rows_per_model_step(log.dt(), 1 / dt);
  if (k == 0)
    throw InputError(fmt::format("the test log's rate {} Hz is not a multiple of the model rate {} Hz",
                                 1 / log.dt(), 1 / dt));
  return k;
}

inline LogAtRate log_at_rate(const IdentifiedModel& model, const FlightLog& log) {
  return {rows_per_step(model.dt(), log), extra_states_along(log, model.structure())};
}

// The simulation's state at log row r: the logged state and the extra states along the log.
inline SimState sim_state_at(const FlightLog& log, const LogAtRate& lr, std::size_t r) {
  SimState s;
  s.world = log.states[r];
  const auto& [flap_lon, flap_lat, gyro] = lr.extra[r];
  s.flap_lon = flap_lon;
  s.flap_lat = flap_lat;
  s.gyro = gyro;
  return s;
}

// The mean of the k controls from log row `row`.
inline std::array<double, 4> mean_controls(const FlightLog& log, std::size_t row, std::size_t k) {
  std::array<double, 4> a{};
  for (std::size_t j = row; j < row + k; ++j)
    for (std::size_t c = 0; c < 4; ++c) a[c] += log.controls[j][c];
  for (double& v : a) v /= static_cast<double>(k);
  return a;
}

}  // namespace pegasus::sysid::detail
