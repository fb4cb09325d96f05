#include "pegasus/envs/gridworld.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <utility>

#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {
constexpr std::array<int, kGridActions> kDx = {0, 1, 0, -1};
constexpr std::array<int, kGridActions> kDy = {1, 0, -1, 0};
}  // namespace

GridGeometry::GridGeometry(int width, int height, const std::vector<Cell>& blocked)
    : width_(width), height_(height) {
  if (width < 1 || height < 1 || static_cast<long long>(width) * height > (1LL << 30))
    throw InputError(
        fmt::format("gridworld: size {} x {} must be at least 1 x 1 and at most 2^30 cells", width, height));
  blocked_.assign(static_cast<std::size_t>(num_cells()), 0);
  for (const Cell& c : blocked) {
    if (!inside(c))
      throw InputError(fmt::format("gridworld: blocked cell ({}, {}) outside the grid", c.x, c.y));
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
    : geometry_(std::move(geometry)),
      intended_(intended),
      step_reward_(step_reward),
      slip_scale_(slip_scale(intended)) {
  if (!geometry_.inside(start))
    throw InputError(fmt::format("gridworld: start ({}, {}) outside the grid", start.x, start.y));
  if (!geometry_.inside(goal))
    throw InputError(fmt::format("gridworld: goal ({}, {}) outside the grid", goal.x, goal.y));
  start_ = geometry_.index(start);
  goal_ = geometry_.index(goal);
  if (start_ == goal_) throw InputError("gridworld: start and goal must differ");
  if (geometry_.blocked(start_) || geometry_.blocked(goal_))
    throw InputError("gridworld: start and goal must not be blocked");
  if (!(intended > 0.0 && intended <= 1.0))
    throw InputError(fmt::format("gridworld: intended probability {} outside (0, 1]", intended));
}

GridWorld corner_gridworld(int n, double intended) {
  if (n < 2) throw InputError(fmt::format("gridworld: size must be >= 2, got {}", n));
  return GridWorld(GridGeometry(n, n), Cell{0, 0}, Cell{n - 1, n - 1}, intended, -1.0);
}

FiniteMdp to_finite_mdp(const GridWorld& w, double gamma) {
  // Written straight into the CSR arrays (no per-row containers): the 1000 x 1000 benchmark grid has 4M
  // rows. Directions that end in the same cell (walls) are merged into one entry.
  const GridGeometry& g = w.geometry();
  if (!(gamma >= 0.0 && gamma <= 1.0))
    throw InputError(fmt::format("gridworld: gamma must lie in [0, 1], got {}", gamma));
  FiniteMdp m;
  m.num_states = w.num_states();
  m.num_actions = kGridActions;
  m.gamma = gamma;
  const std::size_t S = static_cast<std::size_t>(m.num_states);
  m.absorbing.assign(S, 0);
  m.absorbing[static_cast<std::size_t>(w.goal())] = 1;
  m.initial.assign(S, 0.0);
  m.initial[static_cast<std::size_t>(w.start())] = 1.0;
  m.row_start.reserve(S * kGridActions + 1);
  m.next_state.reserve(S * kGridActions * 4);
  m.probability.reserve(S * kGridActions * 4);
  m.reward.reserve(S * kGridActions * 4);
  m.row_start.push_back(0);
  const double slip = (1.0 - w.intended()) / 4.0;
  for (int s = 0; s < m.num_states; ++s) {
    for (int a = 0; a < kGridActions; ++a) {
      if (s == w.goal()) {
        m.next_state.push_back(s);
        m.probability.push_back(1.0);
        m.reward.push_back(0.0);
      } else {
        std::array<std::pair<int, double>, kGridActions> e{};
        int n = 0;
        for (int d = 0; d < kGridActions; ++d) {
          const double p = (d == a ? w.intended() : 0.0) + slip;
          if (p <= 0.0) continue;
          const int next = g.move(s, d);
          int k = 0;
          while (k < n && e[static_cast<std::size_t>(k)].first != next) ++k;
          if (k == n) e[static_cast<std::size_t>(n++)] = {next, 0.0};
          e[static_cast<std::size_t>(k)].second += p;
        }
        std::sort(e.begin(), e.begin() + n);
        for (int k = 0; k < n; ++k) {
          m.next_state.push_back(e[static_cast<std::size_t>(k)].first);
          m.probability.push_back(std::min(1.0, e[static_cast<std::size_t>(k)].second));
          m.reward.push_back(w.step_reward());
        }
      }
      m.row_start.push_back(static_cast<std::uint32_t>(m.next_state.size()));
    }
  }
  m.refresh_expected_reward();
  validate(m, "gridworld");
  return m;
}

std::vector<double> manhattan_potential(const GridWorld& w, double scale) {
  std::vector<double> phi(static_cast<std::size_t>(w.num_states()));
  for (int s = 0; s < w.num_states(); ++s)
    phi[static_cast<std::size_t>(s)] = -scale * w.distance_to_goal(s) / w.intended();
  return phi;
}

}  // namespace pegasus
