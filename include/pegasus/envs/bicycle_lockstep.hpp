#pragma once
// PEGASUS rollouts stepped K at a time ("lockstep"), for the bicycle's training objective.
//
// One bicycle step is a chain of dependent floating-point operations (the tilt through sin(phi) into its
// acceleration, the handlebar angle through its sine and the turning radii into the next step), so one
// ride at a time leaves much of the processor idle while each result waits for the one before. K
// independent rides advanced together, one step each in turn, give the processor independent work to
// overlap: about 1.2x the rollouts per second of one ride at a time (bench/bicycle_bench.cpp,
// BM_BicycleUhat_*).
//
// Each lane does exactly what scenario_return (evaluators/rollout.hpp) does for its (theta, scenario) pair,
// operation for operation and in the same order, so every return is bit-identical to scenario_return's, and
// U-hat is bit-identical to PegasusEvaluator's for any K, thread count or number of MPI ranks
// (tests/bicycle/bicycle_lockstep_test.cpp). Generic over the model and policy; the bicycle uses it.
#include <algorithm>
#include <array>
#include <cstddef>
#include <span>

#include "pegasus/evaluators/rollout.hpp"
#include "pegasus/models/model.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {

// out[j] = scenario_return(m, policy, thetas[j], scenarios, scenario_ids[j], d) for j < lanes <= K.
template <int K, SimulativeModel M, class P>
void lockstep_returns(const M& m, const P& policy, std::span<const std::span<const double>> thetas,
                      std::span<const int> scenario_ids, const ScenarioSet& scenarios, const Discounting& d,
                      std::span<double> out) {
  using State = typename M::State;
  const std::size_t lanes = std::min<std::size_t>(static_cast<std::size_t>(K), out.size());
  const auto initial_dim = static_cast<std::size_t>(scenarios.initial_noise_dim());
  const auto noise_dim = static_cast<std::size_t>(scenarios.noise_dim());
  std::array<State, K> s;
  std::array<double, K> ret{}, weight{};
  std::array<bool, K> riding{};
  NoiseBuffer p(std::max(initial_dim, noise_dim));
  for (std::size_t j = 0; j < lanes; ++j) {
    scenarios.initial_noise(scenario_ids[j], std::span<double>(p.data(), initial_dim));
    s[j] = m.initial_state(std::span<const double>(p.data(), initial_dim));
    weight[j] = 1.0;
    riding[j] = true;
  }
  const auto noise = std::span<double>(p.data(), noise_dim);
  for (int t = 0; t < d.horizon; ++t) {
    bool any = false;
    for (std::size_t j = 0; j < lanes; ++j) {
      if (!riding[j]) continue;
      if (m.terminal(s[j])) {
        riding[j] = false;
        continue;
      }
      any = true;
      const auto a = policy.act(thetas[j], m.observe(s[j]));
      scenarios.step_noise(scenario_ids[j], t, noise);
      const auto next = m.step(s[j], a, noise);
      accumulate_transition(m, s[j], a, next, d.gamma, weight[j], ret[j]);
      weight[j] *= d.gamma;
      s[j] = next;
    }
    if (!any) break;
  }
  for (std::size_t j = 0; j < lanes; ++j) out[j] = ret[j];
}

}  // namespace pegasus
