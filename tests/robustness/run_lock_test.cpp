// Two runs on one --out DIR (issue 16, case 1): the run-directory lock lets exactly one of them work on DIR;
// the other exits 2 at once with one line naming the holder's pid, and touches nothing.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "pegasus/runs/run_directory.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace {

namespace fs = std::filesystem;
using pegasus::test_support::read_text;

enum class Mode { kPlain, kForce, kResume };

const char* flag_of(Mode mode) {
  switch (mode) {
    case Mode::kPlain:
      return "";
    case Mode::kForce:
      return "--force";
    case Mode::kResume:
      return "--resume";
  }
  return "";
}

const char* name_of(Mode mode) {
  switch (mode) {
    case Mode::kPlain:
      return "plain";
    case Mode::kForce:
      return "force";
    case Mode::kResume:
      return "resume";
  }
  return "";
}

// The run both processes make: long enough (about 0.5 s) that the second starts while the first holds DIR.
const std::vector<std::string> kRunArgs = {"dev",       "count", "--steps", "12",
                                           "--step-ms", "40",    "--scale", "0.5"};

struct Exited {
  pid_t pid = -1;
  int code = -1;
  std::string err;
};

class RunLock : public pegasus::test_support::TempDirTest {
 protected:
  // Forks `pegasus dev count ... --out run FLAG`, its stderr to a file; the child waits until `gate` is
  // closed, so that two children can be let go at the same moment.
  pid_t start(Mode mode, const std::string& err_name, std::array<int, 2> gate = {-1, -1}) const {
    std::vector<std::string> args = {PEGASUS_CLI_PATH};
    args.insert(args.end(), kRunArgs.begin(), kRunArgs.end());
    args.insert(args.end(), {"--out", (dir_ / "run").string(), "--quiet"});
    if (mode != Mode::kPlain) args.emplace_back(flag_of(mode));
    const std::string err_file = (dir_ / err_name).string();
    const pid_t child = ::fork();
    if (child == 0) {
      char byte = 0;
      if (gate[0] >= 0) {
        ::close(gate[1]);                  // EOF comes only once every copy of the write end is closed
        (void)!::read(gate[0], &byte, 1);  // returns at EOF, when the parent closes its end
      }
      const int fd = ::open(err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0 || ::dup2(fd, 2) < 0) ::_exit(127);
      const int null = ::open("/dev/null", O_WRONLY);
      if (null < 0 || ::dup2(null, 1) < 0) ::_exit(127);
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      ::execv(argv[0], argv.data());
      ::_exit(127);
    }
    return child;
  }

  Exited wait_for(pid_t child, const std::string& err_name) const {
    int status = 0;
    ::waitpid(child, &status, 0);
    return {child, WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_text(dir_ / err_name)};
  }

  // The state each pair of modes may legally start from: an earlier complete DIR when both replace it, an
  // interrupted DIR.partial when both may take it over, else nothing.
  void prepare(Mode a, Mode b) const {
    auto both = [&](auto pred) { return pred(a) && pred(b); };
    const std::string base = std::string(PEGASUS_CLI_PATH) +
                             " dev count --steps 12 --scale 0.5 --quiet --out " + (dir_ / "run").string();
    if (both([](Mode m) { return m == Mode::kForce; })) {
      ASSERT_EQ(pegasus::test_support::run_shell(base + " --steps 3").code, 0);  // a different, older result
    } else if (both([](Mode m) { return m != Mode::kPlain; })) {
      ASSERT_EQ(pegasus::test_support::run_shell(base + " --fail-at 4").code, 1);
      ASSERT_TRUE(fs::exists(dir_ / "run.partial" / "checkpoint.json"));
    }
  }

  // DIR holds exactly one complete run, equal to a straight run of the same settings, and nothing
  // half-written lies anywhere (no DIR.partial, no lock file, no temporaries).
  void expect_complete_and_alone() const {
    std::string straight_args = std::string(PEGASUS_CLI_PATH);
    for (const auto& a : kRunArgs) straight_args += " " + a;
    const fs::path straight = dir_.parent_path() / (dir_.filename().string() + "-straight");
    if (!fs::exists(straight)) {
      ASSERT_EQ(
          pegasus::test_support::run_shell(straight_args + " --step-ms 0 --quiet --out " + straight.string())
              .code,
          0);
    }
    for (const char* file :
         {"config.toml", "summary.json", "values.csv", "values.svg", "run.json", "report.html"}) {
      EXPECT_TRUE(fs::exists(dir_ / "run" / file)) << file;
    }
    EXPECT_EQ(read_text(dir_ / "run" / "summary.json"), read_text(straight / "summary.json"));
    EXPECT_EQ(read_text(dir_ / "run" / "values.csv"), read_text(straight / "values.csv"));
    EXPECT_FALSE(fs::exists(dir_ / "run.partial"));
    EXPECT_FALSE(fs::exists(dir_ / "run.lock"));
    for (const auto& entry : fs::recursive_directory_iterator(dir_)) {
      EXPECT_FALSE(entry.path().filename().string().ends_with(".tmp")) << entry.path();
    }
  }

