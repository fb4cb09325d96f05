// Finite-MDP solvers and the Sarsa learner (thesis §2.2-2.3, §3.4).
//   BM_ValueIteration_Corner20x20_*       AI-Toolbox's corner problem (MDP/Environments/CornerProblem.hpp:
//   BM_PolicyIteration_Corner20x20        20x20 grid, absorbing corners 0 and 399, moves succeed with 0.8 and
//                                         otherwise stay, -1 per move and per bump into a wall, 0 for a
//                                         failed move; gamma 0.95), tolerance 1e-5.
//   BM_ValueIteration_RandomDense500x4_*  a random dense MDP (500 states, 4 actions, every successor,
//   BM_PolicyIteration_RandomDense500x4   rewards uniform in [-1, 1], gamma 0.95; random_mdp, seed 2024).
//     *_Residual1e-5      the stopping rule AI-Toolbox uses: stop when a sweep changes V by < 1e-5 (like for
//     like per sweep)
//     *_EpsOptimal1e-5    the span (MacQueen) rule: stop when the greedy policy is certified 1e-5-optimal
//     *_Certified1e-6     like for like on the output: the span rule with epsilon = 2e-6 / gamma, so that the
//                         returned V is certified within 1e-6 of V* (value_error_bound <= gamma eps / 2)
//     *_CertifiedAsAIToolbox  certified as close to V* as AI-Toolbox's output at tolerance 1e-5 is in fact
//                         (measured against V*: 1.84e-4 on the dense MDP, 3.96e-6 on the corner problem)
//   BM_BellmanSweep_RandomDense500x4      one sweep of the dense MDP: bytes_per_sweep (8 MB of probabilities)
//                                         and GB_per_s
//   BM_BellmanSweep_Gridworld1000x1000    one Jacobi sweep of T over the 1M-state gridworld (gamma 0.95):
//   BM_ValueIteration_Gridworld1000x1000_10Sweeps   sweeps_per_s, bytes_per_sweep (the CSR arrays, V read
//                                         once, V and the policy written) and GB_per_s = their ratio.
//   BM_Sarsa_Gridworld50x50               Sarsa (0.1-greedy, alpha 0.02, Q = 0) on the §3.4 50x50 gridworld,
//   BM_SarsaRuns4_Gridworld50x50          one run / four runs in lockstep (sarsa_runs), 100 episodes each,
//   BM_SarsaReference_Mt19937_Gridworld50x50  and the plain reference loop with std::mt19937_64 below.
//                                         All report steps_per_s (learning steps per wall second, one core)
//                                         and steps_per_cpu_s (per second of the thread's CPU time: the
//                                         figure to compare when other processes share the cores).
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <random>
#include <vector>

#include "pegasus/envs/gridworld.hpp"
#include "pegasus/mdp/learners.hpp"
#include "pegasus/mdp/random_mdp.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/random/block_stream.hpp"

