#pragma once
// Reward shaping (thesis ch. 3). Learning on M' = (S, A, P, gamma, R + F) instead of M: potential-based
// F(s, a, s') = gamma Phi(s') - Phi(s) leaves the optimal policies unchanged (§3.3, Theorem 1), shifts
// every value function by -Phi (Lemma 2, Remark 1), and is the only form that can promise this without
// knowing P and R (Theorem 1, necessity; see shaping/audit.hpp).
//
// Episodic tasks: Phi of terminal/absorbing states is taken as 0. Otherwise the shaping collected along an
// episode telescopes to gamma^T Phi(s_T) - Phi(s_0), which depends on the (policy-dependent) length T
// when gamma < 1, and the optimal policy can change. (For gamma = 1 this is also the normalisation the
// sufficiency proof of Theorem 1 uses.)
//
// ShapedModel wraps any model of models/model.hpp and is itself a model of the same kind, so a learner, an
// evaluator or PEGASUS search runs on the shaped problem unchanged; the shaping only touches reward().
#include <cmath>
#include <concepts>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "pegasus/mdp/finite_mdp.hpp"
#include "pegasus/models/model.hpp"

namespace pegasus {

// Eq 3.1.
inline double potential_shaping_reward(double gamma, double phi_s, double phi_next) {
  return gamma * phi_next - phi_s;
}
// §3.5: for a semi-MDP whose action took time tau under discount rate beta (gamma = exp(-beta) per unit).
inline double smdp_shaping_reward(double beta, double tau, double phi_s, double phi_next) {
  return std::exp(-beta * tau) * phi_next - phi_s;
}

// A potential given as a table over integer states.
struct TablePotential {
  std::vector<double> values;
  double operator()(int s) const { return values[static_cast<std::size_t>(s)]; }
};

// The discount applied to Phi(s'): the MDP's gamma ...
struct ConstantDiscount {
  double gamma = 1.0;
  template <class S, class A>
  double operator()(const S&, const A&, const S&) const {
    return gamma;
  }
};
// ... or exp(-beta tau(s, a, s')) for a semi-MDP whose actions take variable time (§3.5).
template <class Duration>
struct SmdpDiscount {
  double beta = 0.0;
  Duration duration;
  template <class S, class A>
  double operator()(const S& s, const A& a, const S& next) const {
    return std::exp(-beta * duration(s, a, next));
  }
};

template <ModelBasics M, class Potential, class Discount = ConstantDiscount>
requires std::invocable<const Potential&, const typename M::State&>
class ShapedModel {
 public:
  using State = typename M::State;
  using Action = typename M::Action;
  using Observation = typename M::Observation;

  // zero_at_terminal: treat Phi(s') as 0 when model.terminal(s') (see the header comment; keep true for
  // episodic tasks).
  ShapedModel(M model, Potential phi, Discount discount, bool zero_at_terminal = true)
      : model_(std::move(model)),
        phi_(std::move(phi)),
        discount_(std::move(discount)),
        zero_at_terminal_(zero_at_terminal) {}

  // F(s, a, s') of this wrapper.
  double shaping(const State& s, const Action& a, const State& next) const {
    const double phi_next =
        (zero_at_terminal_ && model_.terminal(next)) ? 0.0 : static_cast<double>(phi_(next));
    const double f = discount_(s, a, next) * phi_next - static_cast<double>(phi_(s));
    if constexpr (HasEventFraction<M> && std::same_as<Discount, ConstantDiscount>) {
      // An event at fraction tau of the step has its reward discounted by gamma^(t + tau) (footnote 9 of
      // §4.4); pre-scale F by gamma^-tau so that the shaping still telescopes with gamma^t weights.
      const double tau = model_.event_fraction(s, a, next);
      if (tau > 0.0 && discount_.gamma > 0.0) return f * std::pow(discount_.gamma, -tau);
    }
    return f;
  }

  double reward(const State& s, const Action& a, const State& next) const {
    return transition_reward(model_, s, a, next) + shaping(s, a, next);
  }

  int state_dim() const { return model_.state_dim(); }
  bool terminal(const State& s) const { return model_.terminal(s); }
  Observation observe(const State& s) const { return model_.observe(s); }
  ActionSpace action_space() const { return model_.action_space(); }

  int noise_dim() const requires SimulativeModel<M> { return model_.noise_dim(); }
  int initial_noise_dim() const requires SimulativeModel<M> { return model_.initial_noise_dim(); }
  State initial_state(std::span<const double> p) const requires SimulativeModel<M> {
    return model_.initial_state(p);
  }
  State step(const State& s, const Action& a, std::span<const double> p) const requires SimulativeModel<M> {
    return model_.step(s, a, p);
  }
  State sample_initial(UniformStream& rng) const requires SamplingModel<M> {
    return model_.sample_initial(rng);
  }
  State sample_step(const State& s, const Action& a, UniformStream& rng) const requires SamplingModel<M> {
    return model_.sample_step(s, a, rng);
  }
  double event_fraction(const State& s, const Action& a,
                        const State& next) const requires HasEventFraction<M> {
    return model_.event_fraction(s, a, next);
  }

