#pragma once
// Where an experiment's results go: its run directory (files, charts, checkpoint), the lines it prints,
// its progress bars and its wall-clock figures. A command builds one from what the user asked for
// (apps/pegasus/command.hpp: RunContext::sink); a library user builds one around any RunDirectory.
//
//   RunDirectory dir = RunDirectory::open("runs/hover", config);
//   nlohmann::json timings = nlohmann::json::object();
//   RunSink sink{.dir = dir, .out = std::cout, .timings = timings};
//   heli::run_hover(options, sink, pool);
//   dir.commit();
#include <cstdint>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "pegasus/runs/progress.hpp"
#include "pegasus/runs/run_directory.hpp"

namespace pegasus {

struct RunSink {
  RunDirectory& dir;        // files, charts and the checkpoint
  std::ostream& out;        // the printed result, line by line
  nlohmann::json& timings;  // wall-clock figures (run.json), never in summary.json
  bool quiet = false;       // no progress bars

  // A progress bar on stderr (plain lines every 10 s where it is no terminal), unless quiet, on the first of
  // the directory's ranks.
  Progress progress(std::string label, std::uint64_t total) const {
    return Progress(std::move(label), total, Progress::default_enabled(quiet, dir.ranks()));
  }
};

}  // namespace pegasus
