// MuJoCo through Pegasus (issue 18): rollout throughput against a plain mj_step loop on the same model, and
// U-hat on 1 and 2 threads, for every shipped model. Counters are physics steps per second.
//
// BM_MujocoOverhead_<model> interleaves, in every benchmark iteration, 16 Pegasus rollouts (scenario noise,
// observation, normalisation, the linear policy at theta = 0, reward, termination and success checks) with a
// plain loop of exactly as many mj_step calls per rollout from the same reset state, replaying the controls
// that rollout applied (recorded once before the timing, so that both do the same physics), and times each
// block by the thread's CPU clock; the counters keep the fastest block of each kind, which filters out the
// interruptions of a shared machine (both kinds are equally exposed to them, and the minimum is the cost
// of the work itself). `ratio` = plain time / Pegasus time per physics step (the issue asks >= 0.95).
// Both step with the model's integrator (issue 52): BM_MujocoOverhead_Hopper_RK4 and _Implicit run the hopper
// with its MJCF's <option> given integrator="RK4" or "implicit" (a copy written to the temporary folder).
// The _GymSwimmer and _GymHopper benchmarks run experiments/mujoco/gymnasium/'s tasks on the user's copies of
// Gymnasium's swimmer.xml and hopper.xml (RK4) in the folder PEGASUS_GYMNASIUM_ASSETS names (skipped
// without).
#ifdef PEGASUS_HAVE_MUJOCO
#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>
#include <time.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "pegasus/mujoco/mujoco_objective.hpp"

