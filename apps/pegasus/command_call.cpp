// call_command (command.hpp): a command of the table run from a program, its settings given as values.
#include <fmt/format.h>

#include <algorithm>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "pegasus/cli/command.hpp"
#include "pegasus/core/error.hpp"

namespace pegasus::cli {

namespace {

// A field name a TOML bare (dotted) key spells as it is: letters, digits, '_', and '.' between words.
bool plain_key(const std::string& name) {
  const bool chars = std::all_of(
      name.begin(), name.end(), [](unsigned char c) { return std::isalnum(c) != 0 || c == '_' || c == '.'; });
  return chars && !name.empty() && name.front() != '.' && name.back() != '.' &&
         name.find("..") == std::string::npos;
}

// The settings as the lines of a config file, so that they are read and checked as one would be (the
// integer 60 taken for a number, unknown keys refused with the list of known ones).
std::string settings_toml(const std::string& path,
                          const std::vector<std::pair<std::string, FieldValue>>& settings) {
  std::string text;
  for (const auto& [name, value] : settings) {
    if (!plain_key(name))
      throw InputError(fmt::format(
          "{}: '{}' is no setting's name (expected a TOML key such as train_seconds)", path, name));
    text += name + " = " + ConfigSchema::format_value(value) + "\n";
  }
  return text;
}

}  // namespace

int call_command(const std::string& path, const std::vector<std::pair<std::string, FieldValue>>& settings,
                 const std::string& out_dir, const CallOptions& options, std::ostream& out,
                 std::ostream& err) {
  static const std::vector<Command> table = commands();
  const auto it = std::find_if(table.begin(), table.end(), [&](const Command& c) { return c.path == path; });
  if (it == table.end() || it->hidden)
    throw InputError(fmt::format("unknown command '{}' (see pegasus --help)", path));
  if (it->out == OutDir::kNone) throw InputError(fmt::format("{}: writes no run directory", path));
  if (out_dir.empty()) throw InputError("out: expected a directory name, got an empty value");
  ConfigSchema config = command_schema(*it);
  // Messages name the command and the setting ("heli pipeline: setting 'flights': expected ...").
  config.load_settings(settings_toml(path, settings), path);
  return run_stage(*it, std::move(config), out_dir,
                   {.quiet = options.quiet, .force = options.force, .resume = options.resume}, out, err);
}

}  // namespace pegasus::cli
