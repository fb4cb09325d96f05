#pragma once
// Model-free learners for tabular models (thesis §2.3): Q-learning (Eq 2.18), Sarsa, Sarsa(lambda) with
// replacing traces, all with epsilon-greedy exploration, and REINFORCE with a softmax policy.
//
// They are templates over the model (any TabularModel: GridWorld, FlagWorld, MdpModel, or those wrapped
// by ShapedModel) and over the uniform source (UniformStream, BlockUniformStream), so the step, the reward
// and the random draws inline into one loop; nothing is allocated per step. Every random number comes
// from the generator passed in.
//
// Episodes start from model.initial_state and end at a terminal state or after max_steps_per_episode
// steps. The curve records, per episode, the steps taken and the undiscounted sum of the rewards the
// learner saw (shaped rewards when the model is shaped).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "pegasus/core/error.hpp"
#include "pegasus/mdp/mdp_model.hpp"

namespace pegasus {

template <class G>
concept UniformSource = requires(G& g) {
  { g.next() } -> std::convertible_to<double>;
};

struct QTable {
  int num_states = 0, num_actions = 0;
  std::vector<double> q;  // row-major S x A

  QTable() = default;
  QTable(int s, int a, double init = 0.0)
      : num_states(s), num_actions(a), q(static_cast<std::size_t>(s) * static_cast<std::size_t>(a), init) {}
  double* row(int s) {
    return q.data() + static_cast<std::size_t>(s) * static_cast<std::size_t>(num_actions);
  }
  const double* row(int s) const {
    return q.data() + static_cast<std::size_t>(s) * static_cast<std::size_t>(num_actions);
  }
  // argmax_a Q(s, a), lowest action on ties.
  int greedy(int s) const {
    const double* r = row(s);
    return static_cast<int>(std::max_element(r, r + num_actions) - r);
  }
  std::vector<int> greedy_policy() const {
    std::vector<int> p(static_cast<std::size_t>(num_states));
    for (int s = 0; s < num_states; ++s) p[static_cast<std::size_t>(s)] = greedy(s);
    return p;
  }
};

struct TdOptions {
  // Number of episodes. Must be >= 1.
  int episodes = 100;
  // Learning rate alpha in (0, 1]. The §3.4 experiments use 0.02.
  double alpha = 0.02;
  // Exploration: a uniformly random action with probability epsilon, else greedy (ties broken uniformly
  // at random). In [0, 1]; §3.4 uses 0.1.
  double epsilon = 0.1;
  // Discount in [0, 1] used in the TD target.
  double gamma = 1.0;
  // Trace decay of Sarsa(lambda), in [0, 1].
  double lambda = 0.9;
  // Traces below this are dropped (Sarsa(lambda) only); in [0, 1).
  double trace_cutoff = 1e-6;
  // Episode length cap. Must be >= 1.
  std::int64_t max_steps_per_episode = 10'000'000;

