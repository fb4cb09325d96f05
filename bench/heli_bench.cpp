// The helicopter (thesis ch. 5): the ground truth and the hover task on the identified model.
//   BM_HeliAircraftStep            Aircraft::step under trim controls with counter-based noise
//   BM_HeliPilotFlight_60s         fly_pilot: 60 s of hover and sweeps (3000 steps), per flight
//   BM_HeliHoverUhat/threads       U-hat of the starting hover policy on the learned model at the thesis's
//                                  settings (§5.3: 30 scenarios x 35 s at 50 Hz, a refit every 5 steps) on 1
//                                  or 2 threads; the model is identified from the shipped 339 s pilot log
//   BM_HeliHoverUhat25Hz/refit   issue 53: U-hat of the starting policy with a 25 Hz model and a 25 Hz
//                                  controller identified from 10 minutes of logs (600 s, 15,000 rows at 25
//                                  Hz), 30 scenarios x 35 s (26,250 steps), a refit every 1 (the old default
//                                  at the model's rate), 2, 3 (the default: every 0.1 s) or 5 steps, 1
//                                  thread: us_per_step and the evaluation's time
//   BM_HeliHoverPolicyAct          one action of the hover policy (body-frame errors, four channel networks)
//   BM_HeliControlLoop             heli control's loop: 10,000 state lines parsed, answered and flushed
//                                  (to /dev/null) per iteration; lines_per_s is per CPU second of the
//                                  thread (load does not count), the figure to hold against 100,000
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus {
namespace {

void BM_HeliAircraftStep(benchmark::State& state) {
  const heli::Aircraft heli;
  std::array<double, heli::Aircraft::kInitialNoise> p0;
  p0.fill(0.5);
  auto s = heli.initial_state(p0);
  UniformStream rng(1, 0);
  std::array<double, heli::Aircraft::kStepNoise> p;
  std::int64_t steps = 0;
  for (auto _ : state) {
    for (double& u : p) u = rng.next();
    s = heli.step(s, heli.hover_trim().controls, p);
    if (heli.terminal(s)) s = heli.initial_state(p0);
    benchmark::DoNotOptimize(s);
    ++steps;
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HeliAircraftStep);

void BM_HeliPilotFlight_60s(benchmark::State& state) {
  const heli::Aircraft heli;
  std::uint64_t seed = 0;
  for (auto _ : state) benchmark::DoNotOptimize(heli::fly_pilot(heli, heli::PilotOptions{}, 60.0, ++seed));
}
BENCHMARK(BM_HeliPilotFlight_60s)->Unit(benchmark::kMillisecond);

std::shared_ptr<const sysid::IdentifiedModel> shipped_model() {
  static const auto model = [] {
    const heli::Aircraft heli;
    const auto log = heli::fly_pilot(heli, heli::PilotOptions{}, 339, 1).log;
    ThreadPool pool(2);
    return std::make_shared<const sysid::IdentifiedModel>(
        sysid::identify(log, sysid::IdentifyOptions{}, pool));
  }();
  return model;
}

void BM_HeliHoverUhat(benchmark::State& state) {
  const auto model = shipped_model();
  const heli::HoverTrainingOptions options;  // 30 scenarios x 35 s, gamma 0.9995, refit every 5 steps
  auto pool = std::make_shared<ThreadPool>(static_cast<int>(state.range(0)));
  auto objective = heli::hover_objective(model, options, pool);
  const Theta theta = objective->parameters().initial();
  double uhat = 0;
  for (auto _ : state) benchmark::DoNotOptimize(uhat = objective->evaluate(theta));
  state.counters["uhat"] = uhat;
  state.counters["steps"] = static_cast<double>(options.scenarios * options.horizon());
}
BENCHMARK(BM_HeliHoverUhat)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

std::shared_ptr<const sysid::IdentifiedModel> ten_minutes_at_25_hz() {
  static const auto model = [] {
    const heli::Aircraft heli;
    const auto log = heli::fly_pilot(heli, heli::PilotOptions{}, 600, 3).log;
    sysid::IdentifyOptions o;
    o.structure.rate_hz = 25;
    ThreadPool pool(2);
    return std::make_shared<const sysid::IdentifiedModel>(sysid::identify(log, o, pool));
  }();
  return model;
}

void BM_HeliHoverUhat25Hz(benchmark::State& state) {
  const auto model = ten_minutes_at_25_hz();
  heli::HoverTrainingOptions options;
  options.control_rate_hz = 25;
  options.refit_every = static_cast<int>(state.range(0));
  auto objective = heli::hover_objective(model, options, std::make_shared<ThreadPool>(1));
  const Theta theta = objective->parameters().initial();
  double uhat = 0;
  for (auto _ : state) benchmark::DoNotOptimize(uhat = objective->evaluate(theta));
  const double steps = static_cast<double>(options.scenarios * options.horizon());
  state.counters["uhat"] = uhat;
  state.counters["steps"] = steps;
  state.counters["us_per_step"] = benchmark::Counter(
      steps * 1e-6, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
  state.counters["rows"] = static_cast<double>(model->data().x.rows());
}
BENCHMARK(BM_HeliHoverUhat25Hz)->Arg(1)->Arg(2)->Arg(3)->Arg(5)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_HeliHoverPolicyAct(benchmark::State& state) {
  const heli::HoverPolicy pi;
  const Theta theta = pi.parameters().initial();
  heli::HeliObservation o;
  o.state = {0.3, -0.2, -10.1, 0.02, -0.01, 0.1, 0.1, 0.2, -0.1, 0.01, 0.02, 0.03};
  for (auto _ : state) {
    o.state[0] += 1e-9;
    benchmark::DoNotOptimize(pi.act(theta, o));
  }
}
BENCHMARK(BM_HeliHoverPolicyAct);

void BM_HeliControlLoop(benchmark::State& state) {
  const heli::HoverPolicy pi;
  const auto controller = heli::make_controller(
      heli::hover_policy_file(pi, pi.parameters().initial(), {}, {0, 0.04, 0.18, 0.19}), "bench");
  std::string input;
  constexpr int kLines = 10000;
  for (int i = 0; i < kLines; ++i) {
    const double t = 0.02 * i;
    input += fmt::format("{},{},{},0.05,-0.01,{},0.1,-0.1,0.02,0.01,0,0.01\n", 0.3 * std::sin(t),
                         -0.2 * std::cos(t), -10 + 0.1 * std::sin(0.5 * t), 0.02 * std::sin(t));
  }
  std::FILE* out = std::fopen("/dev/null", "w");
  std::int64_t lines = 0;
  for (auto _ : state) {
    std::FILE* in = fmemopen(input.data(), input.size(), "r");
    lines += heli::run_control_loop(*controller, {0, 0.04, 0.18, 0.19}, in, out, stderr).lines;
    std::fclose(in);
  }
  std::fclose(out);
  state.counters["lines_per_s"] = benchmark::Counter(static_cast<double>(lines), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_HeliControlLoop)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pegasus
