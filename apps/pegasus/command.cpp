#include "pegasus/cli/command.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <deque>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <system_error>
#include <thread>
#include <variant>
#include <vector>

#include "help_markdown.hpp"
#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/parallel/mpi.hpp"
#include "pegasus/parallel/thread_limits.hpp"
#include "pegasus/report/report.hpp"
#include "pegasus/report/summary_keys.hpp"

namespace pegasus::cli {

RunContext::RunContext(const ConfigSchema& cfg, bool q, RunDirectory* run_dir, std::ostream& o,
                       std::ostream& e)
    : config(cfg),
      seed(static_cast<std::uint64_t>(cfg.get_int("seed"))),
      threads(static_cast<int>(cfg.get_int("threads"))),
      quiet(q),
      out(o),
      err(e),
      run_dir_(run_dir) {}

RunDirectory& RunContext::run_directory() const {
  if (run_dir_ == nullptr) throw std::logic_error("this command was run without --out");
  return *run_dir_;
}

Progress RunContext::progress(std::string label, std::uint64_t total) const {
  return Progress(std::move(label), total,
                  Progress::default_enabled(quiet, run_dir_ ? run_dir_->ranks() : mpi::Communicator::job()));
}

ThreadPool& RunContext::pool() {
  if (!pool_) pool_ = std::make_unique<ThreadPool>(threads);
  return *pool_;
}

namespace {

// What a command prints as its result, passed on to stdout and kept (its first kMaxKept bytes) for run.json,
// whose "printed" lines open the run's report (issue 50: a report leads with the answer).
class KeptOutput : public std::streambuf {
 public:
  static constexpr std::size_t kMaxKept = 64 * 1024;
  explicit KeptOutput(std::streambuf* to) : to_(to) {}
  // The kept text's non-empty lines.
  std::vector<std::string> lines() const {
    std::vector<std::string> out;
    for (std::size_t start = 0; start < kept_.size();) {
      const std::size_t end = std::min(kept_.find('\n', start), kept_.size());
      if (end > start) out.push_back(kept_.substr(start, end - start));
      start = end + 1;
    }
    return out;
  }

 protected:
  int overflow(int c) override {
    if (c == traits_type::eof()) return traits_type::not_eof(c);
    const char ch = static_cast<char>(c);
    keep(&ch, 1);
    return to_->sputc(ch);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    keep(s, static_cast<std::size_t>(n));
    return to_->sputn(s, n);
  }
  int sync() override { return to_->pubsync(); }