  bool IsValid(std::string* error) const {
    auto bad = [&](const std::string& m) {
      if (error) *error = "learner options: " + m;
      return false;
    };
    if (episodes < 1) return bad(fmt::format("episodes must be >= 1, got {}", episodes));
    if (!(alpha > 0.0 && alpha <= 1.0)) return bad(fmt::format("alpha must lie in (0, 1], got {}", alpha));
    if (!(epsilon >= 0.0 && epsilon <= 1.0))
      return bad(fmt::format("epsilon must lie in [0, 1], got {}", epsilon));
    if (!(gamma >= 0.0 && gamma <= 1.0)) return bad(fmt::format("gamma must lie in [0, 1], got {}", gamma));
    if (!(lambda >= 0.0 && lambda <= 1.0))
      return bad(fmt::format("lambda must lie in [0, 1], got {}", lambda));
    if (!(trace_cutoff >= 0.0 && trace_cutoff < 1.0)) return bad("trace_cutoff must lie in [0, 1)");
    if (max_steps_per_episode < 1) return bad("max_steps_per_episode must be >= 1");
    return true;
  }
};

struct LearningCurve {
  std::vector<std::int64_t> steps;  // per episode
  std::vector<double> returns;      // per episode, undiscounted
  std::int64_t total_steps = 0;
  int truncated_episodes = 0;  // episodes that hit max_steps_per_episode
};

// Epsilon-greedy with one uniform u: u < eps picks action floor(u / eps * A); otherwise the rescaled
// remainder picks uniformly among the greedy actions, so ties (all of them at the start, with Q = 0) do
// not favour low action numbers.
namespace detail {
// kTieAction[mask][k]: the k-th set bit of a 4-bit mask, for the branch-free path below.
inline constexpr std::array<std::array<std::int8_t, 4>, 16> kTieAction = [] {
  std::array<std::array<std::int8_t, 4>, 16> t{};
  for (int m = 0; m < 16; ++m) {
    int k = 0;
    for (int a = 0; a < 4; ++a)
      if (m >> a & 1)
        t[static_cast<std::size_t>(m)][static_cast<std::size_t>(k++)] = static_cast<std::int8_t>(a);
  }
  return t;
}();
// kTieCount[mask]: the number of set bits of a 4-bit mask. A table, not std::popcount: without -mpopcnt
// (the portable x86-64 baseline) std::popcount is a call into libgcc on the critical path of every step.
inline constexpr std::array<std::int8_t, 16> kTieCount = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
// The same as doubles: saves an int -> double conversion on the critical path.
inline constexpr std::array<double, 16> kTieCountDouble = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};

// Bit a set iff q[a] == max(q[0..3]). With SSE2 (every x86-64) two packed maxima and two packed compares
// replace the four scalar compares, whose flags (ucomisd: equal and not unordered) cost several
// instructions each. Same mask either way: only the sign of a zero maximum can differ, and -0 == +0.
inline unsigned argmax_mask4(const double* q) {
#if defined(__SSE2__)
  const __m128d q01 = _mm_loadu_pd(q), q23 = _mm_loadu_pd(q + 2);
  const __m128d m = _mm_max_pd(q01, q23);
  const __m128d best = _mm_max_pd(m, _mm_shuffle_pd(m, m, 1));
  return static_cast<unsigned>(_mm_movemask_pd(_mm_cmpeq_pd(q01, best))) |
         static_cast<unsigned>(_mm_movemask_pd(_mm_cmpeq_pd(q23, best))) << 2;
#else
  const double best = std::max(std::max(q[0], q[1]), std::max(q[2], q[3]));
  return static_cast<unsigned>(q[0] == best) | static_cast<unsigned>(q[1] == best) << 1 |
         static_cast<unsigned>(q[2] == best) << 2 | static_cast<unsigned>(q[3] == best) << 3;
#endif
}
}  // namespace detail

// The scales are precomputed so that choosing an action needs no division: a Sarsa step is short enough
// that two divisions on its critical path would cost a good part of it.
class EpsilonGreedy {
 public:
  EpsilonGreedy(double epsilon, int num_actions)
      : epsilon_(epsilon),
        explore_scale_(epsilon > 0.0 ? num_actions / epsilon : 0.0),
        exploit_scale_(epsilon < 1.0 ? 1.0 / (1.0 - epsilon) : 0.0) {}

  template <UniformSource G>
  int operator()(const double* q, int num_actions, G& rng) const {
    const double u = rng.next();
    if (num_actions == 4) {
      // The gridworlds' case, written without data-dependent branches: exploration, ties and the argmax
      // are all unpredictable, and mispredictions would cost more than the rest of a Sarsa step.
      const unsigned mask = detail::argmax_mask4(q);
      const int ties = detail::kTieCount[mask];
      int pick =
          static_cast<int>(std::max(0.0, (u - epsilon_) * exploit_scale_) * detail::kTieCountDouble[mask]);
      pick = pick < ties ? pick : ties - 1;
      const int greedy = detail::kTieAction[mask][static_cast<std::size_t>(pick)];
      int explore = static_cast<int>(u * explore_scale_);
      explore = explore < 3 ? explore : 3;
      return u < epsilon_ ? explore : greedy;
    }
    if (u < epsilon_) {
      const int a = static_cast<int>(u * explore_scale_);
      return a < num_actions ? a : num_actions - 1;
    }
    double best = q[0];
    int ties = 1;
    for (int a = 1; a < num_actions; ++a) {
      if (q[a] > best) {
        best = q[a];
        ties = 1;
      } else if (q[a] == best) {
        ++ties;
      }
    }
    int pick = static_cast<int>((u - epsilon_) * exploit_scale_ * ties);
    if (pick >= ties) pick = ties - 1;
    for (int a = 0; a < num_actions; ++a)
      if (q[a] == best && pick-- == 0) return a;
    return 0;
  }

