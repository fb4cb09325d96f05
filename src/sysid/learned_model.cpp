#include "pegasus/sysid/learned_model.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "pegasus/random/normal_quantile.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::sysid {

namespace logged = heli::logged;

int refit_steps_at(double step_rate_hz) {
  return std::max(1, static_cast<int>(std::lround(kRefitSeconds * step_rate_hz)));
}

bool LearnedModelOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = std::string("learned model: ") + what;
    return false;
  };
  if (!(dt > 0)) return fail("dt must be positive");
  if (refit_every < 1) return fail("refit_every must be >= 1");
  if (!(support_bandwidths > 0)) return fail("support_bandwidths must be positive");
  if (!(start_pos_sigma >= 0 && start_vel_sigma >= 0)) return fail("start sigmas must be >= 0");
  if (!(max_position_error_m > 0 && max_speed_mps > 0 && max_rate_radps > 0))
    return fail("the envelope's limits must be positive");
  std::string inner;
  if (!disturbance.IsValid(&inner)) {
    if (error) *error = "learned model: " + inner;
    return false;
  }
  return true;
}

LearnedHeliModel::LearnedHeliModel(std::shared_ptr<const IdentifiedModel> model, LearnedModelOptions options)
    : model_(std::move(model)), options_(options) {
  std::string error;
  if (!options_.IsValid(&error)) throw std::invalid_argument(error);
  if (!model_) throw std::invalid_argument("learned model: no identified model");
  min_weight_ = std::exp(-0.5 * options_.support_bandwidths * options_.support_bandwidths);
  const NoiseCorrelation& c = model_->noise_correlation();
  colored_ = options_.noise && (c.share.array() > 0).any();
  const double f = options_.dt / model_->dt();  // model steps per step
  const double n = 1 / f;                       // steps per model step
  for (int k = 0; k < kBodyVars; ++k) {
    rho_step_[k] = std::pow(c.rho[k], f);
    // A stationary AR(1) of per-step variance v and correlation r summed over n steps has the variance
    // v (n + 2 sum_{j=1}^{n-1} (n - j) r^j): v is chosen so that this is share * var.
    double sum_factor = n;
    for (int j = 1; j < static_cast<int>(std::ceil(n)); ++j)
      sum_factor += 2 * (n - j) * std::pow(rho_step_[k], j);
    colored_scale_[k] = c.share[k] / sum_factor;
    // The logged states' own error (its AR(1) and white shares) is not the aircraft's motion: not simulated.
    white_scale_[k] = c.white_share(k) * f;
  }
}

ActionSpace LearnedHeliModel::action_space() const {
  return ActionSpace::box({-1, -1, -1, -1}, {1, 1, 1, 1});
}

LearnedHeliModel::State LearnedHeliModel::initial_state(std::span<const double> p0) const {
  State s;
  s.sim.world = options_.start;
  for (std::size_t i = 0; i < 3; ++i) {
    s.sim.world[i] += options_.start_pos_sigma * normal_quantile(p0[i]);
    s.sim.world[6 + i] += options_.start_vel_sigma * normal_quantile(p0[3 + i]);
  }
  if (colored_)
    for (int k = 0; k < kBodyVars; ++k)
      s.colored[k] = std::sqrt(model_->sigma2()[k] * colored_scale_[k]) *
                     normal_quantile(p0[static_cast<std::size_t>(6 + k)]);
  // The wind's draws come after the model's own (see the header).
  const Disturbance& d = options_.disturbance;
  auto next = static_cast<std::size_t>(own_initial_noise_dim());
  s.wind = d.wind;
  if (d.wind_sigma > 0)
    for (std::size_t i = 0; i < 2; ++i) s.wind[i] += d.wind_sigma * normal_quantile(p0[next++]);
  if (gusty())
    for (std::size_t i = 0; i < 3; ++i) s.gust[i] = d.gust_sigma * normal_quantile(p0[next++]);
  return s;
}

std::array<double, 3> LearnedHeliModel::air_of(const State& s) const {
  return {s.wind[0] + s.gust[0], s.wind[1] + s.gust[1], s.wind[2] + s.gust[2]};
}

