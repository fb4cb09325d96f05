#pragma once
// U-hat of EVERY table policy (finite observations -> finite actions) on fixed PEGASUS scenarios, without
// rolling each policy out separately. Policies that agree on the observations a scenario actually visits
// share that scenario's trajectory, so the search walks a tree of partial assignments: each scenario runs
// until it meets an observation whose action is still unassigned, and only such an observation is branched
// on. A leaf (every scenario finished) gives one U-hat shared by all policies that extend its partial
// assignment. Each scenario's return is accumulated by exactly the operations of scenario_return and the
// mean is taken in scenario order, so every value is bit-identical to PegasusEvaluator's.
#include <cstdint>
#include <span>
#include <vector>

#include "pegasus/evaluators/pegasus_evaluator.hpp"

namespace pegasus {

template <SimulativeModel M>
requires std::convertible_to<typename M::Observation, int> && std::convertible_to<int, typename M::Action>
class TablePolicyValues {
 public:
  // observations: number of observation classes a policy maps; values are indexed as TablePolicy
  // enumerates policies (observation 0 least significant). Keeps references to model and scenarios: both
  // must outlive this object.
  TablePolicyValues(const M& model, int observations, const ScenarioSet& scenarios, Discounting d)
      : model_(model),
        observations_(observations),
        actions_(model.action_space().count()),
        scenarios_(scenarios),
        d_(d) {
    validate(d_);
    if (observations < 1 || observations > 16)
      throw InputError("table policy search: expected 1..16 observations");
    if (scenarios.horizon() < d.horizon) throw InputError("scenarios: hold fewer steps than the horizon");
    policies_ = 1;
    for (int o = 0; o < observations; ++o) policies_ *= static_cast<std::uint64_t>(actions_);
    if (policies_ > (1ull << 32)) throw InputError("table policy search: more than 2^32 policies");
    // The scenarios' noise is read once into a flat table: the walk revisits the same steps many times.
    const int m = scenarios.size(), dp = model.noise_dim();
    noise_.resize(static_cast<std::size_t>(m) * static_cast<std::size_t>(d.horizon) *
                  static_cast<std::size_t>(dp));
    for (int i = 0; i < m; ++i)
      for (int t = 0; t < d.horizon; ++t)
        scenarios.step_noise(
            i, t, std::span<double>(noise_.data() + noise_index(i, t), static_cast<std::size_t>(dp)));
    initial_.resize(static_cast<std::size_t>(m));
    NoiseBuffer p0(static_cast<std::size_t>(model.initial_noise_dim()));
    for (int i = 0; i < m; ++i) {
      scenarios.initial_noise(i, p0.span());
      initial_[static_cast<std::size_t>(i)] = model.initial_state(p0.span());
    }
  }

  std::uint64_t policy_count() const { return policies_; }

  // values.size() == policy_count(). Returns the number of leaves (distinct shared evaluations).
  std::uint64_t compute(std::span<double> values, ThreadPool* pool = nullptr) const {
    Node root = make_root();
    // Split the top of the tree into independent subtrees, then walk those in parallel. Each leaf writes
    // only its own policies' slots, so the order of the walk does not matter.
    std::vector<Node> tasks;
    std::uint64_t leaves = 0;
    expand(root, kSplitDepth, tasks, values, leaves);
    std::vector<std::uint64_t> task_leaves(tasks.size(), 0);
    auto body = [&](std::size_t k) {
      std::vector<Node> stack(static_cast<std::size_t>(observations_) + 2, Node{});
      task_leaves[k] = walk(tasks[k], stack, 0, values);
    };
    if (pool) {
      pool->parallel_for(tasks.size(), body);
    } else {
      for (std::size_t k = 0; k < tasks.size(); ++k) body(k);
    }
    for (auto l : task_leaves) leaves += l;
    return leaves;
  }

 private:
  static constexpr int kSplitDepth = 3;
  using State = typename M::State;

  struct Walker {
    State s{};
    int t = 0;
    int waiting = -1;  // observation it needs an action for; -1 when finished
    double ret = 0.0, weight = 1.0;
  };
  struct Node {
    std::array<int, 16> assignment;  // -1: unassigned
    std::vector<Walker> walkers;
    int depth = 0;
  };

  std::size_t noise_index(int i, int t) const {
    return (static_cast<std::size_t>(i) * static_cast<std::size_t>(d_.horizon) +
            static_cast<std::size_t>(t)) *
           static_cast<std::size_t>(model_.noise_dim());
  }

