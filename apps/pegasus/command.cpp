#include "command.hpp"

#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <deque>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <thread>

#include "pegasus/core/error.hpp"

namespace pegasus::cli {

RunContext::RunContext(const ConfigSchema& cfg, bool q, RunDirectory* run_dir, std::ostream& o)
    : config(cfg),
      seed(static_cast<std::uint64_t>(cfg.get_int("seed"))),
      threads(static_cast<int>(cfg.get_int("threads"))),
      quiet(q),
      out(o),
      run_dir_(run_dir) {}

RunDirectory& RunContext::run_directory() const {
  if (run_dir_ == nullptr) throw std::logic_error("this command was run without --out");
  return *run_dir_;
}

Progress RunContext::progress(std::string label, std::uint64_t total) const {
  return Progress(std::move(label), total, Progress::default_enabled(quiet));
}

ThreadPool& RunContext::pool() {
  if (!pool_) pool_ = std::make_unique<ThreadPool>(threads);
  return *pool_;
}

namespace {

// Every message is one line.
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
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
  schema.add_int("threads", hardware, "worker threads; results do not depend on it")
      .min(1)
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
  }
  return "VALUE";
}

void declare_options(Leaf& leaf) {
  CLI::App* app = leaf.app;
  const auto& fields = leaf.schema.fields();
  leaf.texts.resize(fields.size());
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const ConfigField& f = fields[i];
    const std::string help = fmt::format("{} [{}; default {}]", f.help(), f.expectation(),
                                         ConfigSchema::format_value(f.default_value()));
    CLI::Option* option = nullptr;
    if (f.type() == FieldType::kBool) {
      // `--flag` alone means true; `--flag=false` is accepted too.
      option = app->add_flag(ConfigSchema::option_name(f.name()), leaf.texts[i], help);
    } else {
      option = app->add_option(ConfigSchema::option_name(f.name()), leaf.texts[i], help)
                   ->type_name(type_name(f.type()));
    }
    option->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
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

// Runs the command of `leaf` after parsing succeeded.
int execute(Leaf& leaf, std::vector<std::string> argv, std::ostream& out, std::ostream& err) {
  std::optional<RunDirectory> run_dir;
  try {
    ConfigSchema& schema = leaf.schema;
    if (!leaf.config_file.empty()) schema.load_toml_file(leaf.config_file);
    for (std::size_t i = 0; i < leaf.options.size(); ++i) {
      if (leaf.options[i]->count() > 0) schema.set_from_cli(schema.fields()[i].name(), leaf.texts[i]);
    }
    schema.validate();

    const auto start = std::chrono::steady_clock::now();
    if (!leaf.out.empty()) {
      run_dir.emplace(RunDirectory::open(leaf.out, schema, {.force = leaf.force, .resume = leaf.resume}));
    } else if (leaf.command->out == OutDir::kRequired) {
      throw InputError("--out: expected a directory name, got an empty value");
    }
    RunContext context(schema, leaf.quiet, run_dir ? &*run_dir : nullptr, out);
    try {
      leaf.command->run(context);
    } catch (const InputError&) {
      if (run_dir) run_dir->abandon();  // bad input leaves nothing behind (a resumed DIR.partial is kept)
      throw;
    }
    out.flush();
    if (run_dir) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      // Provenance that is not a result (wall time varies), kept apart from summary.json.
      run_dir->write_json("run.json", {{"command", leaf.command->path},
                                       {"version", kVersion},
                                       {"argv", argv},
                                       {"resumed", run_dir->resumed()},
                                       {"threads", context.threads},
                                       {"wall_time_s", wall}});
      run_dir->commit();
    }
    return context.exit_code;
  } catch (const InputError& e) {
    err << "pegasus: " << one_line(e.what()) << std::endl;
    return 2;
  } catch (const std::exception& e) {
    std::string kept;
    if (run_dir && !run_dir->committed()) {
      kept = fmt::format(" (partial results kept in {}: rerun with --resume to continue)",
                         run_dir->path().string());
    }
    err << "pegasus: error: " << one_line(e.what()) << kept << std::endl;
    return 1;
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

int run_cli(int argc, const char* const* argv, const std::vector<CommandGroup>& groups,
            const std::vector<Command>& commands, std::ostream& out, std::ostream& err) {
  std::deque<Leaf> leaves;
  try {
    CLI::App app("pegasus: reward shaping and PEGASUS policy search (A. Y. Ng, PhD thesis, 2003)", "pegasus");
    app.set_version_flag("--version", kVersion);
    app.require_subcommand(1);
    app.get_formatter()->column_width(36);

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
      if (command.declare) command.declare(leaf.schema);
      add_common_fields(leaf.schema);
      declare_options(leaf);
      apps[command.path] = leaf.app;
    }

    if (const std::string problem = precheck(app, argc, argv); !problem.empty()) {
      err << "pegasus: " << problem << " (see pegasus --help)" << std::endl;
      return 2;
    }
    try {
      app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
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
