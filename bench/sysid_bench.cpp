// System identification (thesis §5.2) on the shipped default workload: a 339 s pilot log downsampled to 10 Hz
// (3389 training rows, 16 inputs, 8 outputs), the bandwidth chosen by the default cross-validation.
//   BM_LwrRefit_Fast       one local-regression refit at a query, all outputs (lwr_kernel.hpp: shared X'WX,
//                          8 points per vector on the widest instruction set the CPU has; the label names it)
//   BM_LwrRefit_Fast_Avx2  the same forced onto AVX2+FMA (same bits; what callgrind can run)
//   BM_LwrRefit_Exact      the plain reference refit (every point, one system per output), same queries
//   BM_LwrRefit_{Fast,Exact}_Narrow   the same with every bandwidth divided by 8, where the k-d tree prunes
//   BM_BandwidthCrossValidation/threads   the whole default bandwidth search (identify) on 1 or 2 threads
//   BM_NoiseCheck/threads  Fig 5.3's noise check on the 140 s test flight, on 1 or 2 threads
//   BM_IdentifyTenMinutes/threads/calibrated   identification of a 600 s pilot log (30,000 rows at 50 Hz,
//                          identified at 10 Hz) with white noise, or calibrated ar1+measurement noise
//                          (issue 15's budget: 10 minutes of logs in under 10 s)
//   BM_ModelClassChoice/threads   the model class from the data (issue 48): the global regression of the
//                          600 s log and both classes flown over the test flight at 50 Hz
//                          (choose_model_class)
//   BM_LearnedModelStep    one 50 Hz step of the learned simulative model (a refit every 5 steps)
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <optional>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "pegasus/sysid/model_selection.hpp"

namespace pegasus {
namespace {

// Every kernel figure is reported with the instruction set it ran on: the JSON's context carries it.
const bool kInstructionSetInContext = [] {
  benchmark::AddCustomContext("instruction_set", instruction_set_name(best_instruction_set()));
  return true;
}();

struct Workload {
  sysid::FlightLog train, test;
  std::shared_ptr<const sysid::IdentifiedModel> model;
  sysid::Dataset queries;
};

const Workload& workload() {
  static const Workload w = [] {
    Workload x;
    const heli::Aircraft heli;
    x.train = heli::fly_pilot(heli, heli::PilotOptions{}, 339, 1).log;
    x.test = heli::fly_pilot(heli, heli::PilotOptions{}, 140, 2).log;
    ThreadPool pool(2);
    x.model = std::make_shared<const sysid::IdentifiedModel>(
        sysid::identify(x.train, sysid::IdentifyOptions{}, pool));
    x.queries = sysid::build_dataset(x.test, x.model->structure());
    return x;
  }();
  return w;
}

template <bool kFast>
void refit(benchmark::State& state, std::optional<InstructionSet> isa = std::nullopt) {
  const Workload& w = workload();
  sysid::force_lwr_instruction_set(isa);
  if (kFast) state.SetLabel(instruction_set_name(sysid::lwr_instruction_set()));
  Eigen::Index i = 0;
  double points = 0, fits = 0, rcond = INFINITY;
  for (auto _ : state) {
    const sysid::InputVec q = w.queries.x.row(i).transpose();
    const sysid::LocalFit fit = kFast ? w.model->regression().fit(q) : w.model->regression().fit_exact(q);
    benchmark::DoNotOptimize(fit);
    points += fit.points;
    fits += 1;
    rcond = std::min(rcond, fit.rcond);
    i = (i + 7) % w.queries.rows();
  }
  state.counters["training_rows"] = static_cast<double>(w.model->data().rows());
  state.counters["points_used"] = points / fits;
  state.counters["rcond_min"] = rcond;  // the 1e-9 agreement holds where rcond >= 1e-4 (lwr.hpp)
  sysid::force_lwr_instruction_set(std::nullopt);
}
void BM_LwrRefit_Fast(benchmark::State& state) { refit<true>(state); }
void BM_LwrRefit_Fast_Avx2(benchmark::State& state) { refit<true>(state, InstructionSet::kAvx2Fma); }
void BM_LwrRefit_Exact(benchmark::State& state) { refit<false>(state); }
BENCHMARK(BM_LwrRefit_Fast)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LwrRefit_Fast_Avx2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LwrRefit_Exact)->Unit(benchmark::kMicrosecond);

template <bool kFast>
void refit_narrow(benchmark::State& state) {
  const Workload& w = workload();
  auto inv = w.model->inv_bandwidth();
  for (double& v : inv) v *= 8;
  const sysid::LocalRegression lwr(&w.model->data(), sysid::output_templates(w.model->structure()), inv);
  Eigen::Index i = 0;
  double points = 0, fits = 0;
  for (auto _ : state) {
    const sysid::InputVec q = w.queries.x.row(i).transpose();
    const sysid::LocalFit fit = kFast ? lwr.fit(q) : lwr.fit_exact(q);
    benchmark::DoNotOptimize(fit);
    points += fit.points;
    fits += 1;
    i = (i + 7) % w.queries.rows();
  }
  state.counters["points_used"] = points / fits;
}
void BM_LwrRefit_Fast_Narrow(benchmark::State& state) { refit_narrow<true>(state); }
void BM_LwrRefit_Exact_Narrow(benchmark::State& state) { refit_narrow<false>(state); }
BENCHMARK(BM_LwrRefit_Fast_Narrow)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_LwrRefit_Exact_Narrow)->Unit(benchmark::kMicrosecond);

