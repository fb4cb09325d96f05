#pragma once
// Trajectory trees (Kearns, Mansour and Ng; thesis §4.3, Eq 4.16) for finite action spaces. Each of m
// trees is a complete |A|-ary tree of depth H whose children are drawn from a generative model; built once,
// the trees then evaluate every policy by following its actions. The size is |A|^H per tree by nature,
// so this is only for short horizons (construction refuses more than max_nodes nodes).
#include <cstdint>
#include <span>
#include <vector>

#include "pegasus/evaluators/pegasus_evaluator.hpp"

namespace pegasus {

template <GenerativeModel M>
class TrajectoryTrees {
 public:
  using State = typename M::State;
  using Action = typename M::Action;

  TrajectoryTrees(M model, int trees, Discounting discounting, std::uint64_t seed, ThreadPool* pool = nullptr,
                  std::uint64_t max_nodes = 50'000'000)
      : model_(std::move(model)), trees_(trees), d_(discounting) {
    validate(d_);
    const ActionSpace space = model_.action_space();
    if (!space.is_finite()) throw InputError("trajectory trees: need a finite action space");
    if (trees < 1) throw InputError("trajectory trees: expected m >= 1 trees");
    actions_ = space.count();
    std::uint64_t nodes = 1, level = 1;
    for (int t = 0; t < d_.horizon; ++t) {
      level *= static_cast<std::uint64_t>(actions_);
      nodes += level;
      if (nodes * static_cast<std::uint64_t>(trees) > max_nodes)
        throw InputError("trajectory trees: m |A|^H exceeds the node limit; use a shorter horizon");
    }
    nodes_per_tree_ = nodes;
    states_.resize(nodes * static_cast<std::uint64_t>(trees));
    rewards_.assign(states_.size(), 0.0);
    fractions_.assign(states_.size(), 0.0);
    auto build = [&](std::size_t i) { build_tree(static_cast<int>(i), seed); };
    if (pool) {
      pool->parallel_for(static_cast<std::size_t>(trees), build);
    } else {
      for (int i = 0; i < trees; ++i) build(static_cast<std::size_t>(i));
    }
  }

  int size() const { return trees_; }
  std::uint64_t nodes_per_tree() const { return nodes_per_tree_; }

  // The return of the path that (policy, theta) takes through tree i.
  template <class P>
  double tree_return(const P& policy, std::span<const double> theta, int i) const {
    const std::size_t base = static_cast<std::size_t>(i) * nodes_per_tree_;
    std::size_t node = 0;
    double ret = 0.0, weight = 1.0;
    for (int t = 0; t < d_.horizon; ++t) {
      const State& s = states_[base + node];
      if (model_.terminal(s)) break;
      const auto a = static_cast<std::size_t>(policy.act(theta, model_.observe(s)));
      node = node * static_cast<std::size_t>(actions_) + 1 + a;
      const double tau = fractions_[base + node];
      ret += rewards_[base + node] * weight * (tau > 0.0 ? std::pow(d_.gamma, tau) : 1.0);
      weight *= d_.gamma;
    }
    return ret;
  }

  template <class P>
  double evaluate(const P& policy, std::span<const double> theta) const {
    std::vector<double> returns(static_cast<std::size_t>(trees_));
    for (int i = 0; i < trees_; ++i) returns[static_cast<std::size_t>(i)] = tree_return(policy, theta, i);
    return ordered_mean(returns);
  }

 private:
  void build_tree(int i, std::uint64_t seed) {
    UniformStream rng(seed, static_cast<std::uint32_t>(i));
    const std::size_t base = static_cast<std::size_t>(i) * nodes_per_tree_;
    states_[base] = generative_initial(model_, rng);
    // Breadth-first: node n's children are n |A| + 1 + a, so interior nodes precede their children.
    const std::uint64_t interior = (nodes_per_tree_ - 1) / static_cast<std::uint64_t>(actions_);
    for (std::uint64_t n = 0; n < interior; ++n) {
      const State& s = states_[base + n];
      const bool absorbing = model_.terminal(s);
      for (int a = 0; a < actions_; ++a) {
        const std::size_t child =
            base + n * static_cast<std::uint64_t>(actions_) + 1 + static_cast<std::uint64_t>(a);
        if (absorbing) {  // never followed: a policy's path stops at an absorbing state
          states_[child] = s;
          continue;
        }
        const Action action = static_cast<Action>(a);
        states_[child] = generative_step(model_, s, action, rng);
        rewards_[child] = transition_reward(model_, s, action, states_[child]);
        fractions_[child] = transition_event_fraction(model_, s, action, states_[child]);
      }
    }
  }

  M model_;
  int trees_;
  Discounting d_;
  int actions_ = 0;
  std::uint64_t nodes_per_tree_ = 0;
  std::vector<State> states_;
  std::vector<double> rewards_, fractions_;
};

}  // namespace pegasus