  // Runs a scenario until it finishes or needs an unassigned observation; the same operations, in the
  // same order, as scenario_return.
  void advance(Walker& w, int i, const std::array<int, 16>& assignment) const {
    const auto dp = static_cast<std::size_t>(model_.noise_dim());
    while (w.t < d_.horizon && !model_.terminal(w.s)) {
      const int o = static_cast<int>(model_.observe(w.s));
      const int a = assignment[static_cast<std::size_t>(o)];
      if (a < 0) {
        w.waiting = o;
        return;
      }
      const auto action = static_cast<typename M::Action>(a);
      const State next =
          model_.step(w.s, action, std::span<const double>(noise_.data() + noise_index(i, w.t), dp));
      accumulate_transition(model_, w.s, action, next, d_.gamma, w.weight, w.ret);
      w.weight *= d_.gamma;
      w.s = next;
      ++w.t;
    }
    w.waiting = -1;
  }

  Node make_root() const {
    Node root;
    root.assignment.fill(-1);
    root.walkers.resize(static_cast<std::size_t>(scenarios_.size()));
    for (int i = 0; i < scenarios_.size(); ++i) {
      auto& w = root.walkers[static_cast<std::size_t>(i)];
      w.s = initial_[static_cast<std::size_t>(i)];
      advance(w, i, root.assignment);
    }
    return root;
  }

  int branch_observation(const Node& node) const {
    for (const auto& w : node.walkers)
      if (w.waiting >= 0) return w.waiting;
    return -1;
  }

  void make_child(const Node& parent, int o, int a, Node& child) const {
    child.assignment = parent.assignment;
    child.assignment[static_cast<std::size_t>(o)] = a;
    child.walkers = parent.walkers;  // capacity is reused after the first use of a stack slot
    child.depth = parent.depth + 1;
    for (std::size_t i = 0; i < child.walkers.size(); ++i)
      if (child.walkers[i].waiting == o) advance(child.walkers[i], static_cast<int>(i), child.assignment);
  }

  // U-hat of the leaf, written to every policy that extends its assignment.
  void fill_leaf(const Node& node, std::span<double> values) const {
    double sum = 0.0;
    for (const auto& w : node.walkers) sum += w.ret;
    const double value = sum / static_cast<double>(node.walkers.size());
    std::uint64_t base = 0, stride = 1;
    std::array<std::uint64_t, 16> free_stride{};
    int free_count = 0;
    for (int o = 0; o < observations_; ++o) {
      const int a = node.assignment[static_cast<std::size_t>(o)];
      if (a >= 0) {
        base += static_cast<std::uint64_t>(a) * stride;
      } else {
        free_stride[static_cast<std::size_t>(free_count++)] = stride;
      }
      stride *= static_cast<std::uint64_t>(actions_);
    }
    std::uint64_t combos = 1;
    for (int k = 0; k < free_count; ++k) combos *= static_cast<std::uint64_t>(actions_);
    for (std::uint64_t c = 0; c < combos; ++c) {
      std::uint64_t index = base, rest = c;
      for (int k = 0; k < free_count; ++k) {
        index += (rest % static_cast<std::uint64_t>(actions_)) * free_stride[static_cast<std::size_t>(k)];
        rest /= static_cast<std::uint64_t>(actions_);
      }
      values[index] = value;
    }
  }

  void expand(const Node& node, int depth, std::vector<Node>& tasks, std::span<double> values,
              std::uint64_t& leaves) const {
    const int o = branch_observation(node);
    if (o < 0) {
      fill_leaf(node, values);
      ++leaves;
      return;
    }
    if (depth == 0) {
      tasks.push_back(node);
      return;
    }
    for (int a = 0; a < actions_; ++a) {
      Node child;
      make_child(node, o, a, child);
      expand(child, depth - 1, tasks, values, leaves);
    }
  }

  std::uint64_t walk(const Node& node, std::vector<Node>& stack, std::size_t level,
                     std::span<double> values) const {
    const int o = branch_observation(node);
    if (o < 0) {
      fill_leaf(node, values);
      return 1;
    }
    std::uint64_t leaves = 0;
    Node& child = stack[level];
    for (int a = 0; a < actions_; ++a) {
      make_child(node, o, a, child);
      leaves += walk(child, stack, level + 1, values);
    }
    return leaves;
  }

  const M& model_;
  int observations_;
  int actions_;
  const ScenarioSet& scenarios_;
  Discounting d_;
  std::uint64_t policies_ = 0;
  std::vector<double> noise_;
  std::vector<State> initial_;
};

}  // namespace pegasus