namespace {

using namespace pegasus;

std::filesystem::path experiments() {
  return std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "mujoco";
}

std::shared_ptr<const MujocoEnvironment> environment(const std::filesystem::path& model,
                                                     const std::string& task) {
  MujocoModel m = MujocoModel::load(model);
  MujocoTask t = load_mujoco_task(experiments() / task, m);
  return std::make_shared<const MujocoEnvironment>(std::move(m), std::move(t));
}

std::shared_ptr<const MujocoEnvironment> cartpole() {
  return environment(experiments() / "cartpole.xml", "cartpole_swingup.toml");
}
std::shared_ptr<const MujocoEnvironment> acrobot() {
  return environment(experiments() / "acrobot.xml", "acrobot_swingup.toml");
}
std::shared_ptr<const MujocoEnvironment> hopper() {
  return environment(experiments() / "hopper.xml", "hopper_forward.toml");
}
std::shared_ptr<const MujocoEnvironment> arm26() {
  return environment("/usr/share/mujoco/model/tendon_arm/arm26.xml", "arm26_posture.toml");
}

// A Gymnasium task of experiments/mujoco/gymnasium/ on the user's copy of Gymnasium's model, or null when
// PEGASUS_GYMNASIUM_ASSETS (the folder of Gymnasium's assets/*.xml) is not set.
std::shared_ptr<const MujocoEnvironment> gymnasium(const std::string& name) {
  const char* assets = std::getenv("PEGASUS_GYMNASIUM_ASSETS");
  if (assets == nullptr) return nullptr;
  return environment(std::filesystem::path(assets) / (name + ".xml"), "gymnasium/" + name + ".toml");
}

// The hopper with another integrator: its MJCF copied into the temporary folder (its <option> gains the
// attribute; it includes no other file).
std::shared_ptr<const MujocoEnvironment> hopper_with(const std::string& integrator) {
  std::ifstream in(experiments() / "hopper.xml");
  std::stringstream text;
  text << in.rdbuf();
  std::string xml = text.str();
  const std::string option = "<option ";
  xml.insert(xml.find(option) + option.size(), "integrator=\"" + integrator + "\" ");
  const auto path = std::filesystem::temp_directory_path() / ("pegasus-bench-hopper-" + integrator + ".xml");
  std::ofstream(path) << xml;
  auto env = environment(path, "hopper_forward.toml");
  std::filesystem::remove(path);
  return env;
}

double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void Overhead(benchmark::State& state, const MujocoEnvironment& env) {
  constexpr int kRollouts = 16;
  const mjModel* m = env.model().get();
  const auto policy = make_mujoco_policy("linear", env.observation_dim(), env.action_dim(), {});
  const Theta theta(policy->parameters().size(), 0.0);
  const ScenarioSet scenarios = env.scenarios(1, kRollouts, ScenarioVariant::kPlain);
  const ObservationNormalizer normalizer(env.observation_dim());
  MujocoSlot slot(env);
  mjData* d = mj_makeData(m);
  std::array<int, kRollouts> physics_steps{};
  // Each scenario's start state, so that the reference steps the same states (MuJoCo skips work on exact
  // zeros: a model resting at qpos0 steps faster than a perturbed one).
  std::vector<std::vector<double>> start(kRollouts);
  std::vector<double> p0(static_cast<std::size_t>(env.initial_noise_dim()));
  for (int i = 0; i < kRollouts; ++i) {
    scenarios.initial_noise(i, p0);
    env.reset(slot, p0);
    auto& x = start[static_cast<std::size_t>(i)];
    x.assign(slot.data->qpos, slot.data->qpos + m->nq);
    x.insert(x.end(), slot.data->qvel, slot.data->qvel + m->nv);
  }
  // The controls each rollout applies (its policy's actions plus the task's actuator noise, as data->ctrl
  // holds them during each control step), recorded once outside the timing: the reference replays them, so
  // both halves step the same states under the same controls and do the same physics work (a fixed control
  // drives some models into their joint limits, whose constraints cost MuJoCo more, or less, than the
  // rollouts' own states do).
  std::vector<std::vector<double>> controls(kRollouts);
  for (int i = 0; i < kRollouts; ++i) {
    auto& c = controls[static_cast<std::size_t>(i)];
    const MujocoStepObserver record = [&](int, const mjData* data, std::span<const double>, double) {
      c.insert(c.end(), data->ctrl, data->ctrl + m->nu);
    };
    env.rollout(*policy, theta, normalizer, scenarios, i, slot, nullptr, &record);
  }
  const int frame_skip = env.task().frame_skip;
  double best_pegasus = std::numeric_limits<double>::infinity(), best_plain = best_pegasus;
  for (auto _ : state) {
    std::int64_t total = 0;
    const double t0 = thread_cpu_seconds();
    for (int i = 0; i < kRollouts; ++i) {
      const auto r = env.rollout(*policy, theta, normalizer, scenarios, i, slot);
      physics_steps[static_cast<std::size_t>(i)] = r.steps * frame_skip;
      total += physics_steps[static_cast<std::size_t>(i)];
    }
    const double t1 = thread_cpu_seconds();
    // The reference: the same number of mj_step calls from the same start, replaying the rollout's controls.
    for (int i = 0; i < kRollouts; ++i) {
      mj_resetData(m, d);
      const auto& x = start[static_cast<std::size_t>(i)];
      std::copy(x.begin(), x.begin() + m->nq, d->qpos);
      std::copy(x.begin() + m->nq, x.end(), d->qvel);
      const auto& c = controls[static_cast<std::size_t>(i)];
      const int control_steps = physics_steps[static_cast<std::size_t>(i)] / frame_skip;
      for (int t = 0; t < control_steps; ++t) {
        std::copy_n(c.begin() + static_cast<std::ptrdiff_t>(t) * m->nu, m->nu, d->ctrl);
        for (int s = 0; s < frame_skip; ++s) mj_step(m, d);  // its integrator
      }
      benchmark::DoNotOptimize(d->qpos[0]);
    }
    const double t2 = thread_cpu_seconds();
    best_pegasus = std::min(best_pegasus, (t1 - t0) / static_cast<double>(total));
    best_plain = std::min(best_plain, (t2 - t1) / static_cast<double>(total));
  }
  state.counters["pegasus_steps_per_s"] = 1.0 / best_pegasus;
  state.counters["plain_steps_per_s"] = 1.0 / best_plain;
  state.counters["ratio"] = best_plain / best_pegasus;
  mj_deleteData(d);
}

void BM_MujocoOverhead_Cartpole(benchmark::State& state) { Overhead(state, *cartpole()); }
void BM_MujocoOverhead_Acrobot(benchmark::State& state) { Overhead(state, *acrobot()); }
void BM_MujocoOverhead_Hopper(benchmark::State& state) { Overhead(state, *hopper()); }
void BM_MujocoOverhead_Arm26(benchmark::State& state) { Overhead(state, *arm26()); }
BENCHMARK(BM_MujocoOverhead_Cartpole)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_MujocoOverhead_Acrobot)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_MujocoOverhead_Hopper)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_MujocoOverhead_Arm26)->Unit(benchmark::kMillisecond)->MinTime(2.0);
void BM_MujocoOverhead_Hopper_RK4(benchmark::State& state) { Overhead(state, *hopper_with("RK4")); }
void BM_MujocoOverhead_Hopper_Implicit(benchmark::State& state) { Overhead(state, *hopper_with("implicit")); }
BENCHMARK(BM_MujocoOverhead_Hopper_RK4)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_MujocoOverhead_Hopper_Implicit)->Unit(benchmark::kMillisecond)->MinTime(2.0);
// The Gymnasium task `name`, or null (the benchmark skipped) when PEGASUS_GYMNASIUM_ASSETS is unset.
std::shared_ptr<const MujocoEnvironment> gymnasium_or_skip(benchmark::State& state, const std::string& name) {
  auto env = gymnasium(name);
  if (env == nullptr) state.SkipWithError("PEGASUS_GYMNASIUM_ASSETS is not set");
  return env;
}
void GymOverhead(benchmark::State& state, const std::string& name) {
  if (const auto env = gymnasium_or_skip(state, name)) Overhead(state, *env);
}
void BM_MujocoOverhead_GymSwimmer(benchmark::State& state) { GymOverhead(state, "swimmer"); }
void BM_MujocoOverhead_GymHopper(benchmark::State& state) { GymOverhead(state, "hopper"); }
BENCHMARK(BM_MujocoOverhead_GymSwimmer)->Unit(benchmark::kMillisecond)->MinTime(2.0);
BENCHMARK(BM_MujocoOverhead_GymHopper)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// U-hat of a batch of 8 thetas on 16 scenarios (128 rollouts) on `threads` threads, wall time: the
// speed-up of 2 threads over 1 is the ratio of the two rates (meaningful only on idle cores).
void UhatBatch(benchmark::State& state, const std::shared_ptr<const MujocoEnvironment>& env) {
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
void BM_MujocoUhatBatch_Cartpole_8x16(benchmark::State& state) { UhatBatch(state, cartpole()); }
void BM_MujocoUhatBatch_Arm26_8x16(benchmark::State& state) { UhatBatch(state, arm26()); }
BENCHMARK(BM_MujocoUhatBatch_Cartpole_8x16)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MujocoUhatBatch_Arm26_8x16)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
void GymUhatBatch(benchmark::State& state, const std::string& name) {
  if (const auto env = gymnasium_or_skip(state, name)) UhatBatch(state, env);
}
void BM_MujocoUhatBatch_GymSwimmer_8x16(benchmark::State& state) { GymUhatBatch(state, "swimmer"); }
void BM_MujocoUhatBatch_GymHopper_8x16(benchmark::State& state) { GymUhatBatch(state, "hopper"); }
BENCHMARK(BM_MujocoUhatBatch_GymSwimmer_8x16)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_MujocoUhatBatch_GymHopper_8x16)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
#endif
