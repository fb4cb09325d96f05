#pragma once
// Deterministic simulative models g(s, a, p) (thesis §4.2.1) and generative models, as C++20 concepts so
// that hot loops inline `step`; type erasure happens once, where a problem becomes an Objective.
//
// A SimulativeModel is an immutable parameter struct shared by all threads (MuJoCo's model/data split):
//   using State, Action, Observation;        State small and copyable, owned by whoever steps it
//   int state_dim() const;                   dimension of the state (for reports and checks)
//   int noise_dim() const;                   d_P: uniforms consumed by one step
//   int initial_noise_dim() const;           uniforms consumed to draw s0 ~ D
//   State initial_state(span<const double> p0) const;
//   State step(const State&, const Action&, span<const double> p) const;   pure and deterministic
//   bool terminal(const State&) const;       absorbing: no more reward, no more steps
//   Observation observe(const State&) const; what a (PO)MDP policy sees
//   ActionSpace action_space() const;
//   and a reward in one of three forms: reward(s, a, s'), reward(s, a) or reward(s)
//   (R(s) is the reward of the state being left, so U = R(s0) + gamma R(s1) + ..., Eq 4.3).
// Optional:
//   double event_fraction(const State& s, const Action& a, const State& s') const;
//     the fraction tau in [0, 1] of the step at which an event (entering a goal) happened; the reward of
//     that transition is then discounted by gamma^(t + tau) instead of gamma^t (continuous-time
//     discounting, footnote 9 of §4.4).
//
// A GenerativeModel only samples internally: instead of step/initial_state it offers
//   State sample_initial(UniformStream&) const;  State sample_step(const State&, const Action&,
//   UniformStream&) const;
// Every SimulativeModel is also usable as a generative model (generative_step below draws its p).
#include <algorithm>
#include <array>
#include <concepts>
#include <span>

#include "pegasus/core/error.hpp"
#include "pegasus/models/action_space.hpp"
#include "pegasus/random/counter_rng.hpp"

namespace pegasus {

// Upper bound on d_P and on the initial-state noise dimension; noise lives in stack buffers of this size
// so that no step or rollout allocates.
inline constexpr int kMaxNoiseDim = 64;

template <class M>
concept HasTransitionReward = requires(const M& m, const typename M::State& s, const typename M::Action& a) {
  { m.reward(s, a, s) } -> std::convertible_to<double>;
};
template <class M>
concept HasStateActionReward = requires(const M& m, const typename M::State& s, const typename M::Action& a) {
  { m.reward(s, a) } -> std::convertible_to<double>;
};
template <class M>
concept HasStateReward = requires(const M& m, const typename M::State& s) {
  { m.reward(s) } -> std::convertible_to<double>;
};

template <class M>
concept ModelBasics = requires(const M& m, const typename M::State& s) {
  typename M::State;
  typename M::Action;
  typename M::Observation;
  { m.state_dim() } -> std::convertible_to<int>;
  { m.terminal(s) } -> std::convertible_to<bool>;
  { m.observe(s) } -> std::convertible_to<typename M::Observation>;
  { m.action_space() } -> std::convertible_to<ActionSpace>;
}
&&(HasTransitionReward<M> || HasStateActionReward<M> || HasStateReward<M>);

template <class M>
concept SimulativeModel = ModelBasics<M> &&
    requires(const M& m, const typename M::State& s, const typename M::Action& a, std::span<const double> p) {
  { m.noise_dim() } -> std::convertible_to<int>;
  { m.initial_noise_dim() } -> std::convertible_to<int>;
  { m.initial_state(p) } -> std::convertible_to<typename M::State>;
  { m.step(s, a, p) } -> std::convertible_to<typename M::State>;
};

template <class M>
concept SamplingModel = ModelBasics<M> &&
    requires(const M& m, const typename M::State& s, const typename M::Action& a, UniformStream& rng) {
  { m.sample_initial(rng) } -> std::convertible_to<typename M::State>;
  { m.sample_step(s, a, rng) } -> std::convertible_to<typename M::State>;
};

// Anything Monte Carlo and trajectory trees can use.
template <class M>
concept GenerativeModel = SimulativeModel<M> || SamplingModel<M>;

template <class M>
concept HasEventFraction = requires(const M& m, const typename M::State& s, const typename M::Action& a) {
  { m.event_fraction(s, a, s) } -> std::convertible_to<double>;
};

// R(s, a, s') whatever form the model writes its reward in.
template <ModelBasics M>
inline double transition_reward(const M& m, const typename M::State& s, const typename M::Action& a,
                                const typename M::State& next) {
  if constexpr (HasTransitionReward<M>) {
    return m.reward(s, a, next);
  } else if constexpr (HasStateActionReward<M>) {
    return m.reward(s, a);
  } else {
    (void)a;
    (void)next;
    return m.reward(s);
  }
}

// tau in [0, 1] of footnote 9; 0 for models without events.
template <ModelBasics M>
inline double transition_event_fraction(const M& m, const typename M::State& s, const typename M::Action& a,
                                        const typename M::State& next) {
  if constexpr (HasEventFraction<M>) {
    return m.event_fraction(s, a, next);
  } else {
    (void)m, (void)s, (void)a, (void)next;
    return 0.0;
  }
}

// Checks a simulative model's declared dimensions once, where it enters an evaluator.
template <SimulativeModel M>
void check_noise_dims(const M& m) {
  if (m.noise_dim() < 0 || m.noise_dim() > kMaxNoiseDim || m.initial_noise_dim() < 0 ||
      m.initial_noise_dim() > kMaxNoiseDim)
    throw InputError("model: noise dimensions must lie in [0, " + std::to_string(kMaxNoiseDim) + "]");
}

// s0 ~ D drawn from a sequential stream (Monte Carlo with fresh randomness, trajectory trees).
template <GenerativeModel M>
typename M::State generative_initial(const M& m, UniformStream& rng) {
  if constexpr (SamplingModel<M>) {
    return m.sample_initial(rng);
  } else {
    std::array<double, kMaxNoiseDim> p;
    const int d = m.initial_noise_dim();
    for (int j = 0; j < d; ++j) p[j] = rng.next();
    return m.initial_state(std::span<const double>(p.data(), static_cast<std::size_t>(d)));
  }
}

// s' ~ P_sa drawn from a sequential stream.
template <GenerativeModel M>
typename M::State generative_step(const M& m, const typename M::State& s, const typename M::Action& a,
                                  UniformStream& rng) {
  if constexpr (SamplingModel<M>) {
    return m.sample_step(s, a, rng);
  } else {
    std::array<double, kMaxNoiseDim> p;
    const int d = m.noise_dim();
    for (int j = 0; j < d; ++j) p[j] = rng.next();
    return m.step(s, a, std::span<const double>(p.data(), static_cast<std::size_t>(d)));
  }
}

}  // namespace pegasus