 private:
  double epsilon_, explore_scale_, exploit_scale_;
};

template <UniformSource G>
inline int epsilon_greedy(const double* q, int num_actions, double epsilon, G& rng) {
  return EpsilonGreedy(epsilon, num_actions)(q, num_actions, rng);
}

namespace detail {

template <TabularModel M, UniformSource G>
inline int draw_initial(const M& m, G& rng) {
  NoiseBuffer p(static_cast<std::size_t>(m.initial_noise_dim()));
  for (double& u : p.span()) u = rng.next();
  return m.initial_state(p.span());
}

template <TabularModel M, UniformSource G>
[[gnu::always_inline]] inline int draw_step(const M& m, int s, int a, G& rng) {
  NoiseBuffer p(static_cast<std::size_t>(m.noise_dim()));
  for (double& u : p.span()) u = rng.next();
  return m.step(s, a, p.span());
}

template <TabularModel M>
void check_learner_input(const M& m, const TdOptions& o, const QTable& q) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError(err);
  check_noise_dims(m);
  if (q.num_states != m.num_states() || q.num_actions != m.num_actions())
    throw InputError(fmt::format("learner: Q table is {} x {}, the model {} x {}", q.num_states,
                                 q.num_actions, m.num_states(), m.num_actions()));
}

}  // namespace detail

namespace detail {

// One Sarsa learner's progress through its episodes, advanced one step at a time so that several can be
// interleaved (sarsa_runs). The arithmetic is exactly that of a plain Sarsa loop. The options are copied
// in, and the action count is asked of the model at each step (a constant the compiler folds for the
// gridworlds), so that a step reads nothing through the options.
template <TabularModel M, UniformSource G>
struct SarsaLane {
  const M* m;
  G* rng;
  double* Q;
  LearningCurve* curve;
  EpsilonGreedy choose{0.0, 1};
  double alpha = 0.0, gamma = 0.0;
  std::int64_t max_steps = 0;
  int episodes = 0;
  // s and a apart: stored next to each other, GCC merges their stores into one 8-byte store, which the
  // next step's two 4-byte loads cannot always forward from.
  int s = 0;
  std::int64_t steps = 0;
  int a = 0, episode = 0;
  double ret = 0.0;
  bool active = true;

  void start(const M& model, const TdOptions& opt, G& g, QTable& q, LearningCurve& c) {
    m = &model;
    rng = &g;
    Q = q.q.data();
    curve = &c;
    choose = EpsilonGreedy(opt.epsilon, model.num_actions());
    alpha = opt.alpha;
    gamma = opt.gamma;
    max_steps = opt.max_steps_per_episode;
    episodes = opt.episodes;
    c.steps.reserve(static_cast<std::size_t>(opt.episodes));
    c.returns.reserve(static_cast<std::size_t>(opt.episodes));
    begin_episode();
  }
  [[gnu::noinline]] void begin_episode() {
    for (;;) {
      s = draw_initial(*m, *rng);
      steps = 0;
      ret = 0.0;
      if (!m->terminal(s)) break;
      if (!end_episode()) return;  // an episode that starts at a terminal state takes no step
    }
    const int A = m->num_actions();
    a = choose(Q + static_cast<std::ptrdiff_t>(s) * A, A, *rng);
  }
  // Records the episode; false when it was the last.
  bool end_episode() {
    curve->steps.push_back(steps);
    curve->returns.push_back(ret);
    curve->total_steps += steps;
    if (++episode == episodes) {
      active = false;
      return false;
    }
    return true;
  }
  [[gnu::noinline]] void finish_episode(bool truncated) {
    if (truncated) ++curve->truncated_episodes;
    if (end_episode()) begin_episode();
  }
  [[gnu::always_inline]] void step() {
    const int A = m->num_actions();
    const int s0 = s, a0 = a;
    const int s2 = draw_step(*m, s0, a0, *rng);
    const double r = transition_reward(*m, s0, a0, s2);
    const std::int64_t n = ++steps;
    ret += r;
    double& qsa = Q[static_cast<std::ptrdiff_t>(s0) * A + a0];
    if (m->terminal(s2)) [[unlikely]] {
      qsa += alpha * (r - qsa);
      finish_episode(false);
      return;
    }
    const int a2 = choose(Q + static_cast<std::ptrdiff_t>(s2) * A, A, *rng);
    qsa += alpha * (r + gamma * Q[static_cast<std::ptrdiff_t>(s2) * A + a2] - qsa);
    s = s2;
    a = a2;
    if (n == max_steps) [[unlikely]]
      finish_episode(true);
  }
};

}  // namespace detail

