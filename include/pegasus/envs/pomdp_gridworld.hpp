#pragma once
// The POMDP gridworld of thesis §4.6 (Fig 4.5a): the agent starts bottom-left and pays -1 per step until
// it reaches the absorbing goal top-right. It observes only which of its eight neighbouring squares are
// walls (the border counts as wall), which on an open 5x5 grid gives 8 distinct observations off the goal.
// The deterministic simulative model is the one printed in §4.6:
//   g(s, a, p) = move(s, up) if p <= 0.05, left if p <= 0.10, down if p <= 0.15, right if p <= 0.20,
//                move(s, a) otherwise;  a move into a wall leaves s unchanged.
#include <array>
#include <span>
#include <utility>
#include <vector>

#include "pegasus/evaluators/rollout.hpp"
#include "pegasus/models/action_space.hpp"
#include "pegasus/parallel/thread_pool.hpp"

namespace pegasus {

class PomdpGridworld {
 public:
  using State = int;        // cell = y * width + x, y = 0 is the bottom row
  using Action = int;       // kUp, kLeft, kDown, kRight
  using Observation = int;  // wall-pattern class in [0, observations()); the goal has class observations()

  enum Move : int { kUp = 0, kLeft = 1, kDown = 2, kRight = 3 };
  static constexpr int kActions = 4;
  // Upper ends of the p intervals that slip up, left, down, right (§4.6).
  static constexpr std::array<double, 4> kSlipThresholds = {0.05, 0.10, 0.15, 0.20};

  struct Layout {
    int width = 5;
    int height = 5;
    std::pair<int, int> start = {0, 0};
    std::pair<int, int> goal = {4, 4};
    std::vector<std::pair<int, int>> walls;  // interior wall squares (none in §4.6's open grid)
  };

  PomdpGridworld() : PomdpGridworld(Layout{}) {}
  explicit PomdpGridworld(Layout layout);

  int state_dim() const { return 1; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 0; }
  ActionSpace action_space() const { return ActionSpace::finite(kActions); }
  State initial_state(std::span<const double>) const { return start_; }
  bool terminal(State s) const { return s == goal_; }
  Observation observe(State s) const { return observation_[static_cast<std::size_t>(s)]; }
  double reward(State, Action) const { return -1.0; }

  State step(State s, Action a, std::span<const double> p) const {
    const double u = p[0];
    const int direction = u <= kSlipThresholds[0]   ? kUp
                          : u <= kSlipThresholds[1] ? kLeft
                          : u <= kSlipThresholds[2] ? kDown
                          : u <= kSlipThresholds[3] ? kRight
                                                    : a;
    return moves_[static_cast<std::size_t>(s * kActions + direction)];
  }

  int width() const { return layout_.width; }
  int height() const { return layout_.height; }
  int cells() const { return layout_.width * layout_.height; }
  int observations() const { return observations_; }
  State start() const { return start_; }
  State goal() const { return goal_; }
  bool is_wall(State s) const { return wall_[static_cast<std::size_t>(s)]; }
  // The 8-neighbour wall mask behind observation class o (bit k: neighbour k clockwise from north).
  unsigned mask_of_observation(int o) const { return masks_[static_cast<std::size_t>(o)]; }

  // P(s' | s, a), obtained by integrating g over p: g is constant on each of the five p intervals, so the
  // distribution follows from the same thresholds the simulator uses.
  std::array<std::pair<State, double>, 5> transitions(State s, Action a) const;

  // The exact H-step value sum_{t<H} gamma^t E[R] from the start of the memoryless table policy
  // theta (one action per observation class), by backward induction over the cells: no sampling.
  double exact_value(std::span<const double> theta, const Discounting& d) const;
  // exact_value of every one of the 4^observations() table policies, indexed as TablePolicy enumerates
  // them (observation 0 least significant).
  std::vector<double> exact_values_of_all_policies(const Discounting& d, ThreadPool* pool) const;

 private:
  Layout layout_;
  State start_ = 0, goal_ = 0;
  int observations_ = 0;
  std::vector<bool> wall_;
  std::vector<int> observation_;
  std::vector<unsigned> masks_;
  std::vector<State> moves_;  // [s * 4 + direction]
};

}  // namespace pegasus
