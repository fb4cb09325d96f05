#pragma once
// Where an experiment's results go: its run directory (files, charts, checkpoint), the lines it prints,
// its progress bars and its wall-clock figures. A command builds one from what the user asked for
// (include/pegasus/cli/command.hpp: RunContext::sink); a library user builds one around any RunDirectory.
//
//   RunDirectory dir = RunDirectory::open("runs/hover", config);
//   nlohmann::json timings = nlohmann::json::object();
//   RunSink sink{.dir = dir, .out = std::cout, .timings = timings};
//   heli::run_hover(options, sink, pool);
//   dir.commit();
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "pegasus/runs/config.hpp"
#include "pegasus/runs/progress.hpp"
#include "pegasus/runs/run_directory.hpp"

namespace pegasus {

struct RunSink {
  RunDirectory& dir;        // files, charts and the checkpoint
  std::ostream& out;        // the printed result, line by line
  nlohmann::json& timings;  // wall-clock figures (run.json), never in summary.json
  bool quiet = false;       // no progress bars
  // The folder the options' relative input files were found from (ConfigSchema::get_path), and the run
  // directory's own (a pipeline's run directory, whose stages name each other's files relative to it).
  // Empty: the working directory.
  std::filesystem::path input_base{};

  // A file of the options or of the run directory as the config names it, relative to input_base when under
  // it: what a summary records and a printed line shows.
  std::string named(const std::filesystem::path& file) const {
    return path_named_from(input_base, file.string());
  }

  // A progress bar on stderr (plain lines every 10 s where it is no terminal), unless quiet, on the first of
  // the directory's ranks.
  Progress progress(std::string label, std::uint64_t total) const {
    return Progress(std::move(label), total, Progress::default_enabled(quiet, dir.ranks()));
  }
};

}  // namespace pegasus
