#pragma once
// One rollout of a policy: the discounted return sum_t gamma^t R(s_t, a_t, s_{t+1}) over at most H steps,
// stopping at an absorbing state. gamma = 1 gives the undiscounted finite-horizon return. A transition
// with an event fraction tau (footnote 9) is discounted by gamma^(t + tau).
#include <array>
#include <cmath>
#include <span>

#include "pegasus/models/model.hpp"
#include "pegasus/policies/policies.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus {

struct Discounting {
  double gamma = 1.0;  // in [0, 1]
  int horizon = 1;     // H >= 1
};

void validate(const Discounting& d);  // InputError naming gamma or horizon

// Adds one transition's reward to `ret` at discount `weight` = gamma^t.
template <ModelBasics M>
inline void accumulate_transition(const M& m, const typename M::State& s, const typename M::Action& a,
                                  const typename M::State& next, double gamma, double weight, double& ret) {
  const double r = transition_reward(m, s, a, next);
  if constexpr (HasEventFraction<M>) {
    const double tau = m.event_fraction(s, a, next);
    ret += (tau > 0.0 ? r * weight * std::pow(gamma, tau) : r * weight);
  } else {
    (void)gamma;
    ret += r * weight;
  }
}

// How one scenario's rollout went: its return, the steps taken, and whether it ended in an absorbing state
// (for the helicopter's models, a crash).
struct ScenarioOutcome {
  double ret = 0.0;
  int steps = 0;
  bool absorbed = false;
};

// The rollout of scenario i under (policy, theta); its return is the summand of PEGASUS's U-hat (Eq 4.22).
template <SimulativeModel M, class P>
ScenarioOutcome scenario_outcome(const M& m, const P& policy, std::span<const double> theta,
                                 const ScenarioSet& scenarios, int i, const Discounting& d) {
  const auto initial_dim = static_cast<std::size_t>(scenarios.initial_noise_dim());
  const auto noise_dim = static_cast<std::size_t>(scenarios.noise_dim());
  NoiseBuffer p(std::max(initial_dim, noise_dim));
  scenarios.initial_noise(i, p.first(initial_dim));
  auto s = m.initial_state(p.first(initial_dim));
  const auto noise = p.first(noise_dim);
  ScenarioOutcome out;
  double weight = 1.0;
  for (; out.steps < d.horizon; ++out.steps) {
    if (m.terminal(s)) break;
    const auto a = policy.act(theta, m.observe(s));
    scenarios.step_noise(i, out.steps, noise);
    const auto next = m.step(s, a, noise);
    accumulate_transition(m, s, a, next, d.gamma, weight, out.ret);
    weight *= d.gamma;
    s = next;
  }
  out.absorbed = m.terminal(s);
  return out;
}

// The return of scenario i under (policy, theta): the summand of PEGASUS's U-hat (Eq 4.22).
template <SimulativeModel M, class P>
double scenario_return(const M& m, const P& policy, std::span<const double> theta,
                       const ScenarioSet& scenarios, int i, const Discounting& d) {
  return scenario_outcome(m, policy, theta, scenarios, i, d).ret;
}

// The return of one rollout with fresh randomness drawn from `rng` (Monte Carlo, Eq 4.10).
template <GenerativeModel M, class P>
double sampled_return(const M& m, const P& policy, std::span<const double> theta, UniformStream& rng,
                      const Discounting& d) {
  auto s = generative_initial(m, rng);
  double ret = 0.0, weight = 1.0;
  for (int t = 0; t < d.horizon; ++t) {
    if (m.terminal(s)) break;
    const auto a = policy.act(theta, m.observe(s));
    const auto next = generative_step(m, s, a, rng);
    accumulate_transition(m, s, a, next, d.gamma, weight, ret);
    weight *= d.gamma;
    s = next;
  }
  return ret;
}

}  // namespace pegasus
