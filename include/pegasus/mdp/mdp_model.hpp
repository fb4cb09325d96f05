#pragma once
// A FiniteMdp seen as a deterministic simulative model g(s, a, p) (thesis §4.2.1): one uniform picks the
// successor by inverting the row's cumulative distribution, so learners, shaping wrappers and PEGASUS
// evaluators run on any finite MDP exactly as on a hand-written environment.
#include <algorithm>
#include <concepts>
#include <span>
#include <vector>

#include "pegasus/mdp/finite_mdp.hpp"
#include "pegasus/models/model.hpp"

namespace pegasus {

// Models the tabular learners accept: integer states and actions with known table sizes.
template <class M>
concept TabularModel = SimulativeModel<M> && std::same_as<typename M::State, int> &&
    std::same_as<typename M::Action, int> && requires(const M& m) {
  { m.num_states() } -> std::convertible_to<int>;
  { m.num_actions() } -> std::convertible_to<int>;
};

class MdpModel {
 public:
  using State = int;
  using Action = int;
  using Observation = int;

  // Keeps a reference: `mdp` must outlive the model.
  explicit MdpModel(const FiniteMdp& mdp) : mdp_(&mdp) {
    cumulative_.resize(mdp.num_entries());
    for (std::size_t r = 0; r < mdp.num_rows(); ++r) {
      double c = 0.0;
      for (std::uint32_t k = mdp.row_start[r]; k < mdp.row_start[r + 1]; ++k)
        cumulative_[k] = (c += mdp.probability[k]);
    }
    initial_cumulative_.resize(static_cast<std::size_t>(mdp.num_states));
    double c = 0.0;
    for (int s = 0; s < mdp.num_states; ++s)
      initial_cumulative_[static_cast<std::size_t>(s)] = (c += mdp.initial[static_cast<std::size_t>(s)]);
  }

  int state_dim() const { return 1; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 1; }
  State initial_state(std::span<const double> p) const {
    const auto it = std::upper_bound(initial_cumulative_.begin(), initial_cumulative_.end(),
                                     p[0] * initial_cumulative_.back());
    return static_cast<int>(std::min<std::ptrdiff_t>(it - initial_cumulative_.begin(), mdp_->num_states - 1));
  }
  State step(State s, Action a, std::span<const double> p) const {
    return mdp_->next_state[entry(s, a, p[0])];
  }
  // R(s, a, s'): the reward of the (s, a) entry whose successor is s'.
  double reward(State s, Action a, State next) const {
    const std::size_t r = mdp_->row(s, a);
    for (std::uint32_t k = mdp_->row_start[r]; k < mdp_->row_start[r + 1]; ++k)
      if (mdp_->next_state[k] == next) return mdp_->reward[k];
    return 0.0;
  }
  bool terminal(State s) const { return mdp_->is_absorbing(s); }
  Observation observe(State s) const { return s; }
  ActionSpace action_space() const { return ActionSpace::finite(mdp_->num_actions); }
  int num_states() const { return mdp_->num_states; }
  int num_actions() const { return mdp_->num_actions; }
  const FiniteMdp& mdp() const { return *mdp_; }

 private:
  std::size_t entry(State s, Action a, double u) const {
    const std::size_t r = mdp_->row(s, a);
    const std::uint32_t b = mdp_->row_start[r], e = mdp_->row_start[r + 1];
    const double target = u * cumulative_[e - 1];  // rows sum to 1 within 1e-9; scale so the last wins
    std::uint32_t k = b;
    while (k + 1 < e && cumulative_[k] <= target) ++k;
    return k;
  }

  const FiniteMdp* mdp_;
  std::vector<double> cumulative_;
  std::vector<double> initial_cumulative_;
};

}  // namespace pegasus
