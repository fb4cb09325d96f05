#pragma once
// The shaping audit: is a tabular F potential-based (thesis §3.3, Theorem 1), and if not, why not?
//
// Scope. F matters only on transitions that can happen, so the audit judges F on the scope: the triples
// (s, a, s') with s non-absorbing and either P_sa(s') > 0 in the given MDP or (s, a, s') listed in the
// table (unlisted in-support triples have F = 0). F is potential-based on the scope when some Phi with
// Phi(absorbing) = 0 gives F(s, a, s') = gamma Phi(s') - Phi(s) on every scope triple, to within
// `tolerance * (1 + max |F|)`.
//
// Answer.
//   potential-based: Phi by least squares over the scope triples (sparse QR), and the residual.
//   not potential-based: a witness:
//     * an action dependence (Lemma 4): F(s, a, s') != F(s, a', s'), or
//     * (gamma = 1) a directed cycle of scope transitions with positive (else negative) net shaping
//       reward, the cause of the bicycle and soccer bugs of §3.1;
//   and a counterexample MDP on the same S and A (Appendix 3.A; Lemma 4's construction for an action
//   dependence, the Fig 3.4 construction otherwise) whose optimal action at one state flips under F,
//   verified by solving the counterexample with and without F by policy iteration. The counterexample's
//   transitions are chosen inside the scope when possible; where they leave it, F takes the value of the
//   same (s, s') pair under another action, or 0 if no action reaches s' from s in the scope, and
//   `uses_only_scope` says so.
// Also: whether the given MDP's own optimal policy changes under F (M and M + F solved by policy
// iteration), with the states where it does and the loss in M of M + F's optimal policy.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pegasus/mdp/finite_mdp.hpp"
#include "pegasus/shaping/shaping_table.hpp"

namespace pegasus {

struct AuditOptions {
  // Relative tolerance: residuals and differences below tolerance * (1 + max |F|) count as zero.
  double tolerance = 1e-9;
  // Candidate anchor states (s^_0 of Appendix 3.A) tried for the counterexample. Must be >= 1.
  int max_anchors = 16;
  // Skip the cycle search when states * scope pairs exceeds this (Bellman-Ford is O(V E)).
  double max_cycle_search_work = 2e8;

  bool IsValid(std::string* error) const;
};

struct ActionDependence {  // Lemma 4
  int state = 0, next_state = 0;
  int action_high = 0, action_low = 0;  // F(state, action_high, next) > F(state, action_low, next)
  double f_high = 0.0, f_low = 0.0;
};

struct ShapingCycle {
  std::vector<int> states;   // s_1 .. s_n; the cycle closes with s_n -> s_1
  std::vector<int> actions;  // actions[i] takes states[i] to states[i+1] (mod n) with positive probability
  double net_shaping = 0.0;  // sum of F around the cycle
};

struct Counterexample {
  FiniteMdp mdp;                             // the counterexample M (F is applied as described in the header)
  FiniteMdp shaped;                          // M + F
  int decision_state = 0;                    // where the optimal action flips
  std::uint64_t optimal_actions = 0;         // bitmask of optimal actions at decision_state in M
  std::uint64_t shaped_optimal_actions = 0;  // ... in M + F
  double delta = 0.0;                        // the Delta of Appendix 3.A (shaping advantage of one option)
  bool verified = false;         // the two masks are disjoint: no optimal policy of M + F is optimal in M
  bool uses_only_scope = false;  // every transition of the counterexample lies in the audit's scope
  std::string description;
};

struct PolicyChange {
  bool changes = false;           // some optimal action of M + F is not optimal in M
  std::vector<int> states;        // the states where that happens
  double loss_under_initial = 0;  // sum_s D(s) (V*_M(s) - V_M^{pi'}(s)) for pi' optimal in M + F
  double max_loss = 0;            // max_s (V*_M(s) - V_M^{pi'}(s))
};

struct ShapingAudit {
  bool potential_based = false;
  std::vector<double> potential;  // least-squares Phi (Phi(absorbing) = 0)
  double max_residual = 0.0;      // max over scope triples |gamma Phi(s') - Phi(s) - F|
  double rms_residual = 0.0;
  double tolerance_used = 0.0;
  std::size_t scope_size = 0;
  std::optional<ActionDependence> action_dependence;
  std::optional<ShapingCycle> cycle;
  std::optional<Counterexample> counterexample;
  std::string counterexample_note;  // why no counterexample was built, when none was
  PolicyChange policy_change;

  std::string BriefReport() const;
};

ShapingAudit audit_shaping(const FiniteMdp& mdp, const ShapingTable& f, const AuditOptions& options = {});

}  // namespace pegasus