  // Tabular models (State = int) keep their table sizes.
  int num_states() const requires requires(const M& m) { m.num_states(); }
  { return model_.num_states(); }
  int num_actions() const requires requires(const M& m) { m.num_actions(); }
  { return model_.num_actions(); }

  const M& base() const { return model_; }
  const Potential& potential() const { return phi_; }

 private:
  M model_;
  Potential phi_;
  Discount discount_;
  bool zero_at_terminal_;
};

// F = gamma Phi(s') - Phi(s).
template <ModelBasics M, class Potential>
ShapedModel<M, Potential> shape(M model, Potential phi, double gamma, bool zero_at_terminal = true) {
  return ShapedModel<M, Potential>(std::move(model), std::move(phi), ConstantDiscount{gamma},
                                   zero_at_terminal);
}
// F = exp(-beta tau(s, a, s')) Phi(s') - Phi(s) (§3.5).
template <ModelBasics M, class Potential, class Duration>
ShapedModel<M, Potential, SmdpDiscount<Duration>> shape_smdp(M model, Potential phi, double beta,
                                                             Duration duration,
                                                             bool zero_at_terminal = true) {
  return ShapedModel<M, Potential, SmdpDiscount<Duration>>(
      std::move(model), std::move(phi), SmdpDiscount<Duration>{beta, std::move(duration)}, zero_at_terminal);
}

// The "progress bonus" of §3.1/§3.3, kept as the example of what goes wrong: +bonus whenever the
// successor is closer to the goal, nothing for moving away. It is not potential-based, so a policy that
// shuttles back and forth collects the bonus on every other step (Randlov and Alstrom's bicycle riding in
// circles); do not use it for learning.
template <ModelBasics M, class Distance>
requires std::invocable<const Distance&, const typename M::State&>
class ProgressBonusModel {
 public:
  using State = typename M::State;
  using Action = typename M::Action;
  using Observation = typename M::Observation;

  ProgressBonusModel(M model, Distance distance, double bonus)
      : model_(std::move(model)), distance_(std::move(distance)), bonus_(bonus) {}

  double shaping(const State& s, const Action&, const State& next) const {
    return distance_(next) < distance_(s) ? bonus_ : 0.0;
  }
  double reward(const State& s, const Action& a, const State& next) const {
    return transition_reward(model_, s, a, next) + shaping(s, a, next);
  }
  int state_dim() const { return model_.state_dim(); }
  int noise_dim() const { return model_.noise_dim(); }
  int initial_noise_dim() const { return model_.initial_noise_dim(); }
  State initial_state(std::span<const double> p) const { return model_.initial_state(p); }
  State step(const State& s, const Action& a, std::span<const double> p) const {
    return model_.step(s, a, p);
  }
  bool terminal(const State& s) const { return model_.terminal(s); }
  Observation observe(const State& s) const { return model_.observe(s); }
  ActionSpace action_space() const { return model_.action_space(); }
  int num_states() const requires requires(const M& m) { m.num_states(); }
  { return model_.num_states(); }
  int num_actions() const requires requires(const M& m) { m.num_actions(); }
  { return model_.num_actions(); }
  const M& base() const { return model_; }

 private:
  M model_;
  Distance distance_;
  double bonus_;
};

// ---- Finite MDPs -------------------------------------------------------------------------------------
// All of these add F to R(s, a, s') on the entries of non-absorbing rows (absorbing states end the episode,
// so nothing is collected there) and return a validated FiniteMdp.

// R + gamma Phi(s') - Phi(s), with Phi(absorbing) taken as 0.
FiniteMdp shape_with_potential(const FiniteMdp& mdp, std::span<const double> phi);
// R + f(s, a, s') for an arbitrary shaping function.
FiniteMdp add_shaping(const FiniteMdp& mdp, const std::function<double(int, int, int)>& f);
// R + c on every transition of a non-absorbing state (a constant offset; §3.3 after Remark 2).
FiniteMdp add_constant_reward(const FiniteMdp& mdp, double c);
// The potential giving F = c: Phi = -c/(1-gamma). Only for continuing MDPs (gamma < 1, no absorbing
// states): with episodes, F = c on the last step would need Phi(absorbing) = -c/(1-gamma) != 0, and an
// offset then changes how attractive ending the episode is. Throws InputError otherwise.
std::vector<double> constant_offset_potential(const FiniteMdp& mdp, double c);

}  // namespace pegasus
