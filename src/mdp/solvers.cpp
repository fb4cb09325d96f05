#include "pegasus/mdp/solvers.hpp"

#include <fmt/format.h>

#include <Eigen/Sparse>
#include <Eigen/SparseLU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The hot kernel: Q(s, a) for row r. Raw pointers so the loop is a plain gather-multiply-add.
struct Kernel {
  const std::uint32_t* row_start;
  const std::int32_t* next;
  const double* prob;
  const double* r_sa;
  const std::uint8_t* absorbing;
  double gamma;
  int S, A;

  explicit Kernel(const FiniteMdp& m)
      : row_start(m.row_start.data()),
        next(m.next_state.data()),
        prob(m.probability.data()),
        r_sa(m.expected_reward.data()),
        absorbing(m.absorbing.data()),
        gamma(m.gamma),
        S(m.num_states),
        A(m.num_actions) {}

  double q(std::size_t r, const double* __restrict v) const {
    double acc = 0.0;
    const std::uint32_t e = row_start[r + 1];
    for (std::uint32_t k = row_start[r]; k < e; ++k) acc += prob[k] * v[next[k]];
    return r_sa[r] + gamma * acc;
  }

  // Best Q at s and its (lowest) argmax.
  double best(int s, const double* v, int* arg) const {
    const std::size_t base = static_cast<std::size_t>(s) * static_cast<std::size_t>(A);
    double b = q(base, v);
    int ba = 0;
    for (int a = 1; a < A; ++a) {
      const double x = q(base + static_cast<std::size_t>(a), v);
      if (x > b) {
        b = x;
        ba = a;
      }
    }
    *arg = ba;
    return b;
  }

  // out = T v and policy = greedy(v); returns max |T v - v|. v and out must differ.
  double jacobi(const double* __restrict v, double* __restrict out, int* __restrict policy) const {
    double delta = 0.0;
    for (int s = 0; s < S; ++s) {
      if (absorbing[s]) {
        out[s] = 0.0;
        policy[s] = 0;
        continue;
      }
      const double b = best(s, v, &policy[s]);
      delta = std::max(delta, std::abs(b - v[s]));
      out[s] = b;
    }
    return delta;
  }

  // In-place sweep; returns the largest change.
  double gauss_seidel(double* v) const {
    double delta = 0.0;
    int arg = 0;
    for (int s = 0; s < S; ++s) {
      if (absorbing[s]) continue;
      const double b = best(s, v, &arg);
      delta = std::max(delta, std::abs(b - v[s]));
      v[s] = b;
    }
    return delta;
  }

  // In-place sweep of T_pi.
  void evaluate_in_place(const int* policy, double* v) const {
    for (int s = 0; s < S; ++s) {
      if (absorbing[s]) continue;
      v[s] = q(static_cast<std::size_t>(s) * static_cast<std::size_t>(A) + static_cast<std::size_t>(policy[s]), v);
    }
  }
};

void check(bool ok, const std::string& msg) {
  if (!ok) throw InputError(msg);
}

void require_valid(bool valid, const std::string& error) {
  if (!valid) throw InputError(error);
}

std::vector<double> start_values(const FiniteMdp& m, const std::vector<double>& given) {
  std::vector<double> v = given.empty() ? std::vector<double>(static_cast<std::size_t>(m.num_states), 0.0) : given;
  for (int s = 0; s < m.num_states; ++s)
    if (m.is_absorbing(s)) v[static_cast<std::size_t>(s)] = 0.0;
  return v;
}

const char* termination_name(SolverTermination t) {
  return t == SolverTermination::kConverged ? "converged" : "stopped at the iteration limit";
}