  void TearDown() override {
    fs::remove_all(dir_.parent_path() / (dir_.filename().string() + "-straight"));
    TempDirTest::TearDown();
  }

  // The loser's one line: exit 2, names DIR and the winner's pid.
  static void expect_refused_by(const Exited& loser, const Exited& winner) {
    EXPECT_EQ(loser.code, 2) << loser.err;
    EXPECT_EQ(loser.err.find('\n'), loser.err.size() - 1) << "not one line: " << loser.err;
    EXPECT_NE(loser.err.find("is in use by another run (pid " + std::to_string(winner.pid) + ","),
              std::string::npos)
        << loser.err;
  }
};

constexpr std::array kModes = {Mode::kPlain, Mode::kForce, Mode::kResume};

// The second run starts while the first is known to hold DIR: refused at once, the first unharmed.
TEST_F(RunLock, ASecondRunWhileTheFirstHoldsDirIsRefusedNamingItsPid) {
  int pairs = 0;
  for (Mode first : kModes) {
    for (Mode second : kModes) {
      SCOPED_TRACE(std::string(name_of(first)) + " then " + name_of(second));
      fs::remove_all(dir_ / "run");
      fs::remove_all(dir_ / "run.partial");
      prepare(first, second);
      const pid_t a = start(first, "a.err");
      // The holder writes its pid into DIR.lock right after locking.
      const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
      while (read_text(dir_ / "run.lock") != std::to_string(a) + "\n" &&
             std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
      const auto started = std::chrono::steady_clock::now();
      const Exited b = wait_for(start(second, "b.err"), "b.err");
      const double refused_after =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      const Exited winner = wait_for(a, "a.err");
      EXPECT_EQ(winner.code, 0) << winner.err;
      expect_refused_by(b, winner);
      EXPECT_LT(refused_after, 5.0) << "the second run waited instead of being refused at once";
      expect_complete_and_alone();
      ++pairs;
    }
  }
  EXPECT_EQ(pairs, 9);
}

// Both runs let go at the same moment, twice for every pair of modes: exactly one succeeds, the other is
// refused by the lock, and DIR is complete.
TEST_F(RunLock, TwoRunsStartedTogetherLeaveOneCompleteDirAndOneSuccess) {
  constexpr int kTrials = 2;
  for (int trial = 0; trial < kTrials; ++trial) {
    for (Mode first : kModes) {
      for (Mode second : kModes) {
        SCOPED_TRACE(std::string(name_of(first)) + " with " + name_of(second) + ", trial " +
                     std::to_string(trial));
        fs::remove_all(dir_ / "run");
        fs::remove_all(dir_ / "run.partial");
        prepare(first, second);
        std::array<int, 2> gate{};
        ASSERT_EQ(::pipe(gate.data()), 0);
        const pid_t a = start(first, "a.err", gate);
        const pid_t b = start(second, "b.err", gate);
        ::close(gate[0]);
        ::close(gate[1]);  // both children go
        const Exited ea = wait_for(a, "a.err"), eb = wait_for(b, "b.err");
        EXPECT_EQ((ea.code == 0) + (eb.code == 0), 1) << "a: " << ea.err << "b: " << eb.err;
        if (ea.code == 0) expect_refused_by(eb, ea);
        if (eb.code == 0) expect_refused_by(ea, eb);
        expect_complete_and_alone();
      }
    }
  }
}

// In one process too: a RunDirectory holds DIR until it is destroyed, and a second open() names this pid.
TEST_F(RunLock, OpenIsRefusedWhileAnotherRunDirectoryHoldsDirAndAllowedAfter) {
  pegasus::ConfigSchema schema;
  schema.add_int("n", 1, "a number");
  {
    pegasus::RunDirectory first = pegasus::RunDirectory::open(dir_ / "run", schema);
    const std::string message = pegasus::test_support::input_error_message(
        [&] { (void)pegasus::RunDirectory::open(dir_ / "run", schema, {.force = true}); });
    EXPECT_NE(message.find("(pid " + std::to_string(::getpid()) + ","), std::string::npos) << message;
    EXPECT_TRUE(fs::exists(dir_ / "run.partial" / "config.toml")) << "the refused open touched the run";
    first.commit();
  }
  EXPECT_FALSE(fs::exists(dir_ / "run.lock"));
  pegasus::RunDirectory again = pegasus::RunDirectory::open(dir_ / "run", schema, {.force = true});
  again.commit();
  EXPECT_TRUE(fs::exists(dir_ / "run" / "config.toml"));
}

}  // namespace
