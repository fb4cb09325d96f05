#include "pegasus/envs/pomdp_gridworld.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "pegasus/core/error.hpp"

namespace pegasus {

PomdpGridworld::PomdpGridworld(Layout layout) : layout_(std::move(layout)) {
  const int w = layout_.width, h = layout_.height;
  if (w < 2 || h < 2 || w * h > 4096)
    throw InputError(fmt::format("gridworld: expected 2..64 squares per side, got {}x{}", w, h));
  auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < w && y < h; };
  auto cell = [&](int x, int y) { return y * w + x; };
  for (auto [x, y] : {layout_.start, layout_.goal})
    if (!inside(x, y))
      throw InputError(fmt::format("gridworld: square ({}, {}) lies outside the grid", x, y));
  wall_.assign(static_cast<std::size_t>(w * h), false);
  for (auto [x, y] : layout_.walls) {
    if (!inside(x, y)) throw InputError(fmt::format("gridworld: wall ({}, {}) lies outside the grid", x, y));
    wall_[static_cast<std::size_t>(cell(x, y))] = true;
  }
  start_ = cell(layout_.start.first, layout_.start.second);
  goal_ = cell(layout_.goal.first, layout_.goal.second);
  if (start_ == goal_ || wall_[static_cast<std::size_t>(start_)] || wall_[static_cast<std::size_t>(goal_)])
    throw InputError("gridworld: start and goal must be distinct open squares");

  auto blocked = [&](int x, int y) { return !inside(x, y) || wall_[static_cast<std::size_t>(cell(x, y))]; };
  // Neighbours clockwise from north: N, NE, E, SE, S, SW, W, NW.
  constexpr int dx[8] = {0, 1, 1, 1, 0, -1, -1, -1};
  constexpr int dy[8] = {1, 1, 0, -1, -1, -1, 0, 1};
  observation_.assign(static_cast<std::size_t>(w * h), -1);
  moves_.assign(static_cast<std::size_t>(w * h * kActions), 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int s = cell(x, y);
      // up, left, down, right
      const int mx[4] = {0, -1, 0, 1}, my[4] = {1, 0, -1, 0};
      for (int a = 0; a < kActions; ++a)
        moves_[static_cast<std::size_t>(s * kActions + a)] =
            blocked(x + mx[a], y + my[a]) ? s : cell(x + mx[a], y + my[a]);
      if (s == goal_ || wall_[static_cast<std::size_t>(s)]) continue;
      unsigned mask = 0;
      for (int k = 0; k < 8; ++k)
        if (blocked(x + dx[k], y + dy[k])) mask |= 1u << k;
      auto it = std::find(masks_.begin(), masks_.end(), mask);
      if (it == masks_.end()) {
        masks_.push_back(mask);
        it = masks_.end() - 1;
      }
      observation_[static_cast<std::size_t>(s)] = static_cast<int>(it - masks_.begin());
    }
  observations_ = static_cast<int>(masks_.size());
  observation_[static_cast<std::size_t>(goal_)] = observations_;
  if (observations_ > 16)
    throw InputError(
        "gridworld: more than 16 observation classes; the table policy class would be too large");
}

std::array<std::pair<PomdpGridworld::State, double>, 5> PomdpGridworld::transitions(State s, Action a) const {
  std::array<std::pair<State, double>, 5> out;
  double lower = 0.0;
  for (int k = 0; k < 4; ++k) {
    out[static_cast<std::size_t>(k)] = {moves_[static_cast<std::size_t>(s * kActions + k)],
                                        kSlipThresholds[static_cast<std::size_t>(k)] - lower};
    lower = kSlipThresholds[static_cast<std::size_t>(k)];
  }
  out[4] = {moves_[static_cast<std::size_t>(s * kActions + a)], 1.0 - lower};
  return out;
}

double PomdpGridworld::exact_value(std::span<const double> theta, const Discounting& d) const {
  validate(d);
  const int n = cells();
  std::vector<double> v(static_cast<std::size_t>(n), 0.0), next(static_cast<std::size_t>(n), 0.0);
  // v_k(s) = expected discounted return of the remaining k steps; v_0 = 0, absorbing goal stays 0.
  for (int k = 0; k < d.horizon; ++k) {
    for (int s = 0; s < n; ++s) {
      if (s == goal_ || wall_[static_cast<std::size_t>(s)]) continue;
      const int a = static_cast<int>(theta[static_cast<std::size_t>(observe(s))]);
      double expected = 0.0;
      for (auto [s2, prob] : transitions(s, a)) expected += prob * v[static_cast<std::size_t>(s2)];
      next[static_cast<std::size_t>(s)] = reward(s, a) + d.gamma * expected;
    }
    std::swap(v, next);
  }
  return v[static_cast<std::size_t>(start_)];
}

std::vector<double> PomdpGridworld::exact_values_of_all_policies(const Discounting& d,
                                                                 ThreadPool* pool) const {
  std::size_t count = 1;
  for (int o = 0; o < observations_; ++o) count *= kActions;
  std::vector<double> values(count);
  auto body = [&](std::size_t index) {
    std::array<double, 16> theta{};
    std::size_t rest = index;
    for (int o = 0; o < observations_; ++o) {
      theta[static_cast<std::size_t>(o)] = static_cast<double>(rest % kActions);
      rest /= kActions;
    }
    values[index] =
        exact_value(std::span<const double>(theta.data(), static_cast<std::size_t>(observations_)), d);
  };
  if (pool) {
    pool->parallel_for(count, body, 64);
  } else {
    for (std::size_t i = 0; i < count; ++i) body(i);
  }
  return values;
}

}  // namespace pegasus