namespace pegasus {
namespace {

// AI-Toolbox's makeCornerProblem(GridWorld(n, n)): state x + y n, actions UP, RIGHT, DOWN, LEFT.
FiniteMdp corner_problem(int n, double success = 0.8, double gamma = 0.95) {
  const int S = n * n;
  FiniteMdpBuilder b(S, 4, gamma);
  b.set_absorbing(0);
  b.set_absorbing(S - 1);
  const int dx[4] = {0, 1, 0, -1}, dy[4] = {-1, 0, 1, 0};
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const int s = x + y * n;
      if (s == 0 || s == S - 1) continue;
      for (int a = 0; a < 4; ++a) {
        const int x1 = std::clamp(x + dx[a], 0, n - 1), y1 = std::clamp(y + dy[a], 0, n - 1);
        const int s1 = x1 + y1 * n;
        if (s1 == s) {
          b.add_transition(s, a, s, 1.0, -1.0);
        } else {
          b.add_transition(s, a, s1, success, -1.0);
          b.add_transition(s, a, s, 1.0 - success, 0.0);
        }
      }
    }
  return b.build();
}

FiniteMdp random_dense(int states = 500, int actions = 4) {
  UniformStream rng(2024, 0);
  return random_mdp({.num_states = states, .num_actions = actions, .successors = states, .gamma = 0.95}, rng);
}

const FiniteMdp& corner20() {
  static const FiniteMdp m = corner_problem(20);
  return m;
}
const FiniteMdp& dense500() {
  static const FiniteMdp m = random_dense();
  return m;
}

void value_iteration_bench(benchmark::State& state, const FiniteMdp& m, StopRule rule) {
  ValueIterationOptions o;
  o.stop = rule;
  o.tolerance = 1e-5;
  o.epsilon = 1e-5;
  SolveSummary sum;
  for (auto _ : state) {
    sum = value_iteration(m, o);
    benchmark::DoNotOptimize(sum.value.data());
  }
  state.counters["sweeps"] = sum.iterations;
  state.counters["policy_loss_bound"] = sum.policy_loss_bound;
  state.counters["value_error_bound"] = sum.value_error_bound;
}

// The span rule's epsilon whose certificate puts the returned V within `error` of V*.
void certified_bench(benchmark::State& state, const FiniteMdp& m, double error) {
  ValueIterationOptions o;
  o.epsilon = 2.0 * error / m.gamma;
  SolveSummary sum;
  for (auto _ : state) {
    sum = value_iteration(m, o);
    benchmark::DoNotOptimize(sum.value.data());
  }
  state.counters["sweeps"] = sum.iterations;
  state.counters["value_error_bound"] = sum.value_error_bound;
}

void policy_iteration_bench(benchmark::State& state, const FiniteMdp& m) {
  SolveSummary sum;
  for (auto _ : state) {
    sum = policy_iteration(m);
    benchmark::DoNotOptimize(sum.value.data());
  }
  state.counters["improvements"] = sum.iterations;
}

void BM_ValueIteration_Corner20x20_Residual1e5(benchmark::State& s) {
  value_iteration_bench(s, corner20(), StopRule::kResidual);
}
void BM_ValueIteration_Corner20x20_EpsOptimal1e5(benchmark::State& s) {
  value_iteration_bench(s, corner20(), StopRule::kEpsilonOptimal);
}
void BM_PolicyIteration_Corner20x20(benchmark::State& s) { policy_iteration_bench(s, corner20()); }
void BM_ValueIteration_RandomDense500x4_Residual1e5(benchmark::State& s) {
  value_iteration_bench(s, dense500(), StopRule::kResidual);
}
void BM_ValueIteration_RandomDense500x4_EpsOptimal1e5(benchmark::State& s) {
  value_iteration_bench(s, dense500(), StopRule::kEpsilonOptimal);
}
void BM_PolicyIteration_RandomDense500x4(benchmark::State& s) { policy_iteration_bench(s, dense500()); }
void BM_ValueIteration_Corner20x20_Certified1e6(benchmark::State& s) { certified_bench(s, corner20(), 1e-6); }
void BM_ValueIteration_Corner20x20_CertifiedAsAIToolbox(benchmark::State& s) {
  certified_bench(s, corner20(), 3.96e-6);
}
void BM_ValueIteration_RandomDense500x4_Certified1e6(benchmark::State& s) {
  certified_bench(s, dense500(), 1e-6);
}
void BM_ValueIteration_RandomDense500x4_CertifiedAsAIToolbox(benchmark::State& s) {
  certified_bench(s, dense500(), 1.84e-4);
}
void BM_BellmanSweep_RandomDense500x4(benchmark::State& state) {
  const FiniteMdp& m = dense500();
  std::vector<double> v(static_cast<std::size_t>(m.num_states), 0.0), out(v.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(bellman_backup(m, v, out));
    std::swap(v, out);
  }
  const double bytes = 8.0 * static_cast<double>(m.num_entries());  // the probabilities; V and R are tiny
  state.counters["bytes_per_sweep"] = bytes;
  state.counters["GB_per_s"] =
      benchmark::Counter(bytes * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ValueIteration_Corner20x20_Residual1e5)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_ValueIteration_Corner20x20_EpsOptimal1e5)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_PolicyIteration_Corner20x20)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_ValueIteration_RandomDense500x4_Residual1e5)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_ValueIteration_RandomDense500x4_EpsOptimal1e5)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_PolicyIteration_RandomDense500x4)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_ValueIteration_Corner20x20_Certified1e6)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_ValueIteration_Corner20x20_CertifiedAsAIToolbox)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_ValueIteration_RandomDense500x4_Certified1e6)->Unit(benchmark::kMicrosecond)->MinTime(0.5);
