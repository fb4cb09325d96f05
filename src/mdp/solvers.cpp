#include "pegasus/mdp/solvers.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseLU>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "exact_policy_evaluation.hpp"
#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The range of Delta = T V - V over the states of one sweep. Absorbing states count with Delta = 0: with
// them T is only monotone and sub-homogeneous (T(V + c) <= T V + gamma c for c >= 0, >= for c <= 0), so
// the MacQueen bounds below need min Delta <= 0 <= max Delta, which including them guarantees.
struct Sweep {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double d) {
    lo = std::min(lo, d);
    hi = std::max(hi, d);
  }
  double max_abs() const { return std::max(std::abs(lo), std::abs(hi)); }
  double span() const { return hi - lo; }
};

// The dense rows' kernel on the best instruction set (mdp/dense_dot4.cpp), looked up once (a
// function-local static: safe during static initialisation).
detail::DenseDot4 best_dot4() {
  static const detail::DenseDot4 dot = detail::dense_dot4_kernel(best_instruction_set());
  return dot;
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
  bool all_dense;  // every row lists every state: rows of a state are A consecutive blocks of S

  explicit Kernel(const FiniteMdp& m)
      : row_start(m.row_start.data()),
        next(m.next_state.data()),
        prob(m.probability.data()),
        r_sa(m.expected_reward.data()),
        absorbing(m.absorbing.data()),
        gamma(m.gamma),
        S(m.num_states),
        A(m.num_actions),
        all_dense(m.num_states >= 16 &&
                  m.num_entries() == m.num_rows() * static_cast<std::size_t>(m.num_states)) {}

  double q(std::size_t r, const double* __restrict v) const {
    const std::uint32_t b = row_start[r], e = row_start[r + 1];
    if (e - b == static_cast<std::uint32_t>(S) && S >= 16) {
      // A dense row lists every state in order (successors are sorted and unique): a contiguous dot
      // product, which Eigen vectorises, instead of a gather.
      const Eigen::Map<const Eigen::VectorXd> p(prob + b, S), x(v, S);
      return r_sa[r] + gamma * p.dot(x);
    }
    double acc = 0.0;
    for (std::uint32_t k = b; k < e; ++k) acc += prob[k] * v[next[k]];
    return r_sa[r] + gamma * acc;
  }

  // Best Q at s and its (lowest) argmax.
  double best(int s, const double* v, int* arg) const {
    const std::size_t base = static_cast<std::size_t>(s) * static_cast<std::size_t>(A);
    if (all_dense && A >= 4) return best_dense(base, v, arg);
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

  // best() for a dense MDP: the actions four at a time through the dense kernel, the rest one by one.
  double best_dense(std::size_t base, const double* v, int* arg) const {
    double b = -std::numeric_limits<double>::infinity();
    int ba = 0;
    const std::size_t stride = static_cast<std::size_t>(S);
    const detail::DenseDot4 dot4 = best_dot4();
    int a = 0;
    for (; a + 4 <= A; a += 4) {
      const std::size_t r = base + static_cast<std::size_t>(a);
      double dots[4];
      dot4(prob + row_start[r], stride, v, S, dots);
      for (int j = 0; j < 4; ++j) {
        const double x = r_sa[r + static_cast<std::size_t>(j)] + gamma * dots[j];
        if (x > b) {
          b = x;
          ba = a + j;
        }
      }
    }
    for (; a < A; ++a) {
      const double x = q(base + static_cast<std::size_t>(a), v);
      if (x > b) {
        b = x;
        ba = a;
      }
    }
    *arg = ba;
    return b;
  }

  // out = T v and policy = greedy(v); returns the range of T v - v. v and out must differ.
  Sweep jacobi(const double* __restrict v, double* __restrict out, int* __restrict policy) const {
    Sweep sw;
    for (int s = 0; s < S; ++s) {
      if (absorbing[s]) {
        out[s] = 0.0;
        policy[s] = 0;
        sw.add(0.0);  // see Sweep: absorbing states pin the range to include 0
        continue;
      }
      const double b = best(s, v, &policy[s]);
      sw.add(b - v[s]);
      out[s] = b;
    }
    return sw;
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
      v[s] = q(
          static_cast<std::size_t>(s) * static_cast<std::size_t>(A) + static_cast<std::size_t>(policy[s]), v);
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
  std::vector<double> v =
      given.empty() ? std::vector<double>(static_cast<std::size_t>(m.num_states), 0.0) : given;
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
  detail::PolicyEvaluator evaluator(m);
  std::vector<double> v;
  *steps = 0;
  bool stable = false;
  while (*steps < max_iterations) {
    v = evaluator.evaluate(
        [&policy](int s, int a) { return policy[static_cast<std::size_t>(s)] == a ? 1.0 : 0.0; });
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
  out->value_error_bound = stable ? 0.0 : kInf;
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
    return bad(
        fmt::format("initial_values must have {} entries, got {}", mdp.num_states, initial_values.size()));
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
        return bad(
            fmt::format("initial_policy[{}] = {} outside [0, {})", s, initial_policy[s], mdp.num_actions));
  }
  return true;
}

bool ModifiedPolicyIterationOptions::IsValid(const FiniteMdp&, std::string* error) const {
  auto bad = [&](const std::string& m) {
    if (error) *error = "modified policy iteration options: " + m;
    return false;
  };
  if (!(epsilon > 0.0)) return bad(fmt::format("epsilon must be > 0, got {}", epsilon));
  if (evaluation_sweeps < 1)
    return bad(fmt::format("evaluation_sweeps must be >= 1, got {}", evaluation_sweeps));
  if (max_iterations < 1) return bad(fmt::format("max_iterations must be >= 1, got {}", max_iterations));
  return true;
}

std::string SolveSummary::BriefReport() const {
  return fmt::format("{} after {} iterations (+{} polish), residual {:.3g}, policy loss <= {:.3g}, {:.3g} s",
                     termination_name(termination), iterations, polish_iterations, residual,
                     policy_loss_bound, seconds);
}

namespace {

// Certificate and value estimate from the last Jacobi sweep V' = T V with pi greedy w.r.t. V and
// Delta = V' - V in [lo, hi] (MacQueen bounds, Puterman §6.6.3): with gamma < 1,
//   V' + gamma lo / (1-gamma) <= V* <= V' + gamma hi / (1-gamma)   and   V^pi >= V + lo / (1-gamma),
// so max_s V*(s) - V^pi(s) <= (hi - lo) / (1-gamma) (never worse than the classic 2 ||Delta|| / (1-gamma)),
// and the midpoint of the bounds is within gamma (hi - lo) / (2 (1-gamma)) of V*. On a well-mixing MDP the
// span hi - lo shrinks much faster than ||Delta||, which only shrinks like gamma^k.
void finish_discounted(const FiniteMdp& m, const Sweep& sw, bool extrapolate, std::vector<double>& v,
                       SolveSummary* sum) {
  const double g = m.gamma;
  sum->residual = sw.max_abs();
  sum->policy_loss_bound = g == 0.0 ? 0.0 : sw.span() / (1.0 - g);
  if (extrapolate && g > 0.0) {
    const double shift = g * (sw.lo + sw.hi) / (2.0 * (1.0 - g));
    for (int s = 0; s < m.num_states; ++s)
      if (!m.is_absorbing(s)) v[static_cast<std::size_t>(s)] += shift;
    sum->value_error_bound = g * sw.span() / (2.0 * (1.0 - g));
  } else {
    sum->value_error_bound = g == 0.0 ? 0.0 : g * sw.max_abs() / (1.0 - g);
  }
}

}  // namespace

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
  sum.value_error_bound = kInf;
  sum.termination = SolverTermination::kMaxIterations;
  const bool residual_rule = o.stop == StopRule::kResidual;
  // Is the sweep that produced `sw` good enough to stop?
  auto done = [&](const Sweep& sw) {
    if (residual_rule) return sw.max_abs() < o.tolerance;
    if (g == 1.0) return sw.max_abs() < o.epsilon;  // then polished by policy iteration
    return g == 0.0 || sw.span() / (1.0 - g) <= o.epsilon;
  };
  Sweep last;
  int it = 0;
  while (it < o.max_iterations) {
    ++it;
    if (!o.gauss_seidel) {
      last = k.jacobi(v.data(), w.data(), policy.data());
      std::swap(v, w);  // v = T v_old, policy greedy w.r.t. v_old
      if (done(last)) {
        sum.termination = SolverTermination::kConverged;
        break;
      }
    } else {
      // A Gauss-Seidel sweep's change only says when to try the certificate, which needs a Jacobi pass.
      const double change = k.gauss_seidel(v.data());
      const double try_below = residual_rule ? o.tolerance
                               : g < 1.0     ? o.epsilon * (1.0 - g) / 2.0
                                             : o.epsilon;
      if (change < try_below || g == 0.0) {
        last = k.jacobi(v.data(), w.data(), policy.data());
        std::swap(v, w);
        if (residual_rule || done(last)) {
          sum.termination = SolverTermination::kConverged;
          break;
        }
      }
    }
  }
  sum.iterations = it;
  if (g == 1.0 && !residual_rule && sum.converged()) {
    int steps = 0;
    const auto greedy = greedy_policy(m, v);
    run_policy_iteration(m, greedy, 10'000, 1e-12, &sum, &steps);
    sum.polish_iterations = steps;
    sum.value_error_bound = 0.0;
  } else {
    if (g < 1.0 && it > 0)
      finish_discounted(m, last, !residual_rule, v, &sum);
    else
      sum.residual = last.max_abs();
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
  if (policy.empty())
    policy = greedy_policy(m, std::vector<double>(static_cast<std::size_t>(m.num_states), 0.0));
  SolveSummary sum;
  run_policy_iteration(m, std::move(policy), o.max_iterations, o.improvement_tolerance, &sum,
                       &sum.iterations);
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
  sum.value_error_bound = kInf;
  sum.termination = SolverTermination::kMaxIterations;
  Sweep last;
  int it = 0;
  while (it < o.max_iterations) {
    ++it;
    last = k.jacobi(v.data(), w.data(), policy.data());
    std::swap(v, w);
    const bool done =
        g == 0.0 || (g < 1.0 ? last.span() / (1.0 - g) <= o.epsilon : last.max_abs() < o.epsilon);
    if (done) {
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
    sum.value_error_bound = 0.0;
  } else {
    // The certificate concerns the last improvement sweep only (partial evaluations came before it).
    if (g < 1.0)
      finish_discounted(m, last, true, v, &sum);
    else
      sum.residual = last.max_abs();
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
    check(a >= 0 && a < m.num_actions,
          fmt::format("policy: action {} of state {} outside [0, {})", a, s, m.num_actions));
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
  for (int s = 0; s < m.num_states; ++s) {
    double total = 0.0;
    for (int a = 0; a < m.num_actions; ++a) {
      const double w = pi.probs[m.row(s, a)];
      check(w >= 0.0 && w <= 1.0,
            fmt::format("policy: probability {} of action {} in state {} outside [0, 1]", w, a, s));
      total += w;
    }
    check(std::abs(total - 1.0) <= 1e-9,
          fmt::format("policy: action probabilities of state {} sum to {}", s, total));
  }
  detail::PolicyEvaluator evaluator(m);
  return evaluator.evaluate([&](int s, int a) { return pi.probs[m.row(s, a)]; });
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
  const double r = Kernel(m).jacobi(value.data(), tmp.data(), policy.data()).max_abs();
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
  for (int s = 0; s < m.num_states; ++s)
    sum += m.initial[static_cast<std::size_t>(s)] * value[static_cast<std::size_t>(s)];
  return sum;
}

}  // namespace pegasus
