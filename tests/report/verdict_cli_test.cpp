// Every command that writes a run directory (its --help-markdown section lists --out) has a verdict sentence
// for its report (include/pegasus/report/verdict.hpp): a new command cannot ship a report that leads with
// nothing.
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <string>

#include "pegasus/report/verdict.hpp"
#include "support/cli_runner.hpp"

namespace {

// command -> whether its section of `pegasus --help-markdown` has the option --out.
std::map<std::string, bool> commands_and_out() {
  const auto help = pegasus::test_support::run_pegasus("--help-markdown");
  EXPECT_EQ(help.code, 0) << help.output;
  std::map<std::string, bool> commands;
  std::istringstream lines(help.output);
  std::string line, command;
  const std::string heading = "## pegasus ";
  while (std::getline(lines, line)) {
    if (line.rfind(heading, 0) == 0) {
      command = line.substr(heading.size());
      commands[command] = false;
    } else if (!command.empty() && line.rfind("| `--out` |", 0) == 0) {
      commands[command] = true;
    }
  }
  return commands;
}

TEST(VerdictCli, EveryCommandThatWritesARunDirectoryHasAVerdict) {
  const auto commands = commands_and_out();
  // The parse found the commands: ones with a run directory, and heli control, which serves stdin and has
  // none.
  ASSERT_TRUE(commands.contains("log import") && commands.at("log import"));
  ASSERT_TRUE(commands.contains("heli control"));
  EXPECT_FALSE(commands.at("heli control")) << "heli control now writes a run directory: give it a verdict";
  for (const auto& [command, writes_run_directory] : commands)
    if (writes_run_directory) {
      EXPECT_TRUE(pegasus::report::has_verdict(command)) << command;
    }
}

}  // namespace
