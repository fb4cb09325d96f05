#pragma once
// Dynamic programming on finite MDPs (thesis §2.2-2.3): value iteration (Jacobi and Gauss-Seidel),
// policy iteration with exact evaluation by a sparse LU solve, modified policy iteration, and exact
// evaluation of any deterministic or stochastic policy.
//
// Every solver has the Ceres shape: an Options struct with documented defaults and IsValid(), a Summary
// with a termination type, a message and BriefReport(), and a free function. The inner loops run over the
// CSR arrays of FiniteMdp and allocate nothing per sweep.
//
// Guarantee (value iteration, modified policy iteration, StopRule::kEpsilonOptimal):
//   gamma < 1: the returned policy pi satisfies max_s (V*(s) - V^pi(s)) <= summary.policy_loss_bound <=
//   options.epsilon. The bound is certified by the last Jacobi sweep V' = T V, whose argmax is pi: with
//   Delta = V' - V ranging over [lo, hi] (0 included when there are absorbing states), MacQueen's bounds
//       V + lo/(1-gamma) <= V^pi <= V* <= V + hi/(1-gamma)
//   give ||V* - V^pi|| <= (hi - lo)/(1-gamma) (Puterman 1994, §6.6.3). This is never weaker than the
//   classic rule "stop when ||V_{k+1} - V_k|| < epsilon (1-gamma) / (2 gamma)" (Puterman Thm 6.3.1), and
//   far stronger on MDPs that mix fast, where the span shrinks long before ||Delta|| does. The returned V
//   is the midpoint of the bounds, within summary.value_error_bound = gamma (hi - lo) / (2 (1-gamma)) of V*.
//   gamma = 1 (proper MDPs): no useful contraction modulus is known in general (in the 80/20 gridworld
//   the worst policy's expected time to the goal grows exponentially with the grid size), so sweeps run
//   until ||Delta|| < epsilon and the greedy policy is then polished by policy iteration, which stops at
//   an exactly optimal policy (every policy is proper: Bertsekas & Tsitsiklis 1996, Prop 2.3); both bounds
//   are then 0 up to the round-off of the linear solves.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "pegasus/core/instruction_set.hpp"
#include "pegasus/mdp/finite_mdp.hpp"

namespace pegasus {

enum class StopRule {
  kEpsilonOptimal,  // stop once the greedy policy is certified epsilon-optimal (see above)
  kResidual,        // stop once a sweep changes V by less than `tolerance` in the sup norm (what other
                    // toolboxes such as AI-Toolbox do); V is returned as swept, not extrapolated, and the
                    // bounds are still reported
};

enum class SolverTermination { kConverged, kMaxIterations };

struct ValueIterationOptions {
  // Target suboptimality of the returned greedy policy (sup norm over states). Must be > 0.
  double epsilon = 1e-8;
  StopRule stop = StopRule::kEpsilonOptimal;
  // With StopRule::kResidual: stop when max_s |V_{k+1}(s) - V_k(s)| < tolerance. Must be > 0.
  double tolerance = 1e-8;
  // Update V in place within a sweep (Gauss-Seidel) instead of from the previous sweep (Jacobi).
  bool gauss_seidel = false;
  // Upper limit on sweeps. Must be >= 1.
  int max_iterations = 1'000'000;
  // Starting values (empty: zeros). Absorbing states are forced to 0.
  std::vector<double> initial_values;

  bool IsValid(const FiniteMdp& mdp, std::string* error) const;
};

struct PolicyIterationOptions {
  // Upper limit on improvement steps. Must be >= 1.
  int max_iterations = 10'000;
  // An action replaces the current one only if it improves Q by more than this (guards against cycling
  // between equally good actions through round-off). Must be >= 0.
  double improvement_tolerance = 1e-12;
  // Starting policy (empty: the greedy policy of V = 0).
  std::vector<int> initial_policy;

  bool IsValid(const FiniteMdp& mdp, std::string* error) const;
};

struct ModifiedPolicyIterationOptions {
  // Same meaning as in ValueIterationOptions.
  double epsilon = 1e-8;
  // Sweeps of T_pi per partial evaluation (m in Puterman §6.5). Must be >= 1; 1 is value iteration.
  int evaluation_sweeps = 20;
  int max_iterations = 1'000'000;

