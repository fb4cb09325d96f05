#include "pegasus/envs/flags.hpp"

#include <fmt/format.h>

#include "pegasus/core/error.hpp"

namespace pegasus {

FlagWorld::FlagWorld(GridGeometry geometry, Cell start, std::vector<Cell> flags, double intended,
                     double step_reward)
    : geometry_(std::move(geometry)),
      intended_(intended),
      step_reward_(step_reward),
      slip_scale_(slip_scale(intended)) {
  cells_ = geometry_.num_cells();
  if (!geometry_.inside(start))
    throw InputError(fmt::format("flags: start ({}, {}) outside the grid", start.x, start.y));
  if (flags.empty()) throw InputError("flags: expected at least one flag (the goal)");
  if (static_cast<long long>(cells_) * static_cast<long long>(flags.size()) >= (1LL << 30))
    throw InputError("flags: too many states");
  start_ = geometry_.index(start);
  for (std::size_t i = 0; i < flags.size(); ++i) {
    const Cell c = flags[i];
    if (!geometry_.inside(c))
      throw InputError(fmt::format("flags: flag {} at ({}, {}) outside the grid", i + 1, c.x, c.y));
    const int idx = geometry_.index(c);
    if (idx == start_) throw InputError(fmt::format("flags: flag {} lies on the start cell", i + 1));
    if (geometry_.blocked(idx)) throw InputError(fmt::format("flags: flag {} lies on a blocked cell", i + 1));
    for (int f : flags_)
      if (f == idx) throw InputError(fmt::format("flags: flag {} repeats an earlier flag's cell", i + 1));
    flags_.push_back(idx);
  }
  if (!(intended > 0.0 && intended <= 1.0))
    throw InputError(fmt::format("flags: intended probability {} outside (0, 1]", intended));
  terminal_state_ = num_flags() * cells_;
}

int FlagWorld::remaining_path_length(State s) const {
  if (s == terminal_state_) return 0;
  const int c = collected(s);
  int len = geometry_.manhattan(cell(s), flags_[static_cast<std::size_t>(c)]);
  for (int i = c; i + 1 < num_flags(); ++i)
    len += geometry_.manhattan(flags_[static_cast<std::size_t>(i)], flags_[static_cast<std::size_t>(i) + 1]);
  return len;
}

double FlagWorld::estimated_steps() const { return remaining_path_length(start_) / intended_; }

FlagWorld flags_5x5(double intended) {
  // Route length 3 + 4 + 4 + 3 + 4 = 18 cells, so t = 22.5 steps at 0.8 cells of progress per step.
  return FlagWorld(GridGeometry(5, 5), Cell{0, 0}, {{3, 0}, {4, 3}, {1, 2}, {0, 4}, {4, 4}}, intended);
}

FlagWorld flags_8x8(double intended) {
  return FlagWorld(GridGeometry(8, 8), Cell{0, 0}, {{6, 1}, {2, 3}, {7, 5}, {0, 6}, {3, 7}, {5, 3}, {7, 7}},
                   intended);
}

FlagWorld flag_world(int size, double intended) {
  if (size == 5) return flags_5x5(intended);
  if (size == 8) return flags_8x8(intended);
  throw InputError(fmt::format("flags: size must be 5 or 8, got {}", size));
}

FiniteMdp to_finite_mdp(const FlagWorld& w, double gamma) {
  FiniteMdpBuilder b(w.num_states(), kGridActions, gamma);
  b.set_absorbing(w.terminal_state());
  const double slip = (1.0 - w.intended()) / 4.0;
  for (int s = 0; s < w.terminal_state(); ++s) {
    for (int a = 0; a < kGridActions; ++a) {
      for (int d = 0; d < kGridActions; ++d) {
        const double p = (d == a ? w.intended() : 0.0) + slip;
        // One uniform inside the band of direction d realises exactly this move.
        const double u = d == a ? 0.5 * w.intended() : w.intended() + (d + 0.5) * slip;
        const double noise[1] = {u};
        if (p > 0.0) b.add_transition(s, a, w.step(s, a, noise), p, w.step_reward());
      }
    }
  }
  b.set_initial(w.initial_state({}), 1.0);
  return b.build();
}

std::vector<double> flags_phi0(const FlagWorld& w) {
  const double n = w.num_flags(), t = w.estimated_steps();
  std::vector<double> phi(static_cast<std::size_t>(w.num_states()), 0.0);
  for (int s = 0; s < w.terminal_state(); ++s)
    phi[static_cast<std::size_t>(s)] = -((n - w.collected(s) - 0.5) / n) * t;
  return phi;
}

std::vector<double> flags_phi1(const FlagWorld& w) {
  std::vector<double> phi(static_cast<std::size_t>(w.num_states()), 0.0);
  for (int s = 0; s < w.terminal_state(); ++s)
    phi[static_cast<std::size_t>(s)] = -w.remaining_path_length(s) / w.intended();
  return phi;
}

}  // namespace pegasus
