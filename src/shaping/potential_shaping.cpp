#include "pegasus/shaping/potential_shaping.hpp"

#include <fmt/format.h>

#include "pegasus/core/error.hpp"

namespace pegasus {

FiniteMdp add_shaping(const FiniteMdp& mdp, const std::function<double(int, int, int)>& f) {
  FiniteMdp out = mdp;
  for (int s = 0; s < mdp.num_states; ++s) {
    if (mdp.is_absorbing(s)) continue;
    for (int a = 0; a < mdp.num_actions; ++a) {
      const std::size_t r = mdp.row(s, a);
      for (std::uint32_t k = mdp.row_start[r]; k < mdp.row_start[r + 1]; ++k)
        out.reward[k] += f(s, a, mdp.next_state[k]);
    }
  }
  out.refresh_expected_reward();
  validate(out, "shaped mdp");
  return out;
}

FiniteMdp shape_with_potential(const FiniteMdp& mdp, std::span<const double> phi) {
  if (phi.size() != static_cast<std::size_t>(mdp.num_states))
    throw InputError(fmt::format("potential: expected {} values, got {}", mdp.num_states, phi.size()));
  auto p = [&](int s) { return mdp.is_absorbing(s) ? 0.0 : phi[static_cast<std::size_t>(s)]; };
  return add_shaping(
      mdp, [&](int s, int, int next) { return potential_shaping_reward(mdp.gamma, p(s), p(next)); });
}

FiniteMdp add_constant_reward(const FiniteMdp& mdp, double c) {
  return add_shaping(mdp, [c](int, int, int) { return c; });
}

std::vector<double> constant_offset_potential(const FiniteMdp& mdp, double c) {
  if (!(mdp.gamma < 1.0)) throw InputError("constant offset potential: needs gamma < 1");
  if (mdp.has_absorbing_states())
    throw InputError("constant offset potential: needs an MDP without absorbing states");
  return std::vector<double>(static_cast<std::size_t>(mdp.num_states), -c / (1.0 - mdp.gamma));
}

}  // namespace pegasus
