#pragma once
// The `pegasus` command framework: every experiment is a Command in the table (commands.cpp) with a
// schema of config fields and a run function. The framework turns each field into a `--kebab-case` option,
// adds the common options, loads `--config FILE.toml`, applies command-line overrides, validates everything,
// opens the run directory (`--out DIR`, `--force`, `--resume`), calls `run`, then commits the directory.
//
//   Command{.path = "shaping audit",
//           .description = "Check that potential-based shaping keeps the optimal policy",
//           .declare = [](ConfigSchema& s) { s.add_double("gamma", 0.99, "discount").range(0, 1); },
//           .run = [](RunContext& ctx) {
//             const double gamma = ctx.config.get_double("gamma");
//             auto bar = ctx.progress("mdps", 100);
//             ...; bar.advance();
//             ctx.run_directory().write_json("summary.json", {{"violations", 0}});
//           }};
//
// Exit codes (the same for every command; README "Exit codes"): 0 success; 2 bad input (InputError, a
// command-line parse error, or a DIR locked by another run), one line on stderr, and no run directory left
// behind; 3 the environment refused (EnvironmentError, a file-system error, no memory, no thread: a full
// disk, a missing permission), one line; 1 any other failure, one line. After 1 or 3 in the middle of a run,
// DIR.partial is kept for --resume. A command that finishes normally may return a verdict through
// RunContext::exit_code.
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <nlohmann/json.hpp>
#include <ostream>
#include <streambuf>
#include <string>
#include <vector>

#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/runs/progress.hpp"
#include "pegasus/runs/run_directory.hpp"
#include "pegasus/runs/run_sink.hpp"
#include "pegasus/version.hpp"

namespace pegasus::cli {

inline constexpr int kExitFailure = 1;      // anything else: a bug, or a failure nothing else names
inline constexpr int kExitBadInput = 2;     // the user's input (options, config, files) is wrong
inline constexpr int kExitEnvironment = 3;  // the machine refused (disk full, permission, memory, threads)

// Whether a command writes a run directory.
enum class OutDir {
  kRequired,  // experiments: --out DIR is required
  kOptional,  // small tools: results go to stdout, and to DIR with --out
  kNone,      // no --out, --force, --resume
};

// What a command's run function gets.
class RunContext {
 public:
  RunContext(const ConfigSchema& config, bool quiet, RunDirectory* run_dir, std::ostream& out,
             std::ostream& err);

  const ConfigSchema& config;  // every field resolved and validated, with `seed` and `threads`
  const std::uint64_t seed;    // --seed: the root of all randomness of the run
  const int threads;           // --threads: never changes a result
  const bool quiet;            // --quiet: no progress bar
  std::ostream& out;           // stdout, for the command's printed result
  std::ostream& err;           // stderr, for the notes of the commands it runs (run_stage)
  // The process exit code when run returns normally: a verdict, not an error (e.g. 1 from `shaping audit`
  // when F is not potential-based). The run directory is still committed. Use 0 or 1; 2 means bad input.
  int exit_code = 0;
  // Wall-clock figures of the run (seconds of a phase, time to a bar): written to run.json under "timings",
  // never to summary.json, which stays a function of the inputs alone (two identical runs, identical bytes).
  nlohmann::json timings = nlohmann::json::object();

  bool has_run_directory() const { return run_dir_ != nullptr; }
  // The run directory; std::logic_error without --out (only for OutDir::kOptional commands).
  RunDirectory& run_directory() const;
  // A progress bar on stderr without --quiet (plain lines every 10 s where stderr is no terminal).
  Progress progress(std::string label, std::uint64_t total) const;
  // A pool of `threads` threads, made on first use.
  ThreadPool& pool();
  // Where a library experiment writes (runs/run_sink.hpp): the run directory, out, timings and quiet.
  RunSink sink() {
    return RunSink{.dir = run_directory(),
                   .out = out,
                   .timings = timings,
                   .quiet = quiet,
                   .input_base = config.base_directory()};
  }