// Policy iteration from a given policy; used by policy_iteration and as the gamma = 1 polish.
void run_policy_iteration(const FiniteMdp& m, std::vector<int> policy, int max_iterations, double tol,
                          SolveSummary* out, int* steps) {
  const Kernel k(m);
  std::vector<double> v;
  *steps = 0;
  bool stable = false;
  while (*steps < max_iterations) {
    v = evaluate_policy(m, policy);
    ++*steps;
    stable = true;
    for (int s = 0; s < m.num_states; ++s) {
      if (m.is_absorbing(s)) continue;
      const std::size_t base = m.row(s, 0);
      const int cur = policy[static_cast<std::size_t>(s)];
      double best = k.q(base + static_cast<std::size_t>(cur), v.data());
      int arg = cur;
      for (int a = 0; a < m.num_actions; ++a) {
        const double x = k.q(base + static_cast<std::size_t>(a), v.data());
        if (x > best + tol) {
          best = x;
          arg = a;
        }
      }
      if (arg != cur) {
        policy[static_cast<std::size_t>(s)] = arg;
        stable = false;
      }
    }
    if (stable) break;
  }
  std::vector<double> tv(v.size());
  out->residual = bellman_backup(m, v, tv);
  out->value = std::move(v);
  out->policy = std::move(policy);
  out->termination = stable ? SolverTermination::kConverged : SolverTermination::kMaxIterations;
  out->policy_loss_bound = stable ? 0.0 : kInf;
}

}  // namespace

bool ValueIterationOptions::IsValid(const FiniteMdp& mdp, std::string* error) const {
  auto bad = [&](const std::string& m) {
    if (error) *error = "value iteration options: " + m;
    return false;
  };
  if (!(epsilon > 0.0)) return bad(fmt::format("epsilon must be > 0, got {}", epsilon));
  if (!(tolerance > 0.0)) return bad(fmt::format("tolerance must be > 0, got {}", tolerance));
  if (max_iterations < 1) return bad(fmt::format("max_iterations must be >= 1, got {}", max_iterations));
  if (!initial_values.empty() && initial_values.size() != static_cast<std::size_t>(mdp.num_states))
    return bad(fmt::format("initial_values must have {} entries, got {}", mdp.num_states, initial_values.size()));
  return true;
}

bool PolicyIterationOptions::IsValid(const FiniteMdp& mdp, std::string* error) const {
  auto bad = [&](const std::string& m) {
    if (error) *error = "policy iteration options: " + m;
    return false;
  };
  if (max_iterations < 1) return bad(fmt::format("max_iterations must be >= 1, got {}", max_iterations));
  if (!(improvement_tolerance >= 0.0)) return bad("improvement_tolerance must be >= 0");
  if (!initial_policy.empty()) {
    if (initial_policy.size() != static_cast<std::size_t>(mdp.num_states))
      return bad(fmt::format("initial_policy must have {} entries", mdp.num_states));
    for (std::size_t s = 0; s < initial_policy.size(); ++s)
      if (initial_policy[s] < 0 || initial_policy[s] >= mdp.num_actions)
        return bad(fmt::format("initial_policy[{}] = {} outside [0, {})", s, initial_policy[s], mdp.num_actions));
  }
  return true;
}

bool ModifiedPolicyIterationOptions::IsValid(const FiniteMdp&, std::string* error) const {
  auto bad = [&](const std::string& m) {
    if (error) *error = "modified policy iteration options: " + m;
    return false;
  };
  if (!(epsilon > 0.0)) return bad(fmt::format("epsilon must be > 0, got {}", epsilon));
  if (evaluation_sweeps < 1) return bad(fmt::format("evaluation_sweeps must be >= 1, got {}", evaluation_sweeps));
  if (max_iterations < 1) return bad(fmt::format("max_iterations must be >= 1, got {}", max_iterations));
  return true;
}

std::string SolveSummary::BriefReport() const {
  return fmt::format("{} after {} iterations (+{} polish), residual {:.3g}, policy loss <= {:.3g}, {:.3g} s",
                     termination_name(termination), iterations, polish_iterations, residual, policy_loss_bound,
                     seconds);
}

