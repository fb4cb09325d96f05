#pragma once
// The noise check of `pegasus identify` (identify_run.cpp), apart: the model's +-2 sd bands on the hold-out
// logs (Fig 5.3), the line that says whether they are honest, and the files and summary figures.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/runs/run_directory.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus::heli {

// The noise check on the hold-out logs: each log's, the pooled one, its summary cells and its verdict.
struct HoldOutNoiseCheck {
  std::vector<sysid::NoiseCheck> checks;  // the test log's first
  sysid::NoiseCheck pooled;               // one flight's: its own check
  std::vector<sysid::BandMisses> reported;
  std::string verdict;  // the line the terminal and the report give
};

// The check on the test log (with its series) and on each further hold-out log, pooled.
HoldOutNoiseCheck hold_out_noise_check(const sysid::IdentifiedModel& model, const sysid::FlightLog& test,
                                       const std::vector<sysid::FlightLog>& more_tests,
                                       const IdentifyRunOptions& options, const sysid::IdentifyOptions& o,
                                       ThreadPool& pool);
// noise_check.csv, noise_check_by_horizon.csv, their chart section and svgs.
void write_noise_check(RunDirectory& dir, const HoldOutNoiseCheck& noise, const sysid::IdentifiedModel& model,
                       double rate_hz);
// The cells as summary.json gives them: {seconds: {variable: fraction outside}}.
nlohmann::json outside_by_horizon_json(const std::vector<sysid::BandMisses>& cells);
// summary.json's noise_check_by_log (each log named as the config names it: sink.named).
nlohmann::json noise_check_by_log_json(const HoldOutNoiseCheck& noise, const IdentifyRunOptions& options,
                                       const sysid::IdentifiedModel& model, double rate_hz,
                                       const RunSink& sink);

}  // namespace pegasus::heli