// On-policy TD control (Sutton and Barto §6.4); the §3.4 experiments' learner. Updates q in place.
template <TabularModel M, UniformSource G>
LearningCurve sarsa(const M& m, const TdOptions& o, G& rng, QTable& q) {
  detail::check_learner_input(m, o, q);
  LearningCurve curve;
  detail::SarsaLane<M, G> lane;
  lane.start(m, o, rng, q, curve);
  while (lane.active) lane.step();
  return curve;
}

// Independent Sarsa runs (run i uses rngs[i] and qs[i]), stepped in lockstep four at a time on the calling
// thread. A Sarsa step is one long dependency chain (state -> successor -> its Q row -> action -> next
// state), so a single run leaves most of the core idle; interleaving runs fills it. Each run's result is
// identical to sarsa(m, o, rngs[i], qs[i]).
template <TabularModel M, UniformSource G>
std::vector<LearningCurve> sarsa_runs(const M& m, const TdOptions& o, std::span<G> rngs,
                                      std::span<QTable> qs) {
  if (rngs.size() != qs.size()) throw InputError("sarsa_runs: one generator per Q table expected");
  for (const QTable& q : qs) detail::check_learner_input(m, o, q);
  constexpr std::size_t kLanes = 4;
  std::vector<LearningCurve> curves(qs.size());
  for (std::size_t first = 0; first < qs.size(); first += kLanes) {
    const std::size_t n = std::min(kLanes, qs.size() - first);
    std::array<detail::SarsaLane<M, G>, kLanes> lanes;
    for (std::size_t j = 0; j < n; ++j)
      lanes[j].start(m, o, rngs[first + j], qs[first + j], curves[first + j]);
    for (std::size_t j = n; j < kLanes; ++j) lanes[j].active = false;
    if (n == kLanes) {
      while (lanes[0].active && lanes[1].active && lanes[2].active && lanes[3].active) {
        lanes[0].step();
        lanes[1].step();
        lanes[2].step();
        lanes[3].step();
      }
    }
    for (std::size_t j = 0; j < n; ++j)
      while (lanes[j].active) lanes[j].step();
  }
  return curves;
}

// Off-policy TD control, Eq 2.18, with epsilon-greedy behaviour.
template <TabularModel M, UniformSource G>
LearningCurve q_learning(const M& m, const TdOptions& o, G& rng, QTable& q) {
  detail::check_learner_input(m, o, q);
  const int A = m.num_actions();
  const EpsilonGreedy choose(o.epsilon, A);
  double* const Q = q.q.data();
  LearningCurve curve;
  for (int ep = 0; ep < o.episodes; ++ep) {
    int s = detail::draw_initial(m, rng);
    std::int64_t steps = 0;
    double ret = 0.0;
    while (!m.terminal(s) && steps < o.max_steps_per_episode) {
      const int a = choose(Q + static_cast<std::ptrdiff_t>(s) * A, A, rng);
      const int s2 = detail::draw_step(m, s, a, rng);
      const double r = transition_reward(m, s, a, s2);
      ++steps;
      ret += r;
      double target = r;
      if (!m.terminal(s2)) {
        const double* row = Q + static_cast<std::ptrdiff_t>(s2) * A;
        target += o.gamma * *std::max_element(row, row + A);
      }
      double& qsa = Q[static_cast<std::ptrdiff_t>(s) * A + a];
      qsa += o.alpha * (target - qsa);
      s = s2;
    }
    if (!m.terminal(s)) ++curve.truncated_episodes;
    curve.steps.push_back(steps);
    curve.returns.push_back(ret);
    curve.total_steps += steps;
  }
  return curve;
}