SolveSummary value_iteration(const FiniteMdp& m, const ValueIterationOptions& o) {
  const auto t0 = Clock::now();
  std::string err;
  require_valid(o.IsValid(m, &err), err);
  const Kernel k(m);
  const double g = m.gamma;
  const std::size_t S = static_cast<std::size_t>(m.num_states);
  std::vector<double> v = start_values(m, o.initial_values), w(S);
  std::vector<int> policy(S, 0);
  SolveSummary sum;
  sum.policy_loss_bound = kInf;
  sum.termination = SolverTermination::kMaxIterations;

  // Certificate (see header): pi greedy w.r.t. V and r = ||T V - V|| give ||V* - V^pi|| <= 2r/(1-gamma).
  auto loss_bound = [g](double r) { return g == 0.0 ? 0.0 : g < 1.0 ? 2.0 * r / (1.0 - g) : kInf; };
  // A Jacobi sweep from V_k certifies its own greedy policy with r = delta_k. For Gauss-Seidel the sweep
  // change only suggests it is time to try: the certificate pass below decides.
  const double trigger = o.stop == StopRule::kResidual ? o.tolerance
                         : g < 1.0                     ? o.epsilon * (1.0 - g) / 2.0
                                                       : o.epsilon;
  int it = 0;
  while (it < o.max_iterations) {
    ++it;
    if (!o.gauss_seidel) {
      const double delta = k.jacobi(v.data(), w.data(), policy.data());
      std::swap(v, w);  // v = T v_old, policy greedy w.r.t. v_old
      if (delta < trigger || (g == 0.0)) {
        sum.residual = delta;
        sum.policy_loss_bound = loss_bound(delta);
        sum.termination = SolverTermination::kConverged;
        break;
      }
    } else {
      const double delta = k.gauss_seidel(v.data());
      if (delta < trigger || g == 0.0) {
        const double r = k.jacobi(v.data(), w.data(), policy.data());
        std::swap(v, w);
        if (o.stop == StopRule::kResidual || g == 1.0 || loss_bound(r) <= o.epsilon) {
          sum.residual = r;
          sum.policy_loss_bound = loss_bound(r);
          sum.termination = SolverTermination::kConverged;
          break;
        }
      }
    }
  }
  sum.iterations = it;
  if (g == 1.0 && o.stop == StopRule::kEpsilonOptimal && sum.converged()) {
    int steps = 0;
    const auto greedy = greedy_policy(m, v);
    run_policy_iteration(m, greedy, 10'000, 1e-12, &sum, &steps);
    sum.polish_iterations = steps;
  } else {
    sum.value = std::move(v);
    sum.policy = std::move(policy);
  }
  sum.seconds = seconds_since(t0);
  sum.message = fmt::format("value iteration ({}) {}", o.gauss_seidel ? "Gauss-Seidel" : "Jacobi",
                            termination_name(sum.termination));
  return sum;
}

SolveSummary policy_iteration(const FiniteMdp& m, const PolicyIterationOptions& o) {
  const auto t0 = Clock::now();
  std::string err;
  require_valid(o.IsValid(m, &err), err);
  std::vector<int> policy = o.initial_policy;
  if (policy.empty()) policy = greedy_policy(m, std::vector<double>(static_cast<std::size_t>(m.num_states), 0.0));
  SolveSummary sum;
  run_policy_iteration(m, std::move(policy), o.max_iterations, o.improvement_tolerance, &sum, &sum.iterations);
  sum.seconds = seconds_since(t0);
  sum.message = fmt::format("policy iteration {}", termination_name(sum.termination));
  return sum;
}

SolveSummary modified_policy_iteration(const FiniteMdp& m, const ModifiedPolicyIterationOptions& o) {
  const auto t0 = Clock::now();
  std::string err;
  require_valid(o.IsValid(m, &err), err);
  const Kernel k(m);
  const double g = m.gamma;
  const std::size_t S = static_cast<std::size_t>(m.num_states);
  // Start below V* (T V0 >= V0) for gamma < 1, as Puterman's convergence proof (Thm 6.5.5) assumes.
  double v0 = 0.0;
  if (g < 1.0) {
    double rmin = 0.0;
    for (double r : m.expected_reward) rmin = std::min(rmin, r);
    v0 = rmin / (1.0 - g);
  }
  std::vector<double> v(S, v0), w(S);
  for (std::size_t s = 0; s < S; ++s)
    if (m.absorbing[s]) v[s] = 0.0;
  std::vector<int> policy(S, 0);
  SolveSummary sum;
  sum.policy_loss_bound = kInf;
  sum.termination = SolverTermination::kMaxIterations;
  int it = 0;
  while (it < o.max_iterations) {
    ++it;
    const double r = k.jacobi(v.data(), w.data(), policy.data());
    std::swap(v, w);
    const bool done = g < 1.0 ? 2.0 * r / (1.0 - g) <= o.epsilon : r < o.epsilon;
    if (done || g == 0.0) {
      sum.residual = r;
      sum.policy_loss_bound = g < 1.0 ? 2.0 * r / (1.0 - g) : kInf;
      sum.termination = SolverTermination::kConverged;
      break;
    }
    for (int j = 1; j < o.evaluation_sweeps; ++j) k.evaluate_in_place(policy.data(), v.data());
  }
  sum.iterations = it;
  if (g == 1.0 && sum.converged()) {
    int steps = 0;
    const auto greedy = greedy_policy(m, v);
    run_policy_iteration(m, greedy, 10'000, 1e-12, &sum, &steps);
    sum.polish_iterations = steps;
  } else {
    sum.value = std::move(v);
    sum.policy = std::move(policy);
  }
  sum.seconds = seconds_since(t0);
  sum.message = fmt::format("modified policy iteration (m = {}) {}", o.evaluation_sweeps,
                            termination_name(sum.termination));
  return sum;
}

StochasticPolicy StochasticPolicy::from_deterministic(const FiniteMdp& m, std::span<const int> policy) {
  check(policy.size() == static_cast<std::size_t>(m.num_states),
        fmt::format("policy: expected {} actions, got {}", m.num_states, policy.size()));
  StochasticPolicy p;
  p.num_states = m.num_states;
  p.num_actions = m.num_actions;
  p.probs.assign(m.num_rows(), 0.0);
  for (int s = 0; s < m.num_states; ++s) {
    const int a = policy[static_cast<std::size_t>(s)];
    check(a >= 0 && a < m.num_actions, fmt::format("policy: action {} of state {} outside [0, {})", a, s, m.num_actions));
    p.probs[m.row(s, a)] = 1.0;
  }
  return p;
}

std::vector<double> evaluate_policy(const FiniteMdp& m, std::span<const int> policy) {
  return evaluate_policy(m, StochasticPolicy::from_deterministic(m, policy));
}

std::vector<double> evaluate_policy(const FiniteMdp& m, const StochasticPolicy& pi) {
  check(pi.num_states == m.num_states && pi.num_actions == m.num_actions && pi.probs.size() == m.num_rows(),
        "policy: shape does not match the MDP");
  const int S = m.num_states, A = m.num_actions;
  std::vector<int> index(static_cast<std::size_t>(S), -1);
  int n = 0;
  for (int s = 0; s < S; ++s)
    if (!m.is_absorbing(s)) index[static_cast<std::size_t>(s)] = n++;
  std::vector<double> v(static_cast<std::size_t>(S), 0.0);
  if (n == 0) return v;
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(m.num_entries() + static_cast<std::size_t>(n));
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n);
  for (int s = 0; s < S; ++s) {
    const int i = index[static_cast<std::size_t>(s)];
    if (i < 0) continue;
    double total = 0.0;
    trip.emplace_back(i, i, 1.0);
    for (int a = 0; a < A; ++a) {
      const double w = pi.probs[m.row(s, a)];
      check(w >= 0.0 && w <= 1.0, fmt::format("policy: probability {} of action {} in state {} outside [0, 1]", w, a, s));
      total += w;
      if (w == 0.0) continue;
      const std::size_t r = m.row(s, a);
      rhs[i] += w * m.expected_reward[r];
      for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k) {
        const int j = index[static_cast<std::size_t>(m.next_state[k])];
        if (j >= 0) trip.emplace_back(i, j, -m.gamma * w * m.probability[k]);
      }
    }
    check(std::abs(total - 1.0) <= 1e-9, fmt::format("policy: action probabilities of state {} sum to {}", s, total));
  }
  Eigen::SparseMatrix<double> mat(n, n);
  mat.setFromTriplets(trip.begin(), trip.end());  // sums duplicates
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu;
  lu.compute(mat);
  if (lu.info() != Eigen::Success)
    throw InputError("policy evaluation: I - gamma P_pi is singular (is the policy proper?)");
  const Eigen::VectorXd x = lu.solve(rhs);
  for (int s = 0; s < S; ++s) {
    const int i = index[static_cast<std::size_t>(s)];
    if (i >= 0) v[static_cast<std::size_t>(s)] = x[i];
  }
  return v;
}

