// Controllers out (codegen/c_policy.hpp): the exported hover controller per call, compiled as the tests
// compile it (gcc kCFlags -fPIC -shared: C99, -O3, -ffp-contract=off, no -march, so x86-64 baseline SSE2
// code; libm's functions pick their own variants at load time) and called through dlopen's function pointer.
//   BM_ExportedHoverAct   one hover_act call (13 observation values -> 4 controls), states cycling over 1024
//                         drawn ones (the 3-D rotation, four tanh networks and their clip)
//   BM_CppHoverAct        the same states through the C++ controller (HeliController::act), side by side
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <array>
#include <filesystem>
#include <random>
#include <vector>

#include "pegasus/codegen/c_loader.hpp"
#include "pegasus/codegen/c_policy.hpp"
#include "pegasus/heli/policy_file.hpp"

namespace pegasus {
namespace {

struct HoverSetup {
  heli::PolicyFile file;
  std::vector<std::array<double, 13>> observations;
  HoverSetup() {
    const heli::HoverPolicyInit init{.trim = {0.0, 0.036, 0.184, 0.194}};
    const heli::HoverPolicy policy(init);
    std::mt19937_64 rng(1);
    std::normal_distribution<double> normal;
    Theta theta = policy.parameters().initial();
    for (std::size_t i = 0; i < theta.size(); ++i)
      theta[i] = std::clamp(theta[i] + 0.5 * policy.parameters()[i].scale * normal(rng),
                            policy.parameters()[i].lower, policy.parameters()[i].upper);
    file = heli::hover_policy_file(policy, theta, {0, 0, -10, 0}, init.trim);
    std::uniform_real_distribution<double> u(-1, 1);
    observations.resize(1024);
    for (auto& o : observations) {
      o = {0.02,   2 * u(rng), 2 * u(rng), -10 + 2 * u(rng), 0.1 * u(rng), 0.1 * u(rng), 0.5 * u(rng),
           u(rng), u(rng),     u(rng),     0.3 * u(rng),     0.3 * u(rng), 0.3 * u(rng)};
    }
  }
};

void BM_ExportedHoverAct(benchmark::State& state) {
  const HoverSetup setup;
  const auto dir =
      std::filesystem::temp_directory_path() / ("pegasus-export-bench-" + std::to_string(::getpid()));
  {
    const codegen::LoadedCPolicy c(codegen::export_c_policy(heli::policy_file_json(setup.file), "bench.json"),
                                   dir);
    const auto act = c.act();
    std::array<double, 4> a{};
    std::size_t i = 0;
    for (auto _ : state) {
      act(setup.observations[i].data(), a.data());
      benchmark::DoNotOptimize(a);
      i = (i + 1) & 1023;
    }
    state.SetLabel("gcc -std=c99 -O3 -ffp-contract=off, no -march: x86-64 baseline (SSE2)");
  }
  std::filesystem::remove_all(dir);
}
BENCHMARK(BM_ExportedHoverAct);

void BM_CppHoverAct(benchmark::State& state) {
  const HoverSetup setup;
  const auto controller = heli::make_controller(setup.file, "bench.json");
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& o = setup.observations[i];
    heli::LoggedState s;
    std::copy(o.begin() + 1, o.end(), s.begin());
    benchmark::DoNotOptimize(controller->act(s, o[0]));
    i = (i + 1) & 1023;
  }
}
BENCHMARK(BM_CppHoverAct);

}  // namespace
}  // namespace pegasus
