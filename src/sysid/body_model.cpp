#include "pegasus/sysid/body_model.hpp"

#include <fmt/format.h>

#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::sysid {

namespace logged = heli::logged;

using heli::Euler;

void ExtraStateModel::advance(double dt, const Eigen::Vector3d& w_B, const std::array<double, 4>& a,
                              double* flap_lon, double* flap_lat, double* gyro) const {
  const double e = std::exp(-dt / tau_flap);
  const double lon_ss = flap_per_a1 * a[0] + tau_flap * w_B.y();
  const double lat_ss = flap_per_a2 * a[1] - tau_flap * w_B.x();
  *flap_lon = lon_ss + (*flap_lon - lon_ss) * e;
  *flap_lat = lat_ss + (*flap_lat - lat_ss) * e;
  const double eg = std::exp(-dt / gyro_tau);
  *gyro = w_B.z() + (*gyro - w_B.z()) * eg;
}

std::string ModelStructure::describe() const {
  std::string constant;
  for (int j = 0; j < kInputs; ++j)
    if (constant_inputs[static_cast<std::size_t>(j)])
      constant += (constant.empty() ? "" : ", ") + std::string(kInputNames[static_cast<std::size_t>(j)]);
  return fmt::format("{} Hz, {} extra states, {} intercept, {} templates{}", rate_hz,
                     extra_states ? "with" : "without", intercept ? "with" : "without",
                     templates ? "with" : "without",
                     constant.empty() ? "" : ", constant in the data (left out): " + constant);
}

int OutputTemplate::free_count() const {
  int n = 0;
  for (bool f : free) n += f ? 1 : 0;
  return n;
}

std::array<OutputTemplate, kBodyVars> output_templates(const ModelStructure& m) {
  std::array<OutputTemplate, kBodyVars> t{};
  for (int k = 0; k < kBodyVars; ++k) {
    auto& f = t[static_cast<std::size_t>(k)].free;
    f.fill(true);
    if (m.templates) {
      if (k == kRoll || k == kPitch) {
        f.fill(false);  // phi_{t+1} = phi_t + phidot_t dt needs no regression (§5.2.2)
        continue;
      }
      // Attitude acts on the velocities only through gravity (fixed at +-g below) and not at all on the
      // rates: those coefficients are 0 (§5.2.2: "roll should have no direct effect on forward velocity").
      f[kRoll] = f[kPitch] = false;
    }
    if (!m.extra_states) f[kFlapLon] = f[kFlapLat] = f[kGyro] = false;
    if (!m.intercept) f[kOne] = false;
    for (int j = 0; j < kInputs; ++j)
      if (j != kOne && m.constant_inputs[static_cast<std::size_t>(j)]) f[static_cast<std::size_t>(j)] = false;
  }
  return t;
}

BodyVec known_change(const ModelStructure& m, const InputVec& x, double dt) {
  BodyVec d = BodyVec::Zero();
  if (!m.templates) return d;
  const double g = m.gravity;
  d[kRoll] = x[kRollRate] * dt;
  d[kPitch] = x[kPitchRate] * dt;
  // Gravity in the body frame (NED): (-sin theta, sin phi cos theta, cos phi cos theta) g.
  d[kU] = -g * std::sin(x[kPitch]) * dt;
  d[kV] = g * std::sin(x[kRoll]) * std::cos(x[kPitch]) * dt;
  d[kW] = g * std::cos(x[kRoll]) * std::cos(x[kPitch]) * dt;
  return d;
}

BodyVec body_from_log_state(const std::array<double, kLogStates>& s) {
  const Euler e = heli::attitude_of(s);
  const heli::Vec3 v_B = heli::body_from_world(e, heli::velocity_of(s));
  BodyVec b;
  b << e.roll, e.pitch, v_B.x(), v_B.y(), v_B.z(), s[logged::roll_rate], s[logged::pitch_rate],
      s[logged::yaw_rate];
  return b;
}

std::vector<std::array<double, 3>> extra_states_along(const FlightLog& log, const ModelStructure& m) {
  std::vector<std::array<double, 3>> out(log.rows());
  double fl = 0, fr = 0, gy = 0;
  const double dt = log.dt();
  for (std::size_t i = 0; i < log.rows(); ++i) {
    out[i] = {fl, fr, gy};
    const auto& s = log.states[i];
    const auto w_B = heli::body_rates_from_euler_rates(heli::attitude_of(s), heli::euler_rates_of(s));
    m.extra.advance(dt, w_B, log.controls[i], &fl, &fr, &gy);
  }
  return out;
}

std::size_t log_rows_per_model_step(double log_dt, double rate_hz) {
  const double ratio = 1.0 / (rate_hz * log_dt);
  if (!std::isfinite(ratio)) return 0;
  const long k = std::lround(ratio);
  return k >= 1 && std::abs(ratio - static_cast<double>(k)) <= 0.01 ? static_cast<std::size_t>(k) : 0;
}

Dataset build_dataset(const FlightLog& log, const ModelStructure& m) {
  const double log_dt = log.dt();
  const std::size_t step = log_rows_per_model_step(log_dt, m.rate_hz);
  if (step == 0)
    throw InputError(fmt::format("identify: the log's rate {} Hz is not a multiple of the model rate {} Hz",
                                 1.0 / log_dt, m.rate_hz));
  const auto extra = extra_states_along(log, m);
  const std::size_t n = log.rows() >= step + 1 ? (log.rows() - 1) / step : 0;
  Dataset d;
  d.dt = log_dt * static_cast<double>(step);
  d.x.resize(static_cast<Eigen::Index>(n), kInputs);
  d.y.resize(static_cast<Eigen::Index>(n), kBodyVars);
  d.time.resize(n);
  for (std::size_t r = 0; r < n; ++r) {
    const std::size_t i = r * step;
    const BodyVec b0 = body_from_log_state(log.states[i]);
    const BodyVec b1 = body_from_log_state(log.states[i + step]);
    InputVec x;
    x.head<kBodyVars>() = b0;
    const auto& [flap_lon, flap_lat, gyro] = extra[i];
    x[kFlapLon] = flap_lon;
    x[kFlapLat] = flap_lat;
    x[kGyro] = gyro;
    for (int c = 0; c < 4; ++c) {
      double sum = 0;
      for (std::size_t j = i; j < i + step; ++j) sum += log.controls[j][static_cast<std::size_t>(c)];
      x[kA1 + c] = sum / static_cast<double>(step);
    }
    x[kOne] = 1.0;
    const auto ri = static_cast<Eigen::Index>(r);
    d.x.row(ri) = x.transpose();
    d.y.row(ri) = (b1 - b0 - known_change(m, x, d.dt)).transpose();
    d.time[r] = log.time[i];
  }
  return d;
}

std::array<bool, kInputs> constant_inputs(const Dataset& data) {
  std::array<bool, kInputs> out{};
  if (data.rows() == 0) return out;
  for (int j = 0; j < kInputs; ++j)
    out[static_cast<std::size_t>(j)] = j != kOne && (data.x.col(j).array() == data.x(0, j)).all();
  return out;
}

}  // namespace pegasus::sysid