bool LearnedHeliModel::outside_envelope(const SimState& s) const {
  const auto& w = s.world;
  bool bad =
      std::abs(w[logged::roll]) > options_.max_tilt_rad || std::abs(w[logged::pitch]) > options_.max_tilt_rad;
  for (double v : w) bad = bad || !std::isfinite(v);
  if (bad) return true;
  const auto norm3 = [&](std::size_t at, const std::array<double, 3>& about) {
    return std::hypot(w[at] - about[0], w[at + 1] - about[1], w[at + 2] - about[2]);
  };
  const std::array<double, 3> set_point{options_.start[logged::x], options_.start[logged::y],
                                        options_.start[logged::z]};
  if (norm3(logged::x, set_point) > options_.max_position_error_m) return true;
  if (norm3(logged::xdot, {0, 0, 0}) > options_.max_speed_mps) return true;
  for (std::size_t i = 0; i < 3; ++i)
    if (std::abs(w[logged::roll_rate + i]) > options_.max_rate_radps) return true;
  return false;
}

LearnedHeliModel::State LearnedHeliModel::step(const State& s, const Action& a_in,
                                               std::span<const double> p) const {
  if (s.crashed) return s;
  State n = s;
  Action a;
  for (std::size_t c = 0; c < 4; ++c) a[c] = std::clamp(a_in[c], -1.0, 1.0);
  // In wind the calm model steps the motion relative to the air, and the air frame moves on at the wind's
  // velocity: the regression sees the airspeed, position and velocity come back to the ground.
  const bool calm = options_.disturbance.calm();
  SimState relative = s.sim;
  const std::array<double, 3> air = calm ? std::array<double, 3>{0, 0, 0} : air_of(s);
  if (!calm)
    for (std::size_t i = 0; i < 3; ++i) relative.world[logged::xdot + i] -= air[i];
  const InputVec x = sim_input(relative, a);
  if (s.step % options_.refit_every == 0) {
    const LocalFit fit = model_->regression().fit(x);
    if (fit.singular || fit.max_weight < min_weight_) {
      n.crashed = true;
      return n;
    }
    n.beta = fit.beta;
    n.variance = model_->predictive_variance(fit);
  }
  const double f = options_.dt / model_->dt();
  BodyVec delta = known_change(model_->structure(), x, options_.dt);
  for (int k = 0; k < kBodyVars; ++k) {
    delta[k] += f * n.beta[static_cast<std::size_t>(k)].dot(x);
    if (colored_) {
      const double rho = rho_step_[k];
      n.colored[k] = rho * s.colored[k] + std::sqrt(n.variance[k] * colored_scale_[k] * (1 - rho * rho)) *
                                              normal_quantile(p[static_cast<std::size_t>(kBodyVars + k)]);
      delta[k] +=
          std::sqrt(n.variance[k] * white_scale_[k]) * normal_quantile(p[static_cast<std::size_t>(k)]) +
          n.colored[k];
    } else if (options_.noise) {
      delta[k] += std::sqrt(n.variance[k] * f) * normal_quantile(p[static_cast<std::size_t>(k)]);
    }
  }
  n.sim = sim_advance(model_->structure(), relative, a, delta, options_.dt);
  if (!calm)
    for (std::size_t i = 0; i < 3; ++i) {
      n.sim.world[logged::xdot + i] += air[i];
      n.sim.world[logged::x + i] += options_.dt * air[i];
    }
  n.step = s.step + 1;
  if (gusty()) {
    const Disturbance& d = options_.disturbance;
    const double rho = std::exp(-options_.dt / d.gust_tau_s),
                 innovation = d.gust_sigma * std::sqrt(1 - rho * rho);
    const auto at = static_cast<std::size_t>(own_noise_dim());
    for (std::size_t i = 0; i < 3; ++i) n.gust[i] = rho * s.gust[i] + innovation * normal_quantile(p[at + i]);
  }
  if (outside_envelope(n.sim)) n.crashed = true;
  return n;
}

}  // namespace pegasus::sysid
