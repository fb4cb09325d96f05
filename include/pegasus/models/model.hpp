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
#include <memory>
#include <span>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/models/action_space.hpp"
#include "pegasus/random/counter_rng.hpp"

namespace pegasus {

// Scratch for one draw of scenario numbers (a step's p or a start's p0), of a model's own size: on the stack
// up to kInlineNoiseDim numbers (every model the project ships draws fewer), so that no step or rollout of
// those allocates; on the heap beyond, so that a model's noise dimensions have no upper bound (a
// domain-randomised start may draw hundreds).
class NoiseBuffer {
 public:
  static constexpr std::size_t kInlineNoiseDim = 64;
  explicit NoiseBuffer(std::size_t size)
      : size_(size), heap_(size > kInlineNoiseDim ? std::make_unique<double[]>(size) : nullptr) {}
  double* data() { return heap_ ? heap_.get() : inline_.data(); }
  double& operator[](std::size_t j) { return data()[j]; }
  // The first n numbers (n <= size()).
  std::span<double> first(std::size_t n) { return {data(), n}; }
  std::span<double> span() { return first(size_); }
  std::size_t size() const { return size_; }

 private:
  std::size_t size_;
  std::array<double, kInlineNoiseDim> inline_;  // uninitialised: every user writes before reading
  std::unique_ptr<double[]> heap_;
};

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
  if (m.noise_dim() < 0 || m.initial_noise_dim() < 0)
    throw InputError("model: noise dimensions must be >= 0, got " + std::to_string(m.noise_dim()) +
                     " per step and " + std::to_string(m.initial_noise_dim()) + " for the start");
}

// s0 ~ D drawn from a sequential stream (Monte Carlo with fresh randomness, trajectory trees).
template <GenerativeModel M>
typename M::State generative_initial(const M& m, UniformStream& rng) {
  if constexpr (SamplingModel<M>) {
    return m.sample_initial(rng);
  } else {
    NoiseBuffer p(static_cast<std::size_t>(m.initial_noise_dim()));
    for (double& u : p.span()) u = rng.next();
    return m.initial_state(p.span());
  }
}

// s' ~ P_sa drawn from a sequential stream.
template <GenerativeModel M>
typename M::State generative_step(const M& m, const typename M::State& s, const typename M::Action& a,
                                  UniformStream& rng) {
  if constexpr (SamplingModel<M>) {
    return m.sample_step(s, a, rng);
  } else {
    NoiseBuffer p(static_cast<std::size_t>(m.noise_dim()));
    for (double& u : p.span()) u = rng.next();
    return m.step(s, a, p.span());
  }
}

}  // namespace pegasus