// Sarsa(lambda) with replacing traces (Singh and Sutton 1996): visiting (s, a) sets e(s, a) = 1 and clears
// the traces of the other actions in s. Only the (s, a) with a live trace are touched each step; traces
// that decay below trace_cutoff are dropped.
template <TabularModel M, UniformSource G>
LearningCurve sarsa_lambda(const M& m, const TdOptions& o, G& rng, QTable& q) {
  detail::check_learner_input(m, o, q);
  const int A = m.num_actions();
  const EpsilonGreedy choose(o.epsilon, A);
  double* const Q = q.q.data();
  std::vector<double> e(q.q.size(), 0.0);
  std::vector<std::uint8_t> listed(q.q.size(), 0);
  std::vector<std::int32_t> live;
  live.reserve(1024);
  const double decay = o.gamma * o.lambda;
  LearningCurve curve;
  for (int ep = 0; ep < o.episodes; ++ep) {
    int s = detail::draw_initial(m, rng);
    std::int64_t steps = 0;
    double ret = 0.0;
    if (!m.terminal(s)) {
      int a = choose(Q + static_cast<std::ptrdiff_t>(s) * A, A, rng);
      while (steps < o.max_steps_per_episode) {
        const int s2 = detail::draw_step(m, s, a, rng);
        const double r = transition_reward(m, s, a, s2);
        ++steps;
        ret += r;
        const bool end = m.terminal(s2);
        const int a2 = end ? 0 : choose(Q + static_cast<std::ptrdiff_t>(s2) * A, A, rng);
        const std::int32_t i = s * A + a;
        const double delta = r + (end ? 0.0 : o.gamma * Q[s2 * A + a2]) - Q[i];
        for (int b = 0; b < A; ++b) e[static_cast<std::size_t>(s * A + b)] = 0.0;
        e[static_cast<std::size_t>(i)] = 1.0;
        if (!listed[static_cast<std::size_t>(i)]) {
          listed[static_cast<std::size_t>(i)] = 1;
          live.push_back(i);
        }
        for (std::size_t j = 0; j < live.size();) {
          const auto k = static_cast<std::size_t>(live[j]);
          Q[k] += o.alpha * delta * e[k];
          e[k] *= decay;
          if (e[k] <= o.trace_cutoff) {
            e[k] = 0.0;
            listed[k] = 0;
            live[j] = live.back();
            live.pop_back();
          } else {
            ++j;
          }
        }
        if (end) break;
        s = s2;
        a = a2;
      }
      if (!m.terminal(s) && steps == o.max_steps_per_episode) ++curve.truncated_episodes;
      for (auto k : live) {
        e[static_cast<std::size_t>(k)] = 0.0;
        listed[static_cast<std::size_t>(k)] = 0;
      }
      live.clear();
    }
    curve.steps.push_back(steps);
    curve.returns.push_back(ret);
    curve.total_steps += steps;
  }
  return curve;
}

// ---- REINFORCE (Williams 1992; thesis §2.3) -----------------------------------------------------------

// pi(a | s) = exp(theta(s, a)) / sum_b exp(theta(s, b)).
struct SoftmaxPolicy {
  int num_states = 0, num_actions = 0;
  std::vector<double> theta;

  SoftmaxPolicy() = default;
  SoftmaxPolicy(int s, int a)
      : num_states(s),
        num_actions(a),
        theta(static_cast<std::size_t>(s) * static_cast<std::size_t>(a), 0.0) {}
  // Writes pi(. | s) into out (size num_actions).
  void probabilities(int s, double* out) const {
    const double* t = theta.data() + static_cast<std::size_t>(s) * static_cast<std::size_t>(num_actions);
    const double mx = *std::max_element(t, t + num_actions);
    double z = 0.0;
    for (int a = 0; a < num_actions; ++a) z += (out[a] = std::exp(t[a] - mx));
    for (int a = 0; a < num_actions; ++a) out[a] /= z;
  }
};

