#pragma once
// The shortest-path gridworld of thesis §3.4 (Fig 3.1a): start and goal in opposite corners, -1 per step,
// no discounting; each action moves one cell in its compass direction with probability `intended` and in
// a uniformly random direction (possibly the intended one) otherwise, so the intended cell is reached
// with probability intended + (1 - intended)/4 (0.85 for the thesis's 80/20 split). Moves off the grid or
// into a blocked cell leave the agent in place.
//
// GridWorld is a SimulativeModel (models/model.hpp) with State = Action = Observation = int, so learners
// inline its step; to_finite_mdp gives the same problem as an explicit FiniteMdp for the solvers.
// A cell (x, y) has index y * width + x; y = 0 is the bottom row, where the start is.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "pegasus/mdp/finite_mdp.hpp"
#include "pegasus/models/action_space.hpp"

namespace pegasus {

struct Cell {
  int x = 0, y = 0;
  bool operator==(const Cell&) const = default;
};

// Compass actions.
enum GridAction : int { kNorth = 0, kEast = 1, kSouth = 2, kWest = 3 };
inline constexpr int kGridActions = 4;

// Grid geometry and the move table shared by the gridworld and the flag world.
class GridGeometry {
 public:
  GridGeometry(int width, int height, const std::vector<Cell>& blocked = {});

  int width() const { return width_; }
  int height() const { return height_; }
  int num_cells() const { return width_ * height_; }
  int index(Cell c) const { return c.y * width_ + c.x; }
  Cell cell(int index) const { return {index % width_, index / width_}; }
  bool inside(Cell c) const { return c.x >= 0 && c.y >= 0 && c.x < width_ && c.y < height_; }
  bool blocked(int index) const { return blocked_[static_cast<std::size_t>(index)] != 0; }
  // The cell reached from `index` by moving in direction d (itself at walls and blocked cells).
  int move(int index, int d) const {
    return moves_[static_cast<std::size_t>(index) * kGridActions + static_cast<std::size_t>(d)];
  }
  int manhattan(int a, int b) const;

 private:
  int width_, height_;
  std::vector<std::uint8_t> blocked_;
  std::vector<std::int32_t> moves_;
};

// The direction actually moved, from the intended action and one uniform u in (0, 1): u < intended keeps
// the action, otherwise the remaining interval is split into four equal parts, one per direction.
// slip_scale = 4 / (1 - intended), precomputed so that the step has no division (and no branch).
inline int realised_direction(int action, double u, double intended, double slip_scale) {
  int d = static_cast<int>((u - intended) * slip_scale);
  d = d < 3 ? d : 3;
  d = d > 0 ? d : 0;
  return u < intended ? action : d;
}
inline double slip_scale(double intended) { return intended < 1.0 ? 4.0 / (1.0 - intended) : 0.0; }

class GridWorld {
 public:
  using State = int;
  using Action = int;
  using Observation = int;

  // intended in (0, 1]; start and goal distinct, inside and not blocked.
  GridWorld(GridGeometry geometry, Cell start, Cell goal, double intended = 0.8, double step_reward = -1.0);

  // SimulativeModel.
  int state_dim() const { return 1; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 0; }
  State initial_state(std::span<const double>) const { return start_; }
  State step(State s, Action a, std::span<const double> p) const {
    return geometry_.move(s, realised_direction(a, p[0], intended_, slip_scale_));
  }
  double reward(State, Action) const { return step_reward_; }
  bool terminal(State s) const { return s == goal_; }
  Observation observe(State s) const { return s; }
  ActionSpace action_space() const { return ActionSpace::finite(kGridActions); }

  // Tabular.
  int num_states() const { return geometry_.num_cells(); }
  int num_actions() const { return kGridActions; }

  const GridGeometry& geometry() const { return geometry_; }
  int start() const { return start_; }
  int goal() const { return goal_; }
  double intended() const { return intended_; }
  double step_reward() const { return step_reward_; }
  int distance_to_goal(State s) const { return geometry_.manhattan(s, goal_); }

 private:
  GridGeometry geometry_;
  int start_, goal_;
  double intended_, step_reward_, slip_scale_;
};

// The §3.4 gridworld: n x n, start (0, 0), goal (n-1, n-1), 80/20 moves, -1 per step.
GridWorld corner_gridworld(int n, double intended = 0.8);

// The same problem as a FiniteMdp (goal absorbing, D = start). gamma = 1 as in the thesis.
FiniteMdp to_finite_mdp(const GridWorld& world, double gamma = 1.0);

// Phi0(s) = -scale * manhattan(s, goal) / intended: the §3.4 estimate of V* (about `intended` cells of
// progress per step). scale = 1 gives Phi0, 0.5 gives the thesis's 0.5 Phi0. Phi(goal) = 0.
std::vector<double> manhattan_potential(const GridWorld& world, double scale = 1.0);

}  // namespace pegasus