BENCHMARK(BM_ValueIteration_RandomDense500x4_CertifiedAsAIToolbox)
    ->Unit(benchmark::kMicrosecond)
    ->MinTime(0.5);
BENCHMARK(BM_BellmanSweep_RandomDense500x4)->Unit(benchmark::kMicrosecond)->MinTime(0.5);

// ---- 1000 x 1000 gridworld: memory bandwidth of a sweep -------------------------------------------------

const FiniteMdp& grid1000() {
  static const FiniteMdp m = to_finite_mdp(corner_gridworld(1000), 0.95);
  return m;
}

// What a Jacobi sweep streams: row_start (4 B per row), next_state and probability (12 B per entry), the
// cached R(s, a) (8 B per row), the absorbing flags (1 B), V read once, V' and the greedy action written.
double bytes_per_sweep(const FiniteMdp& m) {
  const double rows = static_cast<double>(m.num_rows()), nnz = static_cast<double>(m.num_entries());
  const double S = m.num_states;
  return 4.0 * (rows + 1) + 12.0 * nnz + 8.0 * rows + S * (1.0 + 8.0 + 8.0 + 4.0);
}

void report_sweeps(benchmark::State& state, const FiniteMdp& m, double sweeps_per_iteration) {
  state.counters["sweeps_per_s"] =
      benchmark::Counter(sweeps_per_iteration, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["bytes_per_sweep"] = bytes_per_sweep(m);
  state.counters["GB_per_s"] = benchmark::Counter(sweeps_per_iteration * bytes_per_sweep(m) * 1e-9,
                                                  benchmark::Counter::kIsIterationInvariantRate);
  state.counters["states"] = m.num_states;
  state.counters["entries"] = static_cast<double>(m.num_entries());
}

void BM_BellmanSweep_Gridworld1000x1000(benchmark::State& state) {
  const FiniteMdp& m = grid1000();
  std::vector<double> v(static_cast<std::size_t>(m.num_states), 0.0), out(v.size());
  for (auto _ : state) {
    benchmark::DoNotOptimize(bellman_backup(m, v, out));
    std::swap(v, out);
  }
  // bellman_backup writes no policy: 4 B per state fewer than the solver's sweep.
  state.counters["sweeps_per_s"] = benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
  const double bytes = bytes_per_sweep(m) - 4.0 * m.num_states;
  state.counters["bytes_per_sweep"] = bytes;
  state.counters["GB_per_s"] =
      benchmark::Counter(bytes * 1e-9, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_BellmanSweep_Gridworld1000x1000)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

void BM_ValueIteration_Gridworld1000x1000_10Sweeps(benchmark::State& state) {
  const FiniteMdp& m = grid1000();
  ValueIterationOptions o;
  o.stop = StopRule::kResidual;
  o.tolerance = 1e-300;
  o.max_iterations = 10;
  int sweeps = 0;
  for (auto _ : state) {
    const SolveSummary sum = value_iteration(m, o);
    sweeps = sum.iterations;
    benchmark::DoNotOptimize(sum.value.data());
  }
  report_sweeps(state, m, sweeps);
}
BENCHMARK(BM_ValueIteration_Gridworld1000x1000_10Sweeps)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

// ---- Sarsa on the 50x50 gridworld -----------------------------------------------------------------------

constexpr int kEpisodes = 100;

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void report_steps(benchmark::State& state, std::int64_t steps, double cpu0) {
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
  state.counters["steps_per_cpu_s"] = static_cast<double>(steps) / (thread_cpu_seconds() - cpu0);
}
const TdOptions kTd{.episodes = kEpisodes, .alpha = 0.02, .epsilon = 0.1, .gamma = 1.0};

void BM_Sarsa_Gridworld50x50(benchmark::State& state) {
  const GridWorld w = corner_gridworld(50);
  std::int64_t steps = 0;
  std::uint32_t stream = 0;
  const double cpu0 = thread_cpu_seconds();
  for (auto _ : state) {
    BlockUniformStream rng(7, stream++ % 64);
    QTable q(w.num_states(), w.num_actions());
    steps += sarsa(w, kTd, rng, q).total_steps;
    benchmark::DoNotOptimize(q.q.data());
  }
  report_steps(state, steps, cpu0);
}
BENCHMARK(BM_Sarsa_Gridworld50x50)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

void BM_SarsaRuns4_Gridworld50x50(benchmark::State& state) {
  const GridWorld w = corner_gridworld(50);
  std::int64_t steps = 0;
  std::uint32_t stream = 0;
  const double cpu0 = thread_cpu_seconds();
  for (auto _ : state) {
    std::vector<BlockUniformStream> rngs;
    std::vector<QTable> qs;
    for (int k = 0; k < 4; ++k) {
      rngs.emplace_back(7, stream++ % 64);
      qs.emplace_back(w.num_states(), w.num_actions());
    }
    for (const auto& c : sarsa_runs(w, kTd, std::span(rngs), std::span(qs))) steps += c.total_steps;
    benchmark::DoNotOptimize(qs[0].q.data());
  }
  report_steps(state, steps, cpu0);
}
BENCHMARK(BM_SarsaRuns4_Gridworld50x50)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

// The reference: Sarsa as one would first write it, with std::mt19937_64 and std::uniform_real_distribution
// (epsilon-greedy with random tie-breaking, the 80/20 move, the goal ends the episode).
std::int64_t reference_sarsa(const GridWorld& w, std::mt19937_64& gen, std::vector<double>& Q) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const GridGeometry& g = w.geometry();
  auto choose = [&](int s) {
    if (uniform(gen) < kTd.epsilon) return static_cast<int>(uniform(gen) * 4) & 3;
    const double* q = &Q[static_cast<std::size_t>(s) * 4];
    const double best = *std::max_element(q, q + 4);
    int ties[4], n = 0;
    for (int a = 0; a < 4; ++a)
      if (q[a] == best) ties[n++] = a;
    return n == 1 ? ties[0] : ties[std::min(n - 1, static_cast<int>(uniform(gen) * n))];
  };
  std::int64_t steps = 0;
  for (int e = 0; e < kEpisodes; ++e) {
    int s = w.start();
    int a = choose(s);
    while (true) {
      const double u = uniform(gen);
      const int d =
          u < w.intended() ? a : std::min(3, static_cast<int>((u - w.intended()) / (1.0 - w.intended()) * 4));
      const int s2 = g.move(s, d);
      ++steps;
      double& qsa = Q[static_cast<std::size_t>(s) * 4 + static_cast<std::size_t>(a)];
      if (s2 == w.goal()) {
        qsa += kTd.alpha * (-1.0 - qsa);
        break;
      }
      const int a2 = choose(s2);
      qsa += kTd.alpha * (-1.0 + Q[static_cast<std::size_t>(s2) * 4 + static_cast<std::size_t>(a2)] - qsa);
      s = s2;
      a = a2;
    }
  }
  return steps;
}

void BM_SarsaReference_Mt19937_Gridworld50x50(benchmark::State& state) {
  const GridWorld w = corner_gridworld(50);
  std::int64_t steps = 0;
  std::uint64_t seed = 0;
  const double cpu0 = thread_cpu_seconds();
  for (auto _ : state) {
    std::mt19937_64 gen(seed++);
    std::vector<double> Q(static_cast<std::size_t>(w.num_states()) * 4, 0.0);
    steps += reference_sarsa(w, gen, Q);
    benchmark::DoNotOptimize(Q.data());
  }
  report_steps(state, steps, cpu0);
}
BENCHMARK(BM_SarsaReference_Mt19937_Gridworld50x50)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MinTime(2.0);

}  // namespace
}  // namespace pegasus