 private:
  RunDirectory* run_dir_;
  std::unique_ptr<ThreadPool> pool_;
};

struct Command {
  std::string path{};                            // "horizon" or nested: "shaping audit"
  std::string description{};                     // one line, shown by --help
  std::function<void(ConfigSchema&)> declare{};  // declares the command's config fields
  std::function<void(RunContext&)> run{};        // does the work; throws on failure
  // Fills fields the user left at their defaults from an input another field names (a vehicle file), after
  // the config file and the command line and before validation, so the resolved config says what was used.
  std::function<void(ConfigSchema&)> resolve{};
  OutDir out = OutDir::kRequired;
  bool hidden = false;  // not listed by --help (framework self-tests)
  // Fields that may also be given as positional arguments, in this order (`pegasus report RUN_DIR`).
  std::vector<std::string> positionals{};
};

// A word of a nested command path that is not itself a command ("shaping" in "shaping audit").
struct CommandGroup {
  std::string path{};
  std::string description{};
  bool hidden = false;
};

// The tables of all commands (commands.cpp).
std::vector<CommandGroup> command_groups();
std::vector<Command> commands();

// A fresh schema of `command`: its fields and the common ones (seed, threads), at their defaults.
ConfigSchema command_schema(const Command& command);

// The command line that gives `config` (every field not at its default; a value as its option takes it),
// with `--out OUT` when OUT is not empty: what run.json records and a composed command prints.
std::vector<std::string> command_line_of(const Command& command, const ConfigSchema& config,
                                         const std::string& out = {});

struct StageOptions {
  bool quiet = false;  // no progress bar
  bool force = false;  // replace an existing OUT_DIR, discard an interrupted OUT_DIR.partial (--force)
  bool resume = true;  // continue an interrupted OUT_DIR.partial (--resume)
};

// Runs `command` in this process with `config` (a command_schema whose fields the caller set with their
// types) into the run directory `out_dir`, exactly as `pegasus PATH ... --out OUT_DIR --resume` would (the
// options say --force and --resume), and returns the command's exit code (a verdict, 0 or 1): the
// command's resolve step, validation, the run, run.json, the report and the commit. A relative OUT_DIR, and
// the relative files the fields name, are found from the config's base directory (set_base_directory; empty:
// the working directory, which is never changed). For commands made of others (heli pipeline). Throws what
// the command throws: InputError leaves no directory behind, any other failure keeps OUT_DIR.partial for a
// rerun to continue.
int run_stage(const Command& command, ConfigSchema config, const std::string& out_dir,
              const StageOptions& options, std::ostream& out, std::ostream& err);

// A stream that drops what is written to it: where the printed results go of MPI ranks other than 0 (main)
// and of a quiet pegasus.pipeline (run.json keeps them).
class NullStream final : public std::ostream {
 public:
  NullStream() : std::ostream(&buffer_) {}

 private:
  class Buffer final : public std::streambuf {
   protected:
    int overflow(int c) override { return c == traits_type::eof() ? 0 : c; }
  };
  Buffer buffer_;
};

// How call_command opens the run directory and prints.
struct CallOptions {
  bool force = false;   // --force
  bool resume = false;  // --resume
  bool quiet = true;    // --quiet
};

// Runs the command of the table (commands()) at `path` ("heli pipeline") in this process into the run
// directory `out_dir`, as `pegasus PATH --FIELD VALUE ... --out OUT_DIR` would, from a program: no command
// line is parsed, and the process's working directory is neither changed nor used beyond a relative OUT_DIR
// (and relative files the settings name). `settings`: field name (the TOML key, "train_seconds",
// "optimizer.gradient.max_iterations", "seed", "threads") -> value, checked as a config file's (an integer
// is taken for a number); the other fields keep their defaults. Returns the command's exit code (a verdict,
// 0 or 1). Bad input (an unknown command or setting, a value of the wrong type or out of range) is an
// InputError of one line naming it ("heli pipeline: setting 'flights': ..."), and leaves no directory behind;
// any other failure keeps OUT_DIR.partial for options.resume to continue. `out` gets what the command prints.
int call_command(const std::string& path, const std::vector<std::pair<std::string, FieldValue>>& settings,
                 const std::string& out_dir, const CallOptions& options, std::ostream& out,
                 std::ostream& err);

// Parses argv, runs the chosen command and returns the process exit code. `err` gets the one-line errors.
int run_cli(int argc, const char* const* argv, const std::vector<CommandGroup>& groups,
            const std::vector<Command>& commands, std::ostream& out, std::ostream& err);

}  // namespace pegasus::cli
