#pragma once
// A finite MDP (S, D, A, {P_sa}, gamma, R) of thesis §2.1, stored for speed.
//
// Layout (CSR, one row per state-action pair): row r = s * A + a owns the entries
// [row_start[r], row_start[r + 1]) of the parallel arrays next_state / probability / reward, so a Bellman
// backup streams three flat arrays front to back and touches V only at the successors. The expected
// one-step reward R(s, a) = sum_s' P_sa(s') R(s, a, s') is cached per row, because every solver needs it
// and only shaping and learners need R(s, a, s').
//
// Rewards in the R(s), R(s, a) and R(s, a, s') forms (§2.1) all become R(s, a, s') on the entries: the
// builder adds them up. R(s) is the reward of the state being left, as in Eq 2.1.
//
// Absorbing states end an episode: no further reward, no further steps. They are stored with a self-loop
// of probability 1 and reward 0 under every action, and every solver fixes their value to 0. With
// gamma = 1 the MDP must be proper (§2.1): the absorbing set is reached with probability 1 under every
// policy. validate() checks that (see check_proper).
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pegasus {

struct FiniteMdp {
  int num_states = 0;
  int num_actions = 0;
  double gamma = 1.0;

  std::vector<std::uint32_t> row_start;  // size S*A + 1
  std::vector<std::int32_t> next_state;  // size nnz
  std::vector<double> probability;       // size nnz
  std::vector<double> reward;            // size nnz: R(s, a, s')
  std::vector<double> expected_reward;   // size S*A: R(s, a)
  std::vector<std::uint8_t> absorbing;   // size S: 1 for absorbing states
  std::vector<double> initial;           // size S: the initial distribution D

  std::size_t row(int s, int a) const {
    return static_cast<std::size_t>(s) * static_cast<std::size_t>(num_actions) + static_cast<std::size_t>(a);
  }
  std::size_t num_rows() const { return static_cast<std::size_t>(num_states) * num_actions; }
  std::size_t num_entries() const { return next_state.size(); }
  bool is_absorbing(int s) const { return absorbing[static_cast<std::size_t>(s)] != 0; }
  bool has_absorbing_states() const;
  // Recomputes expected_reward from the entries (after editing rewards in place).
  void refresh_expected_reward();
};

// Builds a FiniteMdp one (s, a) row at a time, in any order. Every non-absorbing (s, a) must be given
// exactly once; absorbing states get their self-loops automatically. Duplicate successors within a row
// are merged (probabilities added, rewards probability-weighted).
class FiniteMdpBuilder {
 public:
  FiniteMdpBuilder(int num_states, int num_actions, double gamma);

  void set_absorbing(int s);
  // R(s) form: added to every transition leaving s.
  void set_state_reward(int s, double r);
  // R(s, a) form: added to every transition of the row.
  void set_state_action_reward(int s, int a, double r);
  // One successor of row (s, a) with its R(s, a, s') (the transition-reward form).
  void add_transition(int s, int a, int next, double probability, double reward = 0.0);
  void set_initial(int s, double probability);

  // Assembles and validates (throws InputError naming the offending row). Without set_initial calls the
  // initial distribution is uniform over the non-absorbing states.
  FiniteMdp build() const;

 private:
  struct Entry {
    int next;
    double p, r;
  };
  int S_, A_;
  double gamma_;
  std::vector<std::vector<Entry>> rows_;
  std::vector<std::uint8_t> given_;
  std::vector<double> state_reward_, state_action_reward_, initial_;
  std::vector<std::uint8_t> absorbing_;
  bool initial_given_ = false;
};

// Checks the invariants every solver relies on; throws InputError with a one-line message naming the
// first violation (`what` prefixes it, e.g. a file name). Tolerances: rows and D sum to 1 within 1e-9.
void validate(const FiniteMdp& mdp, const std::string& what = "mdp");

// A state from which some policy avoids the absorbing set forever with positive probability, if any.
// Computed as the largest set X of non-absorbing states in which every state has an action whose whole
// support stays in X (a trap); the MDP is proper under every policy iff X is empty, because a
// stationary policy's recurrent class among non-absorbing states is such a trap and, conversely, choosing
// the trapping action in X keeps the process there forever. O(entries).
std::optional<int> find_improper_state(const FiniteMdp& mdp);
// Throws InputError if find_improper_state finds a state (gamma = 1 requires properness, §2.1).
void check_proper(const FiniteMdp& mdp, const std::string& what = "mdp");

// The same MDP with a different discount (keeps every other field).
FiniteMdp with_gamma(FiniteMdp mdp, double gamma);

// Largest |R(s, a, s')| over the entries of non-absorbing rows.
double max_abs_reward(const FiniteMdp& mdp);

}  // namespace pegasus