void BM_BandwidthCrossValidation(benchmark::State& state) {
  const Workload& w = workload();
  ThreadPool pool(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(sysid::identify(w.train, sysid::IdentifyOptions{}, pool));
}
BENCHMARK(BM_BandwidthCrossValidation)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->Iterations(1);

// Fig 5.3's noise check of the shipped model on the 140 s test flight, its 2 s windows filtered on 1 or 2
// threads.
void BM_NoiseCheck(benchmark::State& state) {
  const Workload& w = workload();
  ThreadPool pool(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(sysid::noise_check(*w.model, w.test, 2.0, 0.0, pool));
}
BENCHMARK(BM_NoiseCheck)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

const sysid::FlightLog& ten_minutes() {
  static const sysid::FlightLog log = heli::fly_pilot(heli::Aircraft{}, heli::PilotOptions{}, 600, 3).log;
  return log;
}

void BM_IdentifyTenMinutes(benchmark::State& state) {
  const sysid::FlightLog& log = ten_minutes();
  ThreadPool pool(static_cast<int>(state.range(0)));
  sysid::IdentifyOptions o;
  if (state.range(1) != 0) {
    o.noise = sysid::NoiseModel::kAr1Measurement;
    o.calibrate_noise = true;
  }
  for (auto _ : state) benchmark::DoNotOptimize(sysid::identify(log, o, pool));
  state.counters["rows"] = static_cast<double>(log.rows());
}
BENCHMARK(BM_IdentifyTenMinutes)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "calibrated"})
    ->Unit(benchmark::kSecond)
    ->Iterations(1);

// What `heli identify`'s model class from the data adds at the defaults (issue 48): the global linear
// regression beside the locally weighted one (identified once, outside the timing) on the 600 s log, and both
// flown over the 140 s test flight at 50 Hz as training runs them (choose_model_class).
void BM_ModelClassChoice(benchmark::State& state) {
  ThreadPool pool(static_cast<int>(state.range(0)));
  const sysid::IdentifyOptions o;
  static const sysid::IdentifiedModel local = [&] {
    ThreadPool two(2);
    return sysid::identify_mean(ten_minutes(), o, two);
  }();
  for (auto _ : state) {
    sysid::IdentifyOptions as_global = o;
    as_global.local = false;
    const sysid::IdentifiedModel global = sysid::identify_mean(ten_minutes(), as_global, pool);
    benchmark::DoNotOptimize(sysid::choose_model_class(
        {{"global linear", &global}, {"locally weighted", &local}}, workload().test, 50, 2, pool));
  }
}
BENCHMARK(BM_ModelClassChoice)->Arg(1)->Arg(2)->ArgName("threads")->Unit(benchmark::kSecond)->Iterations(1);

void BM_LearnedModelStep(benchmark::State& state) {
  const Workload& w = workload();
  sysid::LearnedModelOptions o;
  o.start = w.test.states[500];
  const sysid::LearnedHeliModel sim(w.model, o);
  std::array<double, 6> p0{0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
  std::array<double, 8> p{0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
  auto s = sim.initial_state(p0);
  std::size_t t = 500;
  for (auto _ : state) {
    s = sim.step(s, w.test.controls[t], p);
    if (sim.terminal(s) || ++t >= w.test.rows()) {
      t = 500;
      s = sim.initial_state(p0);
    }
    benchmark::DoNotOptimize(s);
  }
  state.counters["steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_LearnedModelStep)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace pegasus
