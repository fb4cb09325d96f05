#include "pegasus/envs/gridworld.hpp"

#include <fmt/format.h>

#include <cstdlib>

#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {
constexpr std::array<int, kGridActions> kDx = {0, 1, 0, -1};
constexpr std::array<int, kGridActions> kDy = {1, 0, -1, 0};
}  // namespace

GridGeometry::GridGeometry(int width, int height, std::vector<Cell> blocked) : width_(width), height_(height) {
  if (width < 1 || height < 1 || static_cast<long long>(width) * height > (1LL << 30))
    throw InputError(fmt::format("gridworld: size {} x {} must be at least 1 x 1 and at most 2^30 cells", width, height));
  blocked_.assign(static_cast<std::size_t>(num_cells()), 0);
  for (const Cell& c : blocked) {
    if (!inside(c)) throw InputError(fmt::format("gridworld: blocked cell ({}, {}) outside the grid", c.x, c.y));
    blocked_[static_cast<std::size_t>(index(c))] = 1;
  }
  moves_.resize(static_cast<std::size_t>(num_cells()) * kGridActions);
  for (int i = 0; i < num_cells(); ++i) {
    const Cell c = cell(i);
    for (int d = 0; d < kGridActions; ++d) {
      const Cell n{c.x + kDx[static_cast<std::size_t>(d)], c.y + kDy[static_cast<std::size_t>(d)]};
      const bool ok = inside(n) && !blocked_[static_cast<std::size_t>(index(n))];
      moves_[static_cast<std::size_t>(i) * kGridActions + static_cast<std::size_t>(d)] = ok ? index(n) : i;
    }
  }
}

int GridGeometry::manhattan(int a, int b) const {
  const Cell ca = cell(a), cb = cell(b);
  return std::abs(ca.x - cb.x) + std::abs(ca.y - cb.y);
}

GridWorld::GridWorld(GridGeometry geometry, Cell start, Cell goal, double intended, double step_reward)
    : geometry_(std::move(geometry)), intended_(intended), step_reward_(step_reward), slip_scale_(slip_scale(intended)) {
  if (!geometry_.inside(start)) throw InputError(fmt::format("gridworld: start ({}, {}) outside the grid", start.x, start.y));
  if (!geometry_.inside(goal)) throw InputError(fmt::format("gridworld: goal ({}, {}) outside the grid", goal.x, goal.y));
  start_ = geometry_.index(start);
  goal_ = geometry_.index(goal);
  if (start_ == goal_) throw InputError("gridworld: start and goal must differ");
  if (geometry_.blocked(start_) || geometry_.blocked(goal_)) throw InputError("gridworld: start and goal must not be blocked");
  if (!(intended > 0.0 && intended <= 1.0)) throw InputError(fmt::format("gridworld: intended probability {} outside (0, 1]", intended));
}

GridWorld corner_gridworld(int n, double intended) {
  if (n < 2) throw InputError(fmt::format("gridworld: size must be >= 2, got {}", n));
  return GridWorld(GridGeometry(n, n), Cell{0, 0}, Cell{n - 1, n - 1}, intended, -1.0);
}

FiniteMdp to_finite_mdp(const GridWorld& w, double gamma) {
  const GridGeometry& g = w.geometry();
  FiniteMdpBuilder b(w.num_states(), kGridActions, gamma);
  b.set_absorbing(w.goal());
  const double slip = (1.0 - w.intended()) / 4.0;
  for (int s = 0; s < w.num_states(); ++s) {
    if (s == w.goal()) continue;
    for (int a = 0; a < kGridActions; ++a) {
      for (int d = 0; d < kGridActions; ++d) {
        const double p = (d == a ? w.intended() : 0.0) + slip;
        if (p > 0.0) b.add_transition(s, a, g.move(s, d), p, w.step_reward());
      }
    }
  }
  b.set_initial(w.start(), 1.0);
  return b.build();
}

std::vector<double> manhattan_potential(const GridWorld& w, double scale) {
  std::vector<double> phi(static_cast<std::size_t>(w.num_states()));
  for (int s = 0; s < w.num_states(); ++s)
    phi[static_cast<std::size_t>(s)] = -scale * w.distance_to_goal(s) / w.intended();
  return phi;
}

}  // namespace pegasus
