#include "pegasus/sysid/learned_model.hpp"

#include <cmath>
#include <stdexcept>

#include "pegasus/heli/frames.hpp"
#include "pegasus/random/normal_quantile.hpp"

namespace pegasus::sysid {

namespace logged = heli::logged;

bool LearnedModelOptions::IsValid(std::string* error) const {
  auto fail = [&](const char* what) {
    if (error) *error = std::string("learned model: ") + what;
    return false;
  };
  if (!(dt > 0)) return fail("dt must be positive");
  if (refit_every < 1) return fail("refit_every must be >= 1");
  if (!(support_bandwidths > 0)) return fail("support_bandwidths must be positive");
  if (!(start_pos_sigma >= 0 && start_vel_sigma >= 0)) return fail("start sigmas must be >= 0");
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
  return s;
}

LearnedHeliModel::State LearnedHeliModel::step(const State& s, const Action& a_in,
                                               std::span<const double> p) const {
  if (s.crashed) return s;
  State n = s;
  Action a;
  for (std::size_t c = 0; c < 4; ++c) a[c] = std::clamp(a_in[c], -1.0, 1.0);
  const InputVec x = sim_input(s.sim, a);
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
  n.sim = sim_advance(model_->structure(), s.sim, a, delta, options_.dt);
  n.step = s.step + 1;
  bool bad = std::abs(n.sim.world[logged::roll]) > options_.max_tilt_rad ||
             std::abs(n.sim.world[logged::pitch]) > options_.max_tilt_rad;
  for (double v : n.sim.world) bad = bad || !std::isfinite(v);
  if (bad) n.crashed = true;
  return n;
}

}  // namespace pegasus::sysid