struct ReinforceOptions {
  // Number of episodes. Must be >= 1.
  int episodes = 1000;
  // Step size of the stochastic gradient ascent, > 0.
  double alpha = 0.1;
  // Discount in [0, 1].
  double gamma = 1.0;
  // Subtract a running average of the episode returns (a constant baseline keeps the gradient unbiased
  // and lowers its variance).
  bool baseline = true;
  // Rate of that running average, in (0, 1].
  double baseline_rate = 0.05;
  // Episode length cap. Must be >= 1.
  std::int64_t max_steps_per_episode = 100'000;

  bool IsValid(std::string* error) const {
    auto bad = [&](const std::string& m) {
      if (error) *error = "REINFORCE options: " + m;
      return false;
    };
    if (episodes < 1) return bad("episodes must be >= 1");
    if (!(alpha > 0.0)) return bad("alpha must be > 0");
    if (!(gamma >= 0.0 && gamma <= 1.0)) return bad("gamma must lie in [0, 1]");
    if (!(baseline_rate > 0.0 && baseline_rate <= 1.0)) return bad("baseline_rate must lie in (0, 1]");
    if (max_steps_per_episode < 1) return bad("max_steps_per_episode must be >= 1");
    return true;
  }
};

// Monte Carlo policy gradient: after each episode, theta(s_t, .) += alpha gamma^t (G_t - b)
// grad log pi(a_t | s_t), with grad_theta(s,b) log pi(a | s) = 1[b = a] - pi(b | s) for the softmax.
template <TabularModel M, UniformSource G>
LearningCurve reinforce(const M& m, const ReinforceOptions& o, G& rng, SoftmaxPolicy& pi) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError(err);
  check_noise_dims(m);
  if (pi.num_states != m.num_states() || pi.num_actions != m.num_actions())
    throw InputError("REINFORCE: policy table does not match the model");
  const int A = m.num_actions();
  std::vector<int> states, actions;
  std::vector<double> rewards, probs(static_cast<std::size_t>(A));
  double baseline = 0.0;
  bool have_baseline = false;
  LearningCurve curve;
  for (int ep = 0; ep < o.episodes; ++ep) {
    states.clear();
    actions.clear();
    rewards.clear();
    int s = detail::draw_initial(m, rng);
    while (!m.terminal(s) && static_cast<std::int64_t>(states.size()) < o.max_steps_per_episode) {
      pi.probabilities(s, probs.data());
      const double u = rng.next();
      int a = 0;
      for (double c = probs[0]; a + 1 < A && u >= c; c += probs[static_cast<std::size_t>(++a)]) {
      }
      const int s2 = detail::draw_step(m, s, a, rng);
      states.push_back(s);
      actions.push_back(a);
      rewards.push_back(transition_reward(m, s, a, s2));
      s = s2;
    }
    if (!m.terminal(s)) ++curve.truncated_episodes;
    const std::size_t T = states.size();
    double undiscounted = 0.0;
    for (double r : rewards) undiscounted += r;
    double g = 0.0;
    std::vector<double>& returns = rewards;  // overwritten in place by G_t
    for (std::size_t t = T; t-- > 0;) returns[t] = g = rewards[t] + o.gamma * g;
    const double g0 = T > 0 ? returns[0] : 0.0;
    const double b = (o.baseline && have_baseline) ? baseline : 0.0;
    double discount = 1.0;
    for (std::size_t t = 0; t < T; ++t) {
      const int st = states[t];
      pi.probabilities(st, probs.data());
      double* th = pi.theta.data() + static_cast<std::size_t>(st) * static_cast<std::size_t>(A);
      const double step = o.alpha * discount * (returns[t] - b);
      for (int a = 0; a < A; ++a)
        th[a] += step * ((a == actions[t] ? 1.0 : 0.0) - probs[static_cast<std::size_t>(a)]);
      discount *= o.gamma;
    }
    if (o.baseline) {
      baseline = have_baseline ? baseline + o.baseline_rate * (g0 - baseline) : g0;
      have_baseline = true;
    }
    curve.steps.push_back(static_cast<std::int64_t>(T));
    curve.returns.push_back(undiscounted);
    curve.total_steps += static_cast<std::int64_t>(T);
  }
  return curve;
}

}  // namespace pegasus
