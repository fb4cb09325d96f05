#pragma once
// The directory a run writes its results to (`--out DIR`). Everything is written into a staging directory
// `DIR.partial` next to DIR, and commit() renames it to DIR, so DIR either does not exist or is complete.
//
//   open(DIR):  DIR exists          -> InputError unless options.force (then DIR is replaced at commit)
//               DIR.partial exists  -> InputError unless options.resume (continue it: its config.toml must
//                                      equal `config` on every field that affects results, else InputError
//                                      naming the key; its inputs.json must give the input files' present
//                                      SHA-256, and a run with input files but no inputs.json is refused)
//                                      or options.force (discard it, start over). A DIR.partial holding
//                                      nothing but inputs.json (killed while starting) is started over.
//               otherwise           -> a fresh DIR.partial (also with --resume: nothing to resume)
// open() first takes an advisory lock (flock) on DIR.lock, held until the RunDirectory is destroyed: a second
// run on the same DIR (plain, --force or --resume, in any mix) gets an InputError naming the holder's pid and
// touches nothing. open() writes the input files' digests (inputs.json), then the resolved config
// (config.toml, the mark of a run that can be resumed). It creates nothing when it throws. If
// the process dies later, DIR.partial stays behind for --resume. Every write is atomic (atomic_file.hpp).
//
//   RunDirectory run = RunDirectory::open(out, schema, {.force = f, .resume = r});
//   if (auto state = run.load_checkpoint()) next = (*state)["next"];
//   ...; run.save_checkpoint({{"next", i}, {"partial_sums", sums}});
//   run.write_json("summary.json", summary);
//   run.commit();
//
// Under mpirun (parallel/mpi.hpp) a directory belongs to the ranks it is opened among (options.ranks: the
// job's by default, or this process alone for a run that only this rank makes), and only the first of them
// touches DIR: open() runs there and its outcome (or its error) is broadcast, so every rank succeeds or
// throws alike; on the other ranks the object is a shadow whose writes, checkpoints, commit() and abandon()
// do nothing, whose load_checkpoint() returns the first rank's checkpoint (a collective: every rank calls it
// at the same point), and whose path() is a private scratch folder, removed at the end, for code that writes
// files there directly.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string_view>
#include <vector>

#include "pegasus/io/json_csv.hpp"
#include "pegasus/parallel/execution_context.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/config.hpp"

namespace pegasus {

struct RunDirectoryOptions {
  bool force = false;   // replace an existing DIR; discard an existing DIR.partial unless resume
  bool resume = false;  // continue an existing DIR.partial
  // The ranks that share the run: the first writes DIR, the others are shadows. this_process(): every rank
  // that opens one writes its own DIR (a per-rank run; never the same DIR on two ranks).
  mpi::Communicator ranks = mpi::Communicator::job();
};

class RunDirectory {
 public:
  static RunDirectory open(const std::filesystem::path& dir, const ConfigSchema& config,
                           RunDirectoryOptions options = {});

  RunDirectory(RunDirectory&&) noexcept = default;
  RunDirectory& operator=(RunDirectory&&) noexcept = default;

  // The staging directory DIR.partial, where everything is written until commit().
  const std::filesystem::path& path() const { return staging_; }
  // DIR, where the results are after commit().
  const std::filesystem::path& final_path() const { return final_; }
  // True when this run continues an interrupted one (an existing DIR.partial was reopened).
  bool resumed() const { return resumed_; }
  bool committed() const { return committed_; }
  // The ranks the directory was opened among (RunDirectoryOptions::ranks); progress bars draw on the first.
  const mpi::Communicator& ranks() const { return ranks_; }
  // True when DIR.partial holds what --resume needs (its config.toml): what a failure may point the user to.
  bool resumable() const;

  // Atomic writes to a path relative to the run directory (sub-folders are created).
  void write_text(const std::filesystem::path& relative, std::string_view content) const;
  void write_json(const std::filesystem::path& relative, const nlohmann::json& value) const;
  void write_csv(const std::filesystem::path& relative, const CsvWriter& csv) const;
  // Adds chart sections to charts.json (charts.hpp), replacing a section of the same id; rewritten
  // atomically each time, so the run directory describes its charts at every moment.
  void add_charts(const std::vector<ChartSection>& sections) const;
  void add_charts(const ChartSection& section) const { add_charts(std::vector<ChartSection>{section}); }
  // An SVG of an xy chart drawn from the series already written (render_svg).
  void write_chart_svg(const std::filesystem::path& relative, const Chart& chart) const;

  // checkpoint.json, written atomically; load_checkpoint() is nullopt when no checkpoint was saved. Under
  // mpirun every rank gets rank 0's checkpoint.
  void save_checkpoint(const nlohmann::json& state) const;
  std::optional<nlohmann::json> load_checkpoint() const;

  // Renames DIR.partial to DIR (replacing an old DIR when opened with force). Throws std::runtime_error if
  // DIR appeared meanwhile and force was not given.
  void commit();
  // Removes DIR.partial if this process created it (bad input found after open); a resumed one is kept.
  // Either way the run is over and DIR's lock is released.
  void abandon();

 private:
  RunDirectory() = default;
  static RunDirectory open_here(const std::filesystem::path& dir, const ConfigSchema& config,
                                RunDirectoryOptions options);
  class Lock;
  std::filesystem::path resolve(const std::filesystem::path& relative) const;
  std::optional<nlohmann::json> load_checkpoint_here() const;

  std::filesystem::path final_, staging_;
  bool force_ = false, resumed_ = false, created_ = false, committed_ = false;
  mpi::Communicator ranks_ = mpi::Communicator::job();
  bool shadow_ = false;                                   // not the first of ranks_: writes nothing
  std::shared_ptr<const std::filesystem::path> scratch_;  // a shadow's staging_, removed with the last copy
  std::shared_ptr<const Lock> lock_;                      // DIR.lock, the first rank's for the whole run
};

}  // namespace pegasus