 private:
  void keep(const char* s, std::size_t n) {
    if (kept_.size() < kMaxKept) kept_.append(s, std::min(n, kMaxKept - kept_.size()));
  }
  std::streambuf* to_;
  std::string kept_;
};

// Every message is one printable line, whatever bytes the paths and values it quotes hold.
std::string one_line(const std::string& s) { return one_line_message(s); }

// A run's error about one of its fields names it as the user set it, as the checks of its value do.
std::string naming_origin(const ConfigSchema& schema, const ConfigFieldError& e) {
  return schema.has(e.field()) ? schema.where(e.field()) + ": " + e.detail() : e.what();
}

// The options of one command, filled by CLI11 while parsing.
struct Leaf {
  const Command* command = nullptr;
  CLI::App* app = nullptr;
  ConfigSchema schema;
  std::vector<std::string> texts;  // one per schema field
  std::vector<CLI::Option*> options;
  std::string out, config_file;
  bool quiet = false, force = false, resume = false;
};

void add_common_fields(ConfigSchema& schema) {
  schema.add_int("seed", 1, "root of every random number of the run (scenarios, initial policies)").min(0);
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  schema.add_int("threads", std::min(hardware, kMaxThreads), "worker threads; results do not depend on it")
      .range(1, kMaxThreads)
      .affects_results(false);
}

std::string type_name(FieldType t) {
  switch (t) {
    case FieldType::kInt:
      return "INT";
    case FieldType::kDouble:
      return "NUMBER";
    case FieldType::kBool:
      return "BOOL";
    case FieldType::kString:
      return "TEXT";
    case FieldType::kIntList:
      return "INT,...";
    case FieldType::kDoubleList:
      return "NUMBER,...";
    case FieldType::kStringList:
      return "TEXT,...";
  }
  return "VALUE";
}

// --help shows a command's own settings and the common options, so that it fits a screen; --help-all adds
// the settings of its parts (dotted names: optimizer.gradient.*, reward.*), listed under this group.
constexpr const char* kAdvancedGroup = "Settings of the parts (tuning)";

bool is_advanced(const ConfigField& f) { return f.name().find('.') != std::string::npos; }

// Before --help prints: the parts' settings are left out, and a footer says how to see them.
void hide_advanced_options(std::deque<Leaf>& leaves) {
  for (Leaf& leaf : leaves) {
    std::size_t hidden = 0;
    for (CLI::Option* option : leaf.options)
      if (option->get_group() == kAdvancedGroup) {
        option->group("");
        ++hidden;
      }
    if (hidden > 0)
      leaf.app->footer(
          fmt::format("{} more settings of its parts (optimizer, reward, ...): pegasus {} "
                      "--help-all. Every option is also a TOML key of --config (docs/reference).",
                      hidden, leaf.command->path));
  }
}

void declare_options(Leaf& leaf) {
  CLI::App* app = leaf.app;
  const auto& fields = leaf.schema.fields();
  leaf.texts.resize(fields.size());
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const ConfigField& f = fields[i];
    // A flag takes its value after '=' only (`--ablations false` would read `false` as the next argument).
    const std::string expected = f.type() == FieldType::kBool
                                     ? fmt::format("{0} or {0}=false", ConfigSchema::option_name(f.name()))
                                     : f.expectation();
    const std::string help =
        fmt::format("{} [{}; default {}]", f.help(), expected, ConfigSchema::format_value(f.default_value()));
    CLI::Option* option = nullptr;
    if (f.type() == FieldType::kBool) {
      // `--flag` alone means true; `--flag=false` is accepted too.
      option = app->add_flag(ConfigSchema::option_name(f.name()), leaf.texts[i], help);
    } else {
      std::string names = ConfigSchema::option_name(f.name());
      const auto& positionals = leaf.command->positionals;
      if (std::find(positionals.begin(), positionals.end(), f.name()) != positionals.end()) {
        std::string upper = f.name();  // `run_dir` is the positional RUN_DIR and the option --run-dir
        std::transform(upper.begin(), upper.end(), upper.begin(),
                       [](unsigned char c) { return std::toupper(c); });
        names = upper + "," + names;
      }
      option = app->add_option(names, leaf.texts[i], help)->type_name(type_name(f.type()));
    }
    option->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
    // The settings of a part (optimizer.*, reward.*, ...) are for tuning: --help-all lists them.
    if (is_advanced(f)) option->group(kAdvancedGroup);
    leaf.options.push_back(option);
  }
  app->add_option("--config", leaf.config_file, "TOML file of settings; command-line options override it")
      ->type_name("FILE.toml");
  if (leaf.command->out != OutDir::kNone) {
    CLI::Option* out =
        app->add_option("--out", leaf.out, "run directory to create (written to DIR.partial first)")
            ->type_name("DIR");
    if (leaf.command->out == OutDir::kRequired) out->required();
    app->add_flag("--force", leaf.force, "replace an existing DIR, discard an interrupted DIR.partial");
    app->add_flag("--resume", leaf.resume, "continue the interrupted run in DIR.partial from its checkpoint");
  }
  app->add_flag("--quiet", leaf.quiet, "no progress bar");
}

// Under mpirun (parallel/mpi.hpp) every rank executes the command; rank 0 alone prints results and errors
// (the others get null streams from main) and writes the run directory. Failures in the set-up (config,
// run directory) are agreed on by all ranks, which then exit alike; a failure later, while ranks may be
// inside a collective, prints its line and ends the whole job (MPI_Abort), and rank 0 names the kept
// DIR.partial when it is stopped that way.
std::string rank_prefix() {
  return mpi::is_root() ? std::string("pegasus: ")
                        : fmt::format("pegasus: rank {} of {}: ", mpi::rank(), mpi::size());
}

// Loads the config file and the overrides, and validates them. With several ranks, every rank learns whether
// any failed: rank 0's error is rethrown; another rank's is printed by that rank and reported by rank 0.
void set_up_config(Leaf& leaf) {
  ConfigSchema& schema = leaf.schema;
  std::exception_ptr error;
  try {
    std::vector<std::string> given;  // on the command line, which wins over the file
    for (std::size_t i = 0; i < leaf.options.size(); ++i)
      if (leaf.options[i]->count() > 0) given.push_back(schema.fields()[i].name());
    if (!leaf.config_file.empty()) schema.load_toml_file(leaf.config_file, given);
    for (std::size_t i = 0; i < leaf.options.size(); ++i) {
      if (leaf.options[i]->count() > 0) schema.set_from_cli(schema.fields()[i].name(), leaf.texts[i]);
    }
    if (leaf.command->resolve) leaf.command->resolve(schema);
    schema.validate();
  } catch (...) {
    error = std::current_exception();
  }
  if (mpi::size() == 1) {
    if (error) std::rethrow_exception(error);
    return;
  }
  const std::vector<int> failed = mpi::allgather_int(error ? 1 : 0);
  if (failed[0]) std::rethrow_exception(error);
  std::string ranks;
  for (std::size_t r = 1; r < failed.size(); ++r)
    if (failed[r]) ranks += (ranks.empty() ? "" : ", ") + std::to_string(r);
  if (ranks.empty()) return;
  if (error) {
    try {
      std::rethrow_exception(error);
    } catch (const std::exception& e) {
      std::cerr << rank_prefix() << one_line(e.what()) << std::endl;
    }
  }
  throw InputError("rank " + ranks + " could not read the configuration (see its message)");
}

// After a failure has been said (by rank 0; the other ranks print nothing for one met by all): mpirun stops
// the remaining ranks once the first exits with an error, so rank 0 must not then add its "job was stopped"
// line, and a failure in the set-up, which every rank meets alike (set_up_config and RunDirectory::open agree
// on it), lets the ranks leave together only once rank 0 has said it.
void leave_after_saying(bool running) {
  mpi::stop_message_said();
  if (!running) mpi::barrier();
}

// Ctrl-C, a hang-up or a plain kill (SIGTERM) while a run directory is open: the interrupted run's
// DIR.partial stays for --resume, and the handler says so before the signal takes its default course (exit
// status 128 + the signal, as a shell expects). The line is formatted when the directory opens and kept in
// static storage, so that the handler only calls write(2). Under mpirun the launcher's SIGTERM is the MPI
// layer's (mpi.hpp: its stop message).
char g_interrupted_line[2048] = "";

extern "C" void on_interrupt(int signal_number) {
  const ssize_t ignored = ::write(STDERR_FILENO, g_interrupted_line, std::strlen(g_interrupted_line));
  (void)ignored;
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

class InterruptLine {
 public:
  explicit InterruptLine(const std::filesystem::path& partial) {
    // After a progress bar's carriage return, on a line of its own.
    std::string text = fmt::format(
        "{}pegasus: interrupted; partial results kept in {}: rerun the same command "
        "with --resume to continue (or --force to start again)\n",
        ::isatty(STDERR_FILENO) ? "\n" : "", printable(partial.string()));
    if (text.size() >= sizeof g_interrupted_line)
      text = "pegasus: interrupted; rerun with --resume to continue\n";
    std::memcpy(g_interrupted_line, text.c_str(), text.size() + 1);
    // A signal the process was started ignoring (a background job of a script ignores SIGINT, nohup
    // SIGHUP) stays ignored.
    for (std::size_t i = 0; i < std::size(kSignals); ++i) {
      previous_[i] = std::signal(kSignals[i], on_interrupt);
      if (previous_[i] == SIG_IGN) std::signal(kSignals[i], SIG_IGN);
    }
  }
  ~InterruptLine() {
    for (std::size_t i = 0; i < std::size(kSignals); ++i) std::signal(kSignals[i], previous_[i]);
  }
  InterruptLine(const InterruptLine&) = delete;
  InterruptLine& operator=(const InterruptLine&) = delete;

 private:
  static constexpr int kSignals[] = {SIGINT, SIGHUP, SIGTERM};
  using Handler = void (*)(int);
  Handler previous_[std::size(kSignals)]{};
};

// Opens the run directory (when `dir` is given), runs `command` with the resolved and validated `schema`,
// and writes run.json and the report before committing. `run_dir` stays with the caller for its error
// message; `running` turns true once the set-up is past. A stage of another command (run_stage) leaves the
// MPI stop message to the command that runs it.
int run_command(const Command& command, const ConfigSchema& schema, const std::string& dir,
                RunDirectoryOptions opening, bool quiet, bool stage, const std::vector<std::string>& argv,
                std::optional<RunDirectory>& run_dir, bool& running, std::ostream& out, std::ostream& err) {
  const auto start = std::chrono::steady_clock::now();
  std::optional<InterruptLine> interrupt_line;
  if (!dir.empty()) {
    run_dir.emplace(RunDirectory::open(dir, schema, opening));
    if (!stage && mpi::size() == 1) interrupt_line.emplace(run_dir->path());
    if (!stage)
      mpi::set_stop_message(
          fmt::format("pegasus: error: the MPI job was stopped (a rank failed or the job was "
                      "killed); partial results kept in {}: rerun with --resume to continue",
                      run_dir->path().string()));
  } else if (command.out == OutDir::kRequired) {
    throw InputError("--out: expected a directory name, got an empty value");
  }
  running = true;
  KeptOutput kept(out.rdbuf());
  std::ostream printed(&kept);
  RunContext context(schema, quiet, run_dir ? &*run_dir : nullptr, printed, err);
  try {
    command.run(context);
  } catch (const ConfigFieldError& e) {
    if (run_dir) run_dir->abandon();  // bad input leaves nothing behind (a resumed DIR.partial is kept)
    throw InputError(naming_origin(schema, e));
  } catch (const InputError&) {
    if (run_dir) run_dir->abandon();
    throw;
  }
  printed.flush();
  out.flush();
  if (run_dir) {
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // Provenance that is not a result (wall time varies), kept apart from summary.json.
    nlohmann::json provenance = {
        {"command", command.path},       {"version", kVersion},        {"argv", argv},
        {"resumed", run_dir->resumed()}, {"threads", context.threads}, {"ranks", mpi::size()},
        {"wall_time_s", wall},           {"timings", context.timings}};
    // What the run printed (its result lines and warnings), which the report opens with.
    const std::vector<std::string> lines = kept.lines();
    std::vector<std::string> warnings;
    for (const std::string& line : lines)
      if (line.starts_with("warning:")) warnings.push_back(line);
    provenance["printed"] = lines;
    provenance["warnings"] = warnings;
    if (mpi::size() > 1) {
      const mpi::CommStats comm = mpi::comm_stats();  // rank 0's
      provenance["allgathers"] = comm.calls;
      provenance["allgather_seconds"] = comm.seconds;
    }
    run_dir->write_json("run.json", provenance);
    // The run's HTML report (report/report.hpp), by rank 0 alone; a failure costs only the report (one
    // note).
    if (mpi::is_root()) report::write_report_or_note(run_dir->path(), err);
    run_dir->commit();
  }
  return context.exit_code;
}

// Runs the command of `leaf` after parsing succeeded.
int execute(Leaf& leaf, const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  std::optional<RunDirectory> run_dir;
  bool running = false;  // past the set-up: with several ranks, a failure ends the whole job
  try {
    set_up_config(leaf);
    return run_command(*leaf.command, leaf.schema, leaf.out, {.force = leaf.force, .resume = leaf.resume},
                       leaf.quiet, /*stage=*/false, argv, run_dir, running, out, err);
  } catch (const InputError& e) {
    err << "pegasus: " << one_line(e.what()) << std::endl;
    leave_after_saying(running);
    if (running && mpi::size() > 1) {
      // Bad input is normally met by every rank alike: rank 0 says it and ends the job. A rank alone with it
      // (a file only its node lacks) says it after a moment.
      if (!mpi::is_root()) {
        std::this_thread::sleep_for(std::chrono::seconds(2));
        std::cerr << rank_prefix() << one_line(e.what()) << std::endl;
      }
      mpi::abort_job(kExitBadInput);
    }
    return kExitBadInput;
  } catch (const std::exception& e) {
    // Whose fault: the machine's (a full disk, a permission, no memory or thread) or anything else's.
    const bool environment = dynamic_cast<const EnvironmentError*>(&e) != nullptr ||
                             dynamic_cast<const std::filesystem::filesystem_error*>(&e) != nullptr ||
                             dynamic_cast<const std::bad_alloc*>(&e) != nullptr ||
                             dynamic_cast<const std::system_error*>(&e) != nullptr;
    const int code = environment ? kExitEnvironment : kExitFailure;
    std::string kept;
    if (run_dir && !run_dir->committed() && run_dir->resumable()) {
      kept = fmt::format(" (partial results kept in {}: rerun with --resume to continue)",
                         run_dir->path().string());
    }
    if (mpi::is_root()) {
      err << "pegasus: error: " << one_line(e.what() + kept) << std::endl;
    } else {
      std::cerr << rank_prefix() << "error: " << one_line(e.what()) << std::endl;
    }
    leave_after_saying(running);
    if (running && mpi::size() > 1) mpi::abort_job(code);
    return code;
  }
}

// Clearer messages than CLI11's for two common slips: an unknown command word (CLI11: "A subcommand is
// required") and an option missing its value (CLI11 takes the next option as the value). Empty if fine.
std::string precheck(CLI::App& app, int argc, const char* const* argv) {
  CLI::App* current = &app;
  auto known = [](const std::vector<CLI::App*>& subs) {
    std::string listed, all;
    for (CLI::App* sub : subs) {
      all += (all.empty() ? "" : ", ") + sub->get_name();
      if (!sub->get_group().empty()) listed += (listed.empty() ? "" : ", ") + sub->get_name();
    }
    return listed.empty() ? all : listed;
  };
  int i = 1;
  for (;; ++i) {
    auto subs = current->get_subcommands([](CLI::App*) { return true; });
    if (subs.empty()) break;
    if (i == argc) return fmt::format("a command is required (commands: {})", known(subs));
    const std::string word = argv[i];
    if (word.starts_with("-")) break;
    auto it = std::find_if(subs.begin(), subs.end(), [&](CLI::App* sub) { return sub->get_name() == word; });
    if (it == subs.end()) return fmt::format("unknown command '{}' (commands: {})", word, known(subs));
    current = *it;
  }
  for (; i < argc; ++i) {
    const std::string word = argv[i];
    if (!word.starts_with("--") || word.find('=') != std::string::npos) continue;
    const CLI::Option* option = current->get_option_no_throw(word);
    if (option == nullptr || option->get_expected_min() < 1) continue;
    if (i + 1 == argc || std::string_view(argv[i + 1]).starts_with("--")) return word + ": expected a value";
    ++i;
  }
  return {};
}

}  // namespace

ConfigSchema command_schema(const Command& command) {
  ConfigSchema schema;
  if (command.declare) command.declare(schema);
  add_common_fields(schema);
  return schema;
}

std::vector<std::string> command_line_of(const Command& command, const ConfigSchema& config,
                                         const std::string& out) {
  std::vector<std::string> line = {"pegasus"};
  for (std::size_t from = 0; from <= command.path.size();) {
    const std::size_t space = std::min(command.path.find(' ', from), command.path.size());
    line.push_back(command.path.substr(from, space - from));
    from = space + 1;
  }
  struct Text {
    std::string operator()(std::int64_t x) const { return std::to_string(x); }
    std::string operator()(double x) const { return format_double(x); }
    std::string operator()(bool x) const { return x ? "true" : "false"; }
    std::string operator()(const std::string& x) const { return x; }
    std::string operator()(const std::vector<std::int64_t>& xs) const {
      return fmt::format("{}", fmt::join(xs, ","));
    }
    std::string operator()(const std::vector<double>& xs) const {
      std::string text;
      for (double x : xs) text += (text.empty() ? "" : ",") + format_double(x);
      return text;
    }
    std::string operator()(const std::vector<std::string>& xs) const {
      return fmt::format("{}", fmt::join(xs, ","));
    }
  };
  for (const ConfigField& f : config.fields()) {
    if (config.origin(f.name()) == "default") continue;
    const FieldValue& value = config.value(f.name());
    const std::string option = ConfigSchema::option_name(f.name());
    if (f.type() == FieldType::kBool)
      line.push_back(std::get<bool>(value) ? option : option + "=false");
    else
      line.insert(line.end(), {option, std::visit(Text{}, value)});
  }
  if (!out.empty()) line.insert(line.end(), {"--out", out});
  return line;
}

int run_stage(const Command& command, ConfigSchema config, const std::string& out_dir,
              const StageOptions& options, std::ostream& out, std::ostream& err) {
  std::vector<std::string> argv = command_line_of(command, config, out_dir);  // what the caller set
  if (options.force) argv.emplace_back("--force");
  if (options.resume) argv.emplace_back("--resume");
  if (options.quiet) argv.emplace_back("--quiet");
  if (command.resolve) command.resolve(config);
  config.validate();
  std::optional<RunDirectory> run_dir;
  bool running = false;
  return run_command(command, config, path_under(config.base_directory(), out_dir),
                     {.force = options.force, .resume = options.resume}, options.quiet, /*stage=*/true, argv,
                     run_dir, running, out, err);
}

int run_cli(int argc, const char* const* argv, const std::vector<CommandGroup>& groups,
            const std::vector<Command>& commands, std::ostream& out, std::ostream& err) {
  std::deque<Leaf> leaves;
  try {
    CLI::App app("pegasus: reward shaping and PEGASUS policy search (A. Y. Ng, PhD thesis, 2003)", "pegasus");
    app.set_version_flag("--version", kVersion);
    app.require_subcommand(1);
    app.get_formatter()->column_width(36);
    app.set_help_all_flag("--help-all", "Print every option, the settings of the parts included, and exit");

    // Nested commands: every word of a path is a subcommand of the previous one.
    std::map<std::string, CLI::App*> apps{{"", &app}};
    auto parent_of = [&](const std::string& path) -> CLI::App* {
      const auto space = path.rfind(' ');
      const std::string parent = space == std::string::npos ? "" : path.substr(0, space);
      auto it = apps.find(parent);
      if (it == apps.end()) throw std::logic_error("command '" + path + "' has no group '" + parent + "'");
      return it->second;
    };
    auto word_of = [](const std::string& path) {
      const auto space = path.rfind(' ');
      return space == std::string::npos ? path : path.substr(space + 1);
    };
    for (const auto& group : groups) {
      CLI::App* sub = parent_of(group.path)->add_subcommand(word_of(group.path), group.description);
      sub->require_subcommand(1);
      if (group.hidden) sub->group("");
      apps[group.path] = sub;
    }
    for (const auto& command : commands) {
      Leaf& leaf = leaves.emplace_back();
      leaf.command = &command;
      leaf.app = parent_of(command.path)->add_subcommand(word_of(command.path), command.description);
      if (command.hidden) leaf.app->group("");
      leaf.schema = command_schema(command);
      declare_options(leaf);
      apps[command.path] = leaf.app;
    }

    if (argc == 2 && std::string_view(argv[1]) == kHelpMarkdownFlag) {  // the manual's generated reference
      out << help_markdown(app);
      return 0;
    }
    if (argc == 2 && std::string_view(argv[1]) == kSummaryKeysMarkdownFlag) {  // the summary.json reference
      out << summary_keys_markdown();
      return 0;
    }
    if (argc >= 2 && std::string_view(argv[1]) == kUndescribedSummaryKeysFlag)  // the key table's check
      return undescribed_summary_keys_main(std::vector<std::string>(argv + 2, argv + argc), out, err);
    if (const std::string problem = precheck(app, argc, argv); !problem.empty()) {
      err << "pegasus: " << problem << " (see pegasus --help)" << std::endl;
      return 2;
    }
    try {
      app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
      hide_advanced_options(leaves);
      return app.exit(e, out, err);
    } catch (const CLI::CallForAllHelp& e) {
      return app.exit(e, out, err);
    } catch (const CLI::CallForVersion& e) {
      return app.exit(e, out, err);
    } catch (const CLI::ParseError& e) {
      err << "pegasus: " << one_line(e.what()) << " (see pegasus --help)" << std::endl;
      return 2;
    }
    for (auto& leaf : leaves) {
      if (leaf.app->parsed()) return execute(leaf, std::vector<std::string>(argv, argv + argc), out, err);
    }
    err << "pegasus: a command is required (see pegasus --help)" << std::endl;
    return 2;
  } catch (const std::exception& e) {
    err << "pegasus: error: " << one_line(e.what()) << std::endl;
    return 1;
  }
}

}  // namespace pegasus::cli
