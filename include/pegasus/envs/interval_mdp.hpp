#pragma once
// The MDP behind Theorem 11 (thesis §4.5.2, Appendix 4.B): states s_-1, s_0, s_1 and an absorbing state,
// R(s_i) = i, and from s_0 every action moves to s_-1 or s_1 with probability 1/2, so U(pi) = 0 for every
// policy. Its deterministic simulative model is deliberately complex: action a_i sends s_0 to s_-1 exactly
// when p lies in T_i, where T_1, T_2, ... enumerate unions of intervals of total length 1/2. We enumerate
// the dyadic ones: level k splits [0, 1) into 2^k equal bins and takes every set of 2^(k-1) of them, so for
// any m scenarios some T_i (with 2^k >= 2m) misses them all and PEGASUS estimates U-hat(a_i) = 1.
// The "simple" model of footnote 10 (s_-1 iff p <= 1/2, whatever the action) is available for contrast.
#include <cstdint>
#include <span>

#include "pegasus/models/action_space.hpp"

namespace pegasus {

class IntervalMdp {
 public:
  enum State : int { kMinus = -1, kStart = 0, kPlus = 1, kAbsorbing = 2 };
  using Action = std::uint64_t;  // index i of T_i (0-based)
  using Observation = int;

  // Levels 1..5 of dyadic unions hold 2 + 6 + 70 + 12870 + 601080390 sets.
  static constexpr int kMaxLevel = 5;

  explicit IntervalMdp(bool simple = false) : simple_(simple) {}

  int state_dim() const { return 1; }
  int noise_dim() const { return 1; }
  int initial_noise_dim() const { return 0; }
  // Countably many actions; the finite space reported is the enumerated prefix up to level 5.
  ActionSpace action_space() const { return ActionSpace::finite(static_cast<int>(action_count(4))); }
  State initial_state(std::span<const double>) const { return kStart; }
  bool terminal(State s) const { return s == kAbsorbing; }
  Observation observe(State s) const { return static_cast<int>(s); }
  double reward(State s) const { return s == kAbsorbing ? 0.0 : static_cast<double>(static_cast<int>(s)); }

  State step(State s, Action a, std::span<const double> p) const {
    if (s != kStart) return kAbsorbing;
    const bool lower = simple_ ? p[0] <= 0.5 : in_set(a, p[0]);
    return lower ? kMinus : kPlus;
  }

  // Number of sets T_i in levels 1..level.
  static std::uint64_t action_count(int level);
  // Bit b set: bin b of the level of T_i belongs to T_i. level receives k.
  static std::uint32_t bins_of(Action i, int* level);
  // Lebesgue measure of T_i (exactly 1/2 for every i; checked in tests).
  static double measure(Action i);
  static bool in_set(Action i, double p);

 private:
  bool simple_;
};

}  // namespace pegasus
