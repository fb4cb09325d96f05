#include "pegasus/scenarios/scenario_set.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <boost/random/sobol.hpp>
#include <numeric>

#include "pegasus/core/error.hpp"

namespace pegasus {

ScenarioVariant parse_scenario_variant(const std::string& name) {
  for (const ScenarioVariant v : kScenarioVariants)
    if (to_string(v) == name) return v;
  throw InputError(fmt::format("scenario variant: expected one of {}; got '{}'",
                               fmt::join(scenario_variant_names(), ", "), name));
}

std::string to_string(ScenarioVariant variant) {
  switch (variant) {
    case ScenarioVariant::kPlain:
      return "plain";
    case ScenarioVariant::kAntithetic:
      return "antithetic";
    case ScenarioVariant::kStratified:
      return "stratified";
    case ScenarioVariant::kSobol:
      return "sobol";
  }
  return "plain";
}

std::vector<std::string> scenario_variant_names() {
  std::vector<std::string> names;
  for (const ScenarioVariant v : kScenarioVariants) names.push_back(to_string(v));
  return names;
}

ScenarioSet::ScenarioSet(const ScenarioOptions& options) : options_(options), rng_(options.seed) {
  if (options.count < 1) throw InputError(fmt::format("scenarios: expected m >= 1, got {}", options.count));
  if (options.horizon < 1) throw InputError(fmt::format("horizon: expected H >= 1, got {}", options.horizon));
  if (options.noise_dim < 0 || options.initial_noise_dim < 0)
    throw InputError("scenarios: noise dimensions must be >= 0");

  const auto m = static_cast<std::size_t>(options.count);
  if (options.variant == ScenarioVariant::kStratified) {
    // One random permutation of the m strata per initial dimension (Fisher-Yates on counter uniforms).
    strata_.resize(static_cast<std::size_t>(options.initial_noise_dim) * m);
    for (int dim = 0; dim < options.initial_noise_dim; ++dim) {
      auto first = strata_.begin() + static_cast<std::ptrdiff_t>(dim * m);
      std::iota(first, first + static_cast<std::ptrdiff_t>(m), 0u);
      for (std::size_t k = m; k > 1; --k) {
        const double u = rng_.uniform2(RngDomain::kPermutation, static_cast<std::uint32_t>(dim),
                                       static_cast<std::uint32_t>(k), 0)[0];
        const auto j = std::min(k - 1, static_cast<std::size_t>(u * static_cast<double>(k)));
        std::swap(first[static_cast<std::ptrdiff_t>(k - 1)], first[static_cast<std::ptrdiff_t>(j)]);
      }
    }
  }
  if (options.variant == ScenarioVariant::kSobol) {
    sobol_dim_ = static_cast<std::size_t>(options.initial_noise_dim) +
                 static_cast<std::size_t>(options.horizon) * static_cast<std::size_t>(options.noise_dim);
    if (sobol_dim_ == 0) sobol_dim_ = 1;
    if (sobol_dim_ > BOOST_RANDOM_SOBOL_MAX_DIMENSION)
      throw InputError(fmt::format("scenarios: sobol needs initial_noise_dim + H * noise_dim <= {}, got {}",
                                   BOOST_RANDOM_SOBOL_MAX_DIMENSION, sobol_dim_));
    // Points are stored (m x dims): a Sobol point is produced one whole vector at a time.
    boost::random::sobol engine(sobol_dim_);
    // Boost's engine starts at the sequence's second point; the all-zero first point is put back in front
    // so that the first 2^k points form a (t, k, s)-net (m = 2^k scenarios evenly spread). The random
    // digital shift moves every point, the zero point included.
    std::vector<std::uint64_t> shift(sobol_dim_);
    for (std::size_t d = 0; d < sobol_dim_; ++d)
      shift[d] = rng_.bits64(RngDomain::kPermutation, static_cast<std::uint32_t>(d),
                             static_cast<std::uint32_t>(d >> 32), 0xffffffffu);
    sobol_points_.resize(m * sobol_dim_);
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t d = 0; d < sobol_dim_; ++d) {
        const std::uint64_t x =
            (i == 0 ? 0 : static_cast<std::uint64_t>(engine())) ^ shift[d];  // digital shift
        sobol_points_[i * sobol_dim_ + d] =
            CounterRng::to_unit(static_cast<std::uint32_t>(x >> 32), static_cast<std::uint32_t>(x));
      }
  }
}

double ScenarioSet::plain(RngDomain domain, int i, int t, int j) const {
  return rng_.uniform2(domain, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(t),
                       static_cast<std::uint32_t>(j / 2))[static_cast<std::size_t>(j % 2)];
}

void ScenarioSet::initial_noise(int i, std::span<double> out) const {
  const int d = options_.initial_noise_dim;
  switch (options_.variant) {
    case ScenarioVariant::kPlain:
      for (int j = 0; j < d; ++j) out[static_cast<std::size_t>(j)] = plain(RngDomain::kInitialNoise, i, 0, j);
      return;
    case ScenarioVariant::kAntithetic:
      for (int j = 0; j < d; ++j) {
        const double u = plain(RngDomain::kInitialNoise, i / 2, 0, j);
        out[static_cast<std::size_t>(j)] = (i % 2 == 0) ? u : 1.0 - u;
      }
      return;
    case ScenarioVariant::kStratified: {
      const auto m = static_cast<std::size_t>(options_.count);
      for (int j = 0; j < d; ++j) {
        const double stratum = strata_[static_cast<std::size_t>(j) * m + static_cast<std::size_t>(i)];
        out[static_cast<std::size_t>(j)] =
            (stratum + plain(RngDomain::kInitialNoise, i, 0, j)) / static_cast<double>(options_.count);
      }
      return;
    }
    case ScenarioVariant::kSobol:
      for (int j = 0; j < d; ++j) out[static_cast<std::size_t>(j)] = sobol(i, static_cast<std::size_t>(j));
      return;
  }
}

void ScenarioSet::step_noise(int i, int t, std::span<double> out) const {
  const int d = options_.noise_dim;
  switch (options_.variant) {
    case ScenarioVariant::kPlain:
    case ScenarioVariant::kStratified:
      for (int j = 0; j < d; j += 2) {
        const auto u = rng_.uniform2(RngDomain::kStepNoise, static_cast<std::uint32_t>(i),
                                     static_cast<std::uint32_t>(t), static_cast<std::uint32_t>(j / 2));
        out[static_cast<std::size_t>(j)] = u[0];
        if (j + 1 < d) out[static_cast<std::size_t>(j + 1)] = u[1];
      }
      return;
    case ScenarioVariant::kAntithetic:
      for (int j = 0; j < d; ++j) {
        const double u = plain(RngDomain::kStepNoise, i / 2, t, j);
        out[static_cast<std::size_t>(j)] = (i % 2 == 0) ? u : 1.0 - u;
      }
      return;
    case ScenarioVariant::kSobol: {
      const std::size_t base = static_cast<std::size_t>(options_.initial_noise_dim) +
                               static_cast<std::size_t>(t) * static_cast<std::size_t>(d);
      for (int j = 0; j < d; ++j)
        out[static_cast<std::size_t>(j)] = sobol(i, base + static_cast<std::size_t>(j));
      return;
    }
  }
}

}  // namespace pegasus
