// The helicopter pipeline run from a program (include/pegasus/cli/command.hpp: call_command): in this
// process, by the command table's own code, without a command line, and without using or changing the working
// directory (the stages name each other's files relative to the run directory: ConfigSchema::get_path). Its
// files are the CLI's, byte for byte.
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pegasus/cli/command.hpp"
#include "pegasus/core/error.hpp"
#include "support/cli_runner.hpp"

namespace pegasus::cli {
namespace {

namespace fs = std::filesystem;
using test_support::read_text;
using test_support::run_pegasus;

// The process's working directory for the life of a test, put back after.
class InDirectory {
 public:
  explicit InDirectory(const fs::path& dir) : previous_(fs::current_path()) { fs::current_path(dir); }
  ~InDirectory() { fs::current_path(previous_); }
  InDirectory(const InDirectory&) = delete;
  InDirectory& operator=(const InDirectory&) = delete;

 private:
  fs::path previous_;
};

class PipelineCall : public test_support::TempDirTest {};

// The smallest pipeline that still trains and flies (a few seconds).
const char* const kSmallOptions =
    "--train-seconds 60 --test-seconds 25 --cv-points 40 --scale-grid 2,4 --coordinate-passes 0 --scenarios "
    "2 "
    "--scenario-seconds 2 --gradient-iterations 0 --hill-climbing-iterations 1 --flights 2 --flight-seconds "
    "3 "
    "--seed 5 --threads 2";
std::vector<std::pair<std::string, FieldValue>> small_settings() {
  return {{"train_seconds", std::int64_t{60}},
          {"test_seconds", 25.0},
          {"cv_points", std::int64_t{40}},
          {"scale_grid", std::vector<std::int64_t>{2, 4}},
          {"coordinate_passes", std::int64_t{0}},
          {"scenarios", std::int64_t{2}},
          {"scenario_seconds", 2.0},
          {"gradient_iterations", std::int64_t{0}},
          {"hill_climbing_iterations", std::int64_t{1}},
          {"flights", std::int64_t{2}},
          {"flight_seconds", 3.0},
          {"seed", std::int64_t{5}},
          {"threads", std::int64_t{2}}};
}

TEST_F(PipelineCall, RunsInThisProcessWithoutTheWorkingDirectoryAndWritesTheCLIsFiles) {
  const auto cli =
      run_pegasus(fmt::format("heli pipeline --quiet {} --out {}", kSmallOptions, (dir_ / "cli").string()));
  ASSERT_EQ(cli.code, 0) << cli.output;

  // From a working directory where the stages' relative names (pilot-train/log.csv, ...) name nothing.
  fs::create_directories(dir_ / "elsewhere");
  const InDirectory elsewhere(dir_ / "elsewhere");
  const fs::path before = fs::current_path();
  std::ostringstream out, err;
  EXPECT_EQ(call_command("heli pipeline", small_settings(), (dir_ / "lib").string(), {}, out, err), 0)
      << err.str();
  EXPECT_EQ(fs::current_path(), before);
  EXPECT_TRUE(fs::is_empty(dir_ / "elsewhere"));
  EXPECT_FALSE(fs::exists(dir_ / "lib.partial"));
  for (const char* part :
       {"summary.json", "config.toml", "pilot-train/summary.json", "pilot-test/summary.json",
        "identify/summary.json", "identify/config.toml", "hover/summary.json", "hover/config.toml",
        "hover/policy.json", "fly/summary.json", "fly/config.toml"}) {
    const std::string library = read_text(dir_ / "lib" / part);
    EXPECT_FALSE(library.empty()) << part;
    EXPECT_EQ(library, read_text(dir_ / "cli" / part)) << part;
  }
  // The stages recorded their inputs as the config names them, relative to the run directory.
  EXPECT_NE(read_text(dir_ / "lib" / "hover" / "config.toml").find("\"identify/model.json\""),
            std::string::npos);
}

TEST_F(PipelineCall, BadSettingsNameTheFieldAndLeaveNothing) {
  std::ostringstream out, err;
  for (const auto& [setting, named] :
       {std::pair{std::pair<std::string, FieldValue>{"flights", std::int64_t{-1}}, std::string("'flights'")},
        std::pair{std::pair<std::string, FieldValue>{"flight_secs", 3.0}, std::string("'flight_secs'")},
        std::pair{std::pair<std::string, FieldValue>{"flights", std::string("two")},
                  std::string("'flights'")}}) {
    try {
      call_command("heli pipeline", {setting}, (dir_ / "bad").string(), {}, out, err);
      ADD_FAILURE() << setting.first << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(dir_ / "bad"));
    EXPECT_FALSE(fs::exists(dir_ / "bad.partial"));
  }
  EXPECT_THROW(call_command("heli nothing", {}, (dir_ / "bad").string(), {}, out, err), InputError);
}

}  // namespace
}  // namespace pegasus::cli
