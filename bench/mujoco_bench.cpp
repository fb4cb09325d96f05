// MuJoCo through Pegasus (issue 18): rollout throughput against a plain mj_step loop on the same model, and
// U-hat on 1 and 2 threads. Counters are physics steps per second. Shared, loaded 2-core VM: run each
// benchmark with --benchmark_repetitions and compare medians.
#ifdef PEGASUS_HAVE_MUJOCO
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <filesystem>

#include "pegasus/mujoco/mujoco_objective.hpp"

namespace {

using namespace pegasus;

std::filesystem::path experiments() {
  return std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "mujoco";
}

std::shared_ptr<const MujocoEnvironment> environment(const std::string& model, const std::string& task) {
  MujocoModel m = MujocoModel::load(model);
  MujocoTask t = load_mujoco_task(experiments() / task, m);
  return std::make_shared<const MujocoEnvironment>(std::move(m), std::move(t));
}

std::shared_ptr<const MujocoEnvironment> cartpole() {
  return environment((experiments() / "cartpole.xml").string(), "cartpole_swingup.toml");
}
std::shared_ptr<const MujocoEnvironment> arm26() {
  return environment("/usr/share/mujoco/model/tendon_arm/arm26.xml", "arm26_posture.toml");
}

// The reference: reset, then horizon * frame_skip mj_step calls with a fixed ctrl; nothing else.
void PlainLoop(benchmark::State& state, const MujocoEnvironment& env) {
  const mjModel* m = env.model().get();
  mjData* d = mj_makeData(m);
  const int steps = env.task().horizon * env.task().frame_skip;
  std::int64_t total = 0;
  for (auto _ : state) {
    mj_resetData(m, d);
    for (int k = 0; k < m->nu; ++k) d->ctrl[k] = 0.1;
    for (int s = 0; s < steps; ++s) mj_step(m, d);
    total += steps;
    benchmark::DoNotOptimize(d->qpos[0]);
  }
  state.counters["physics_steps_per_s"] =
      benchmark::Counter(static_cast<double>(total), benchmark::Counter::kIsRate);
  mj_deleteData(d);
}

// The same physics through a Pegasus rollout: scenario noise, observation, normalisation, the linear policy
// (theta = 0: every rollout runs the full horizon), reward and termination checks.
void PegasusRollout(benchmark::State& state, const MujocoEnvironment& env) {
  const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
  const Theta theta(policy->parameters().size(), 0.0);
  const ScenarioSet scenarios = env.scenarios(1, 64, ScenarioVariant::kPlain);
  const ObservationNormalizer normalizer(env.observation_dim());
  MujocoSlot slot(env);
  std::int64_t total = 0;
  int i = 0;
  for (auto _ : state) {
    const auto r = env.rollout(*policy, theta, normalizer, scenarios, i, slot);
    i = (i + 1) % scenarios.size();
    total += static_cast<std::int64_t>(r.steps) * env.task().frame_skip;
  }
  state.counters["physics_steps_per_s"] =
      benchmark::Counter(static_cast<double>(total), benchmark::Counter::kIsRate);
}

void BM_MujocoPlainStepLoop_Cartpole_H300x2(benchmark::State& state) { PlainLoop(state, *cartpole()); }
void BM_MujocoPegasusRollout_Cartpole_H300x2(benchmark::State& state) { PegasusRollout(state, *cartpole()); }
void BM_MujocoPlainStepLoop_Arm26_H200x4(benchmark::State& state) { PlainLoop(state, *arm26()); }
void BM_MujocoPegasusRollout_Arm26_H200x4(benchmark::State& state) { PegasusRollout(state, *arm26()); }
BENCHMARK(BM_MujocoPlainStepLoop_Cartpole_H300x2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MujocoPegasusRollout_Cartpole_H300x2)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MujocoPlainStepLoop_Arm26_H200x4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MujocoPegasusRollout_Arm26_H200x4)->Unit(benchmark::kMillisecond);

// U-hat of a batch of 8 thetas on 16 arm26 scenarios (128 rollouts) on `threads` threads.
void BM_MujocoUhatBatch_Arm26_8x16(benchmark::State& state) {
  const auto env = arm26();
  std::shared_ptr<const MujocoPolicy> policy =
      make_mujoco_policy("linear", env->observation_dim(), env->action_dim(), {});
  ThreadPool pool(static_cast<int>(state.range(0)));
  MujocoObjective objective(env, policy, env->scenarios(1, 16, ScenarioVariant::kPlain), &pool);
  std::vector<Theta> thetas(8, Theta(policy->parameters().size(), 0.0));
  for (std::size_t k = 0; k < thetas.size(); ++k) thetas[k][0] = 0.01 * static_cast<double>(k);
  std::vector<double> values(thetas.size());
  for (auto _ : state) objective.evaluate_batch(thetas, values);
  state.counters["physics_steps_per_s"] = benchmark::Counter(
      static_cast<double>(objective.control_steps() * env->task().frame_skip), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MujocoUhatBatch_Arm26_8x16)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
#endif
