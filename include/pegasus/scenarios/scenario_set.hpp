#pragma once
// A set of m PEGASUS scenarios (thesis §4.4.2, Eq 4.22): scenario i is (s0^(i), p_1^(i), ..., p_H^(i)).
// Plain scenarios are computed on demand from a counter-based generator keyed by the seed, with counter
// (scenario, step, block): random access, nothing stored, the same numbers on every thread and process.
// Variance-reduction variants (§4.7): antithetic pairs, stratified (Latin hypercube) initial states, and
// quasi-Monte Carlo (Sobol points from Boost, randomised by a random digital shift).
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pegasus/random/counter_rng.hpp"

namespace pegasus {

enum class ScenarioVariant {
  kPlain,       // independent uniforms
  kAntithetic,  // scenario 2k+1 uses 1 - u wherever scenario 2k uses u (systematic sampling, §4.7)
  kStratified,  // initial-state uniforms stratified across scenarios (Latin hypercube); steps plain
  kSobol,       // every uniform of scenario i is a coordinate of the i-th randomised Sobol point
};

inline constexpr std::array<ScenarioVariant, 4> kScenarioVariants = {
    ScenarioVariant::kPlain, ScenarioVariant::kAntithetic, ScenarioVariant::kStratified,
    ScenarioVariant::kSobol};

ScenarioVariant parse_scenario_variant(const std::string& name);  // "plain", "antithetic", ...
std::string to_string(ScenarioVariant variant);
std::vector<std::string> scenario_variant_names();  // to_string of each of kScenarioVariants

struct ScenarioOptions {
  std::uint64_t seed = 1;
  int count = 1;              // m >= 1
  int horizon = 1;            // H >= 1: steps whose noise a scenario holds
  int noise_dim = 1;          // d_P: uniforms per step
  int initial_noise_dim = 0;  // uniforms that draw s0
  ScenarioVariant variant = ScenarioVariant::kPlain;
};

class ScenarioSet {
 public:
  explicit ScenarioSet(const ScenarioOptions& options);

  int size() const { return options_.count; }
  int horizon() const { return options_.horizon; }
  int noise_dim() const { return options_.noise_dim; }
  int initial_noise_dim() const { return options_.initial_noise_dim; }
  const ScenarioOptions& options() const { return options_; }

  // The uniforms that draw s0 of scenario i (out.size() == initial_noise_dim()).
  void initial_noise(int i, std::span<double> out) const;
  // p_{t+1} of scenario i, the noise of step t in [0, H) (out.size() == noise_dim()).
  void step_noise(int i, int t, std::span<double> out) const;

 private:
  double plain(RngDomain domain, int i, int t, int j) const;
  // Coordinate `dim` of the randomised Sobol point of scenario i.
  double sobol(int i, std::size_t dim) const {
    return sobol_points_[static_cast<std::size_t>(i) * sobol_dim_ + dim];
  }

  ScenarioOptions options_;
  CounterRng rng_;
  std::vector<std::uint32_t> strata_;  // [dim * m + i]: stratum of scenario i in initial dimension dim
  std::size_t sobol_dim_ = 0;
  std::vector<double> sobol_points_;
};

}  // namespace pegasus
