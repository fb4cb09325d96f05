// The noise check's cells (thesis Fig 5.3): the checks of several logs pooled, the fraction of steps outside
// the +-2 sd band at each horizon, and whether each cell's misses could come from an honest band.
#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <cmath>
#include <stdexcept>

#include "pegasus/sysid/identify.hpp"

namespace pegasus::sysid {

NoiseCheck pooled_noise_check(const std::vector<NoiseCheck>& checks) {
  if (checks.empty()) throw std::invalid_argument("pooled_noise_check: no checks");
  NoiseCheck out = checks.front();  // its traces
  const std::size_t seg = out.steps_by_horizon.size();
  // Counts back from the fractions (each a count over the steps, so the rounding is exact).
  auto counts = [](const BodyVec& fraction, int steps) {
    return (fraction * steps).array().round().matrix().eval();
  };
  BodyVec outside = counts(out.outside_fraction, out.steps);
  std::vector<BodyVec> outside_by_horizon(seg);
  for (std::size_t t = 0; t < seg; ++t)
    outside_by_horizon[t] = counts(out.outside_by_horizon[t], out.steps_by_horizon[t]);
  for (std::size_t c = 1; c < checks.size(); ++c) {
    const NoiseCheck& more = checks[c];
    if (more.steps_by_horizon.size() != seg)
      throw std::invalid_argument("pooled_noise_check: the checks differ in their steps per reset");
    outside += counts(more.outside_fraction, more.steps);
    out.steps += more.steps;
    for (std::size_t t = 0; t < seg; ++t) {
      outside_by_horizon[t] += counts(more.outside_by_horizon[t], more.steps_by_horizon[t]);
      out.steps_by_horizon[t] += more.steps_by_horizon[t];
    }
    out.normalized_errors.insert(out.normalized_errors.end(), more.normalized_errors.begin(),
                                 more.normalized_errors.end());
  }
  out.outside_fraction = out.steps > 0 ? BodyVec(outside / out.steps) : BodyVec::Zero();
  for (std::size_t t = 0; t < seg; ++t)
    out.outside_by_horizon[t] = out.steps_by_horizon[t] > 0
                                    ? BodyVec(outside_by_horizon[t] / out.steps_by_horizon[t])
                                    : BodyVec::Zero();
  return out;
}

std::vector<BandMisses> band_misses(const NoiseCheck& check, double dt, const std::vector<double>& seconds) {
  std::vector<BandMisses> out;
  for (double s : seconds) {
    const long t = std::lround(s / dt) - 1;
    if (t < 0 || static_cast<std::size_t>(t) >= check.steps_by_horizon.size() ||
        check.steps_by_horizon[static_cast<std::size_t>(t)] == 0)
      continue;
    for (int k = 0; k < kBodyVars; ++k)
      out.push_back({k, s, check.outside_by_horizon[static_cast<std::size_t>(t)][k],
                     check.steps_by_horizon[static_cast<std::size_t>(t)]});
  }
  return out;
}

std::vector<BandMisses> band_misses_at_every_step(const NoiseCheck& check, double rate_hz) {
  std::vector<BandMisses> out;
  for (std::size_t t = 0; t < check.steps_by_horizon.size(); ++t)
    for (int k = 0; k < kBodyVars && check.steps_by_horizon[t] > 0; ++k)
      out.push_back({k, static_cast<double>(t + 1) / rate_hz, check.outside_by_horizon[t][k],
                     check.steps_by_horizon[t]});
  return out;
}

bool honest_misses(double outside) {
  // A relative tolerance, so that a count exactly at a limit is inside however its quotient rounds.
  return outside >= kHonestMissLow * (1 - 1e-9) && outside <= kHonestMissHigh * (1 + 1e-9);
}

bool misses_consistent_with_honest(int outside, int steps, double alpha) {
  if (steps <= 0) return true;  // nothing counted: no evidence either way
  using boost::math::binomial_distribution;
  const auto trials = static_cast<double>(steps), successes = static_cast<double>(outside);
  const double lower =
      outside == 0 ? 0.0 : binomial_distribution<>::find_lower_bound_on_p(trials, successes, alpha / 2);
  const double upper =
      outside == steps ? 1.0 : binomial_distribution<>::find_upper_bound_on_p(trials, successes, alpha / 2);
  return upper >= kHonestMissLow && lower <= kHonestMissHigh;
}

std::vector<BandMisses> cells_beyond_chance(const std::vector<BandMisses>& cells) {
  std::vector<BandMisses> out;
  const double alpha = kNoiseCheckAlpha / static_cast<double>(std::max<std::size_t>(cells.size(), 1));
  for (const BandMisses& m : cells) {
    const auto outside = static_cast<int>(std::lround(m.outside * m.steps));
    if (!misses_consistent_with_honest(outside, m.steps, alpha)) out.push_back(m);
  }
  return out;
}

}  // namespace pegasus::sysid
