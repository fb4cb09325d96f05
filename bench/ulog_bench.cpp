// PX4 ULog import of the 4 MB sample flight (../shared/data/px4/sample.ulg: 68 s, 64,542 data messages of 43
// topics; the target is under 0.2 s):
//   BM_UlogRead_AllTopics     read and parse the file, every topic's records stored
//   BM_UlogRead_ImportTopics  the same storing only the three topics the quadrotor's vehicle file uses
//   BM_UlogImport             what `pegasus log import` does before identification: read those topics,
//                             resample them to the 50 Hz flight log (3,442 rows) and hash the file (SHA-256)
// Skipped with a message when the sample is absent.
#include <benchmark/benchmark.h>

#include <filesystem>

#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/sha256.hpp"
#include "pegasus/logs/ulog.hpp"
#include "pegasus/logs/ulog_import.hpp"

namespace pegasus {
namespace {

const std::filesystem::path kSample =
    std::filesystem::path(PEGASUS_SOURCE_DIR) / ".." / "shared" / "data" / "px4" / "sample.ulg";
const std::filesystem::path kVehicle =
    std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "vehicles" / "px4-quadrotor.toml";

bool have_sample(benchmark::State& state) {
  if (std::filesystem::exists(kSample)) return true;
  state.SkipWithError(("the sample is absent: " + kSample.string()).c_str());
  return false;
}

void BM_UlogRead_AllTopics(benchmark::State& state) {
  if (!have_sample(state)) return;
  for (auto _ : state) {
    const logs::UlogFile f = logs::read_ulog(kSample);
    benchmark::DoNotOptimize(f.data_messages);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) *
                          static_cast<std::int64_t>(std::filesystem::file_size(kSample)));
}
BENCHMARK(BM_UlogRead_AllTopics)->Unit(benchmark::kMillisecond);

void BM_UlogRead_ImportTopics(benchmark::State& state) {
  if (!have_sample(state)) return;
  const logs::VehicleLogSpec spec = logs::read_vehicle_log_spec(kVehicle);
  for (auto _ : state) {
    const logs::UlogFile f = logs::read_ulog(kSample, {.topics = spec.topic_names()});
    benchmark::DoNotOptimize(f.data_messages);
  }
}
BENCHMARK(BM_UlogRead_ImportTopics)->Unit(benchmark::kMillisecond);

void BM_UlogImport(benchmark::State& state) {
  if (!have_sample(state)) return;
  const logs::VehicleLogSpec spec = logs::read_vehicle_log_spec(kVehicle);
  for (auto _ : state) {
    const logs::UlogFile f = logs::read_ulog(kSample, {.topics = spec.topic_names()});
    const sysid::FlightLog log = logs::import_ulog(f, spec, kSample.string());
    const std::string sha = file_sha256(kSample);
    benchmark::DoNotOptimize(log.rows());
    benchmark::DoNotOptimize(sha.data());
  }
}
BENCHMARK(BM_UlogImport)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace pegasus
