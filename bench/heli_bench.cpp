// The ground-truth helicopter (thesis ch. 5): one 50 Hz step (2 RK4 substeps, rotor inflow by Newton) and a
// pilot flight.
//   BM_HeliAircraftStep            Aircraft::step under trim controls with counter-based noise
//   BM_HeliPilotFlight_60s         fly_pilot: 60 s of hover and sweeps (3000 steps), per flight
#include <benchmark/benchmark.h>

#include <array>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"

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

}  // namespace
}  // namespace pegasus
