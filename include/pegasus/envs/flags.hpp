#pragma once
// The flag-collecting gridworld of thesis §3.4 (Fig 3.1b): the agent starts in the bottom-left corner and
// must visit the flags in order; the last flag is the goal. Moves and rewards are those of the §3.4
// gridworld (80/20 moves, -1 per step, no discounting). The state records the flags collected so far:
// state = collected * cells + cell for collected in [0, n), and one terminal state n * cells entered when
// the goal (flag n) is reached. Stepping onto the next flag in the sequence collects it; other flags are
// ordinary cells.
//
// The figure's flag positions are not in the text, so the layouts below are ours (see flags.cpp).
#include <span>
#include <vector>

#include "pegasus/envs/gridworld.hpp"

namespace pegasus {

class FlagWorld {
 public:
  using State = int;
  using Action = int;
  using Observation = int;

  // flags: the subgoals in visiting order, the goal last; distinct, inside, none on the start cell.
  FlagWorld(GridGeometry geometry, Cell start, std::vector<Cell> flags, double intended = 0.8,
            double step_reward = -1.0);

  int state_dim() const { return 1; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 0; }
  State initial_state(std::span<const double>) const { return start_; }
  State step(State s, Action a, std::span<const double> p) const {
    if (s == terminal_state_) return s;
    const int collected = s / cells_;
    const int cell =
        geometry_.move(s - collected * cells_, realised_direction(a, p[0], intended_, slip_scale_));
    if (cell != flags_[static_cast<std::size_t>(collected)]) return collected * cells_ + cell;
    return collected + 1 == num_flags() ? terminal_state_ : (collected + 1) * cells_ + cell;
  }
  double reward(State, Action) const { return step_reward_; }
  bool terminal(State s) const { return s == terminal_state_; }
  Observation observe(State s) const { return s; }
  ActionSpace action_space() const { return ActionSpace::finite(kGridActions); }

  int num_states() const { return terminal_state_ + 1; }
  int num_actions() const { return kGridActions; }

  const GridGeometry& geometry() const { return geometry_; }
  int num_flags() const { return static_cast<int>(flags_.size()); }
  int terminal_state() const { return terminal_state_; }
  double intended() const { return intended_; }
  double step_reward() const { return step_reward_; }
  // Flags collected in state s (num_flags() at the terminal state) and the cell (start cell index for
  // the terminal state, which has no cell).
  int collected(State s) const { return s == terminal_state_ ? num_flags() : s / cells_; }
  int cell(State s) const { return s == terminal_state_ ? flags_.back() : s % cells_; }
  State state_of(int collected, int cell) const { return collected * cells_ + cell; }
  // Manhattan length of the remaining flag sequence from s: to the next flag, then flag to flag.
  int remaining_path_length(State s) const;
  // The thesis's estimate t of the steps to the goal: the whole route's Manhattan length / intended.
  double estimated_steps() const;

 private:
  GridGeometry geometry_;
  int cells_, start_, terminal_state_;
  std::vector<int> flags_;  // cell indices
  double intended_, step_reward_, slip_scale_;
};

// 5x5 with 5 subgoals (goal included) and 8x8 with 8, as in §3.4; the positions are our choice.
FlagWorld flags_5x5(double intended = 0.8);
FlagWorld flags_8x8(double intended = 0.8);
// size 5 or 8.
FlagWorld flag_world(int size, double intended = 0.8);

FiniteMdp to_finite_mdp(const FlagWorld& world, double gamma = 1.0);

// Phi0(s) = -((n - n_s - 0.5) / n) * t: with n_s flags collected, about that fraction of the estimated
// t steps remains (§3.4; the 0.5 is the typical case of being halfway to the next flag). Phi(terminal) = 0.
std::vector<double> flags_phi0(const FlagWorld& world);
// Phi1(s) = -(remaining Manhattan length of the flag route from s) / intended: the fine-tuned potential.
std::vector<double> flags_phi1(const FlagWorld& world);

}  // namespace pegasus
