#include "pegasus/mdp/random_mdp.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>

#include "pegasus/core/error.hpp"

namespace pegasus {

bool RandomMdpOptions::IsValid(std::string* error) const {
  auto bad = [&](const std::string& m) {
    if (error) *error = "random MDP options: " + m;
    return false;
  };
  if (num_states < 2) return bad(fmt::format("num_states must be >= 2, got {}", num_states));
  if (num_actions < 1) return bad(fmt::format("num_actions must be >= 1, got {}", num_actions));
  if (successors < 1 || successors > num_states)
    return bad(fmt::format("successors must lie in [1, {}], got {}", num_states, successors));
  if (!(gamma >= 0.0 && gamma <= 1.0)) return bad(fmt::format("gamma must lie in [0, 1], got {}", gamma));
  if (!(reward_min <= reward_max)) return bad("reward_min must be <= reward_max");
  return true;
}

FiniteMdp random_mdp(const RandomMdpOptions& o, UniformStream& rng) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError(err);
  const bool episodic = o.episodic || o.gamma == 1.0;
  const int S = o.num_states, A = o.num_actions;
  const int end = S - 1;  // the absorbing state when episodic
  FiniteMdpBuilder b(S, A, o.gamma);
  if (episodic) b.set_absorbing(end);
  auto reward = [&] { return o.reward_min + (o.reward_max - o.reward_min) * rng.next(); };
  std::vector<int> pool(static_cast<std::size_t>(S));
  std::vector<double> w;
  for (int s = 0; s < S; ++s) {
    if (episodic && s == end) continue;
    for (int a = 0; a < A; ++a) {
      // Candidate successors: all states, or (episodic, "forward" rows) only higher-numbered ones.
      const bool leak = !episodic || s == end - 1 || rng.next() < 0.5;
      const int lo = (episodic && !leak) ? s + 1 : 0;
      pool.resize(static_cast<std::size_t>(S - lo));
      std::iota(pool.begin(), pool.end(), lo);
      if (episodic && leak) pool.pop_back();  // the leak adds `end` itself (lo <= end always)
      const int k = std::min<int>(o.successors, static_cast<int>(pool.size()));
      for (int i = 0; i < k; ++i) {  // partial Fisher-Yates
        const auto j =
            static_cast<std::size_t>(i) + rng.next_below(pool.size() - static_cast<std::size_t>(i));
        std::swap(pool[static_cast<std::size_t>(i)], pool[j]);
      }
      w.assign(static_cast<std::size_t>(k), 0.0);
      double total = 0.0;
      for (auto& x : w) total += (x = 0.05 + rng.next());
      double leak_p = 0.0;
      if (episodic && leak) leak_p = 0.05 + 0.25 * rng.next();
      for (int i = 0; i < k; ++i) {
        const double p = (1.0 - leak_p) * w[static_cast<std::size_t>(i)] / total;
        b.add_transition(s, a, pool[static_cast<std::size_t>(i)], p, reward());
      }
      if (leak_p > 0.0) b.add_transition(s, a, end, leak_p, reward());
    }
  }
  return b.build();
}

}  // namespace pegasus