  bool IsValid(const FiniteMdp& mdp, std::string* error) const;
};

struct SolveSummary {
  std::vector<double> value;  // V: the certified iterate (VI, MPI) or V^pi exactly (PI)
  std::vector<int> policy;    // greedy deterministic policy, one action per state (0 at absorbing states)
  int iterations = 0;         // sweeps (VI), improvement steps (PI, MPI)
  int polish_iterations = 0;  // policy-iteration steps after the sweeps (gamma = 1)
  double residual = 0.0;      // max_s |(T V)(s) - V(s)| at the end
  double policy_loss_bound = 0.0;  // certified max_s V*(s) - V^pi(s) (infinity when not certified)
  double value_error_bound = 0.0;  // certified max_s |V(s) - V*(s)| of the returned value
  SolverTermination termination = SolverTermination::kConverged;
  double seconds = 0.0;
  std::string message;

  bool converged() const { return termination == SolverTermination::kConverged; }
  std::string BriefReport() const;
};

SolveSummary value_iteration(const FiniteMdp& mdp, const ValueIterationOptions& options = {});
SolveSummary policy_iteration(const FiniteMdp& mdp, const PolicyIterationOptions& options = {});
SolveSummary modified_policy_iteration(const FiniteMdp& mdp,
                                       const ModifiedPolicyIterationOptions& options = {});

// A stochastic policy: probs[s * A + a] = pi(a | s); each row sums to 1.
struct StochasticPolicy {
  int num_states = 0, num_actions = 0;
  std::vector<double> probs;
  static StochasticPolicy from_deterministic(const FiniteMdp& mdp, std::span<const int> policy);
};

// V^pi exactly, by solving (I - gamma P_pi) V = R_pi over the non-absorbing states with a sparse LU
// factorisation (Eq 2.8). Throws InputError on a malformed policy.
std::vector<double> evaluate_policy(const FiniteMdp& mdp, std::span<const int> policy);
std::vector<double> evaluate_policy(const FiniteMdp& mdp, const StochasticPolicy& policy);

// Q(s, a) = R(s, a) + gamma sum_s' P_sa(s') V(s') (Eq 2.12 with V = V^pi), row-major S x A; absorbing
// rows are 0.
std::vector<double> q_from_values(const FiniteMdp& mdp, std::span<const double> value);
// argmax_a Q(s, a), lowest action on ties (Eq 2.15).
std::vector<int> greedy_policy(const FiniteMdp& mdp, std::span<const double> value);
// One Bellman optimality backup: out = T V; returns max_s |(T V)(s) - V(s)|.
double bellman_backup(const FiniteMdp& mdp, std::span<const double> value, std::span<double> out);
// For each state, a bitmask of the actions within `tol` of max_a Q(s, a) (A <= 64).
std::vector<std::uint64_t> near_optimal_actions(const FiniteMdp& mdp, std::span<const double> q, double tol);
// Expected return under D: sum_s D(s) V(s).
double expected_under_initial(const FiniteMdp& mdp, std::span<const double> value);

namespace detail {
// The kernel of a dense MDP's sweep (every row lists every state): four dot products of consecutive rows
// with V. The sweep runs on best_instruction_set() (the baseline is SSE2), so results are deterministic on a
// given machine; the sets sum in different orders and FMA rounds once, so they agree to a few ulps of
// sum_k |p_k v_k|, not bit for bit. Exposed for tests.
// out[a] = sum_{k < n} p[a * stride + k] v[k], a = 0..3. `isa` must be supported.
void dense_dot4(InstructionSet isa, const double* p, std::size_t stride, const double* v, int n, double* out);
// The same kernel as a function pointer, for a sweep to look up once.
using DenseDot4 = void (*)(const double* p, std::size_t stride, const double* v, int n, double* out);
DenseDot4 dense_dot4_kernel(InstructionSet isa);
}  // namespace detail

}  // namespace pegasus