std::vector<double> q_from_values(const FiniteMdp& m, std::span<const double> value) {
  check(value.size() == static_cast<std::size_t>(m.num_states), "q_from_values: value has the wrong size");
  const Kernel k(m);
  std::vector<double> q(m.num_rows(), 0.0);
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) continue;
    for (int a = 0; a < m.num_actions; ++a) q[m.row(s, a)] = k.q(m.row(s, a), value.data());
  }
  return q;
}

std::vector<int> greedy_policy(const FiniteMdp& m, std::span<const double> value) {
  check(value.size() == static_cast<std::size_t>(m.num_states), "greedy_policy: value has the wrong size");
  const Kernel k(m);
  std::vector<int> policy(static_cast<std::size_t>(m.num_states), 0);
  for (int s = 0; s < m.num_states; ++s)
    if (!m.is_absorbing(s)) k.best(s, value.data(), &policy[static_cast<std::size_t>(s)]);
  return policy;
}

double bellman_backup(const FiniteMdp& m, std::span<const double> value, std::span<double> out) {
  check(value.size() == static_cast<std::size_t>(m.num_states) && out.size() == value.size(),
        "bellman_backup: wrong sizes");
  std::vector<int> policy(value.size());
  std::vector<double> tmp(value.size());
  const double r = Kernel(m).jacobi(value.data(), tmp.data(), policy.data());
  std::copy(tmp.begin(), tmp.end(), out.begin());
  return r;
}

std::vector<std::uint64_t> near_optimal_actions(const FiniteMdp& m, std::span<const double> q, double tol) {
  check(m.num_actions <= 64, "near_optimal_actions: at most 64 actions");
  check(q.size() == m.num_rows(), "near_optimal_actions: q has the wrong size");
  std::vector<std::uint64_t> mask(static_cast<std::size_t>(m.num_states), 0);
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) {
      mask[static_cast<std::size_t>(s)] = m.num_actions == 64 ? ~0ULL : ((1ULL << m.num_actions) - 1);
      continue;
    }
    double best = -kInf;
    for (int a = 0; a < m.num_actions; ++a) best = std::max(best, q[m.row(s, a)]);
    for (int a = 0; a < m.num_actions; ++a)
      if (q[m.row(s, a)] >= best - tol) mask[static_cast<std::size_t>(s)] |= 1ULL << a;
  }
  return mask;
}

double expected_under_initial(const FiniteMdp& m, std::span<const double> value) {
  double sum = 0.0;
  for (int s = 0; s < m.num_states; ++s) sum += m.initial[static_cast<std::size_t>(s)] * value[static_cast<std::size_t>(s)];
  return sum;
}

}  // namespace pegasus
