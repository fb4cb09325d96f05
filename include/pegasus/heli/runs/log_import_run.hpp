#pragma once
// `log import` as a library function: a PX4 ULog flight as the project's CSV flight log
// (logs/ulog_import.hpp) with its provenance; then, on the first part of it, the identification of thesis
// §5.2 and the hold-out prediction error of the identified model, the global linear model and a
// constant-velocity baseline at 0.5, 1 and 2 s (Fig 5.2's measure). Writes log.csv, provenance.json,
// model.json, mse_vs_horizon.csv, charts and summary.json; bad input (the file, the vehicle's topics, a
// hold-out part too short) throws InputError.
#include <string>

#include "pegasus/logs/ulog.hpp"
#include "pegasus/logs/ulog_import.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/runs/run_sink.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus {

struct LogImportRunOptions {
  std::string ulog_file;     // .ulg
  std::string vehicle_file;  // its [log] section names the topics
  logs::ImportOptions window{};
  logs::UlogReadOptions::TruncatedTail truncated_tail = logs::UlogReadOptions::TruncatedTail::kDiscard;
  bool identify = true;          // identify on the first part and report hold-out prediction errors
  double train_fraction = 0.7;   // the first part of the log used for identification
  double start_spacing_s = 0.5;  // spacing of the open-loop prediction starts on the hold-out part, s
  // The identification (its rate and latent states come from the vehicle); a short flight's window.
  sysid::IdentifyOptions identification = [] {
    sysid::IdentifyOptions o;
    o.window_s = 8;
    return o;
  }();
};

void run_log_import(const LogImportRunOptions& options, RunSink& sink, ThreadPool& pool);

// Its config section (the `log import` command's fields; bandwidth floors as heli/runs/heli_config.hpp's).
void declare_log_import_config(ConfigSchema& s);
LogImportRunOptions read_log_import_config(const ConfigSchema& c);

}  // namespace pegasus
