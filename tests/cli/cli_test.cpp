// End-to-end tests of the `pegasus` command framework: they run the built CLI as a user would.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

namespace {

namespace fs = std::filesystem;

struct Result {
  int rc = -1;
  std::string out, err;
};

std::string slurp(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

class Cli : public testing::Test {
 protected:
  void SetUp() override {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("pegasus_cli_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }

  // Runs `pegasus ARGS` in the scratch folder; stderr is a file, never a terminal.
  Result run(const std::string& args) const {
    const std::string command =
        "cd '" + dir_.string() + "' && '" PEGASUS_CLI_PATH "' " + args + " >stdout.txt 2>stderr.txt";
    const int status = std::system(command.c_str());
    Result r;
    r.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = slurp(dir_ / "stdout.txt");
    r.err = slurp(dir_ / "stderr.txt");
    return r;
  }

  void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }
  nlohmann::json json(const std::string& name) const { return nlohmann::json::parse(slurp(dir_ / name)); }
  bool exists(const std::string& name) const { return fs::exists(dir_ / name); }

  // Bad input: exit 2, one line "pegasus: ..." on stderr that contains `expected`, no run directory.
  void expect_bad_input(const std::string& args, const std::string& expected) const {
    SCOPED_TRACE(args);
    const Result r = run(args + " --out run");
    EXPECT_EQ(r.rc, 2);
    EXPECT_EQ(r.err.rfind("pegasus: ", 0), 0u) << r.err;
    ASSERT_FALSE(r.err.empty());
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line: " << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_FALSE(exists("run"));
    EXPECT_FALSE(exists("run.partial"));
  }

  fs::path dir_;
};

TEST_F(Cli, HelpListsCommandsAndExitsZero) {
  const Result r = run("--help");
  EXPECT_EQ(r.rc, 0);
  EXPECT_NE(r.out.find("horizon"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("dev"), std::string::npos) << "self-test commands are hidden";
  const Result sub = run("horizon --help");
  EXPECT_EQ(sub.rc, 0);
  for (const char* option : {"--gamma", "--epsilon", "--rmax", "--seed", "--threads", "--out", "--config",
                             "--quiet", "--force", "--resume"}) {
    EXPECT_NE(sub.out.find(option), std::string::npos) << option;
  }
  // --help fits a screen: a command's own settings; its parts' (dotted names) are behind --help-all, which a
  // footer names (issue 50).
  const Result nested = run("dev count --help");
  EXPECT_EQ(nested.rc, 0);
  EXPECT_EQ(nested.out.find("--weights.values"), std::string::npos) << nested.out;
  EXPECT_NE(nested.out.find("--step-ms"), std::string::npos) << nested.out;
  EXPECT_NE(
      nested.out.find("1 more settings of its parts (optimizer, reward, ...): pegasus dev count --help-all"),
      std::string::npos)
      << nested.out;
  const Result all = run("dev count --help-all");
  EXPECT_EQ(all.rc, 0);
  EXPECT_NE(all.out.find("--weights.values"), std::string::npos) << all.out;
  EXPECT_NE(all.out.find("--step-ms"), std::string::npos) << all.out;
  // The longest command's --help stays about a screen; --help-all lists everything.
  const Result hover = run("heli hover --help"), hover_all = run("heli hover --help-all");
  EXPECT_LE(std::count(hover.out.begin(), hover.out.end(), '\n'), 40) << hover.out;
  EXPECT_GT(std::count(hover_all.out.begin(), hover_all.out.end(), '\n'), 80);
}

TEST_F(Cli, VersionPrintsTheVersion) {
  const Result r = run("--version");
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(r.out, "0.1.0\n");
}

TEST_F(Cli, NoCommandIsBadInput) {
  const Result r = run("");
  EXPECT_EQ(r.rc, 2);
  EXPECT_EQ(r.err.rfind("pegasus: ", 0), 0u);
}

TEST_F(Cli, HorizonPrintsAndRecordsTheEpsilonHorizon) {
  // eps (1 - gamma) / (2 Rmax) = 0.005; ln 0.005 / ln 0.9 = 50.29 -> 51.
  const Result r = run("horizon --gamma 0.9 --epsilon 0.1 --rmax 1");
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "{\"horizon\":51}\n");
  EXPECT_EQ(r.err, "");
  EXPECT_FALSE(exists("run"));
  const Result with_out = run("horizon --gamma 0.9 --epsilon 0.1 --rmax 1 --out run --quiet");
  EXPECT_EQ(with_out.rc, 0) << with_out.err;
  EXPECT_EQ(json("run/summary.json"), (nlohmann::json{{"horizon", 51}}));
  EXPECT_TRUE(exists("run/config.toml"));
  EXPECT_EQ(json("run/run.json")["command"], "horizon");
  EXPECT_FALSE(exists("run.partial"));
}

TEST_F(Cli, EveryKindOfBadInputExitsTwoWithOneLineAndNoRunDirectory) {
  expect_bad_input("horizon --gamma 1.5", "--gamma: expected a number in (0, 1), got '1.5'");
  expect_bad_input("horizon --gamma 0", "--gamma: expected a number in (0, 1)");
  expect_bad_input("horizon --gamma abc", "--gamma: expected a number");
  expect_bad_input("horizon --epsilon -1", "--epsilon: expected a number > 0");
  expect_bad_input("horizon --threads 0", "--threads: expected an integer in [1, 1024], got '0'");
  expect_bad_input("horizon --seed -3", "--seed: expected an integer >= 0");
  expect_bad_input("horizon --gama 0.5", "--gama");
  expect_bad_input("horizon --gamma", "--gamma");
  expect_bad_input("horizon extra", "extra");
  expect_bad_input("nosuchcommand", "unknown command 'nosuchcommand' (commands: ");
  expect_bad_input("horizon --gamma", "--gamma: expected a value");
  expect_bad_input("dev count --steps 0", "--steps: expected an integer in [1, 1000000], got '0'");
  expect_bad_input("dev count --shape cubic", "--shape: expected one of \"sqrt\", \"linear\", got 'cubic'");
  expect_bad_input("dev count --negate=maybe", "--negate: expected true or false, got 'maybe'");
  expect_bad_input("dev count --skip 1,-2", "--skip: expected a list of integers, each >= 0, got '1,-2'");
  expect_bad_input("dev count --weights.values ''",
                   "--weights.values: expected a list of numbers (at least 1)");
  expect_bad_input("dev count --resume --force --steps 2 --steps 0", "--steps");

  write("unknown.toml", "gamma = 0.9\ngama = 0.5\n");
  expect_bad_input("horizon --config unknown.toml",
                   "unknown.toml:2: unknown key 'gama' (did you mean 'gamma'?)");
  write("type.toml", "# a comment\nepsilon = \"small\"\n");
  expect_bad_input("horizon --config type.toml",
                   "type.toml:2: key 'epsilon': expected a number > 0, got the string \"small\"");
  write("range.toml", "\n\ngamma = 1.5\n");
  expect_bad_input("horizon --config range.toml",
                   "range.toml:3: key 'gamma': expected a number in (0, 1), got 1.5");
  // An option replaces the file's value, so the file's out-of-range one is not held against the run.
  const auto overridden = run("horizon --config range.toml --gamma 0.5 --epsilon 0.1 --rmax 1");
  EXPECT_EQ(overridden.rc, 0) << overridden.err;
  EXPECT_EQ(overridden.out, "{\"horizon\":6}\n");
  write("threads.toml", "threads = 0\n");
  expect_bad_input("horizon --config threads.toml",
                   "threads.toml:1: key 'threads': expected an integer in [1, 1024], got 0");
  write("syntax.toml", "gamma = 0.9\nepsilon = = 1\n");
  expect_bad_input("horizon --config syntax.toml", "syntax.toml:2: invalid TOML");
  write("nested.toml", "[weights]\nvalue = [1.0]\n");
  expect_bad_input("dev count --config nested.toml", "nested.toml:2: unknown key 'weights.value'");
  expect_bad_input("horizon --config missing.toml", "missing.toml: cannot read config file");
  expect_bad_input("horizon --config .", ".: cannot read config file");
}

TEST_F(Cli, CommandLineOverridesTheConfigFileAndTheResolvedConfigReloads) {
  write("run.toml", "gamma = 0.5\nepsilon = 0.1\nrmax = 2.0\nseed = 7\n");
  const Result r = run("horizon --config run.toml --gamma 0.9 --out first");
  EXPECT_EQ(r.rc, 0) << r.err;
  EXPECT_EQ(r.out, "{\"horizon\":57}\n");  // ln(0.1 * 0.1 / 4) / ln(0.9) = 56.8
  const std::string stored = slurp(dir_ / "first/config.toml");
  EXPECT_NE(stored.find("gamma = 0.9\n"), std::string::npos) << stored;
  EXPECT_NE(stored.find("rmax = 2.0\n"), std::string::npos) << stored;
  EXPECT_NE(stored.find("seed = 7\n"), std::string::npos) << stored;
  const Result again = run("horizon --config first/config.toml --out second");
  EXPECT_EQ(again.rc, 0) << again.err;
  EXPECT_EQ(slurp(dir_ / "second/summary.json"), slurp(dir_ / "first/summary.json"));
  EXPECT_EQ(slurp(dir_ / "second/config.toml"), stored);
}

TEST_F(Cli, ExistingOutIsRefusedAndForceReplacesIt) {
  ASSERT_EQ(run("horizon --gamma 0.9 --out run").rc, 0);
  const Result refused = run("horizon --gamma 0.5 --out run");
  EXPECT_EQ(refused.rc, 2);
  EXPECT_NE(refused.err.find("already exists (use --force to replace it)"), std::string::npos) << refused.err;
  EXPECT_EQ(json("run/summary.json")["horizon"], 73);
  const Result forced = run("horizon --gamma 0.5 --out run --force");
  EXPECT_EQ(forced.rc, 0) << forced.err;
  EXPECT_EQ(json("run/summary.json")["horizon"], 9);
  EXPECT_FALSE(exists("run.partial"));
}

TEST_F(Cli, RuntimeFailureExitsOneAndKeepsThePartialRunForResume) {
  const Result failed = run("dev count --steps 6 --fail-at 3 --out run");
  EXPECT_EQ(failed.rc, 1);
  EXPECT_EQ(failed.err.rfind("pegasus: error: failed at step 3", 0), 0u) << failed.err;
  EXPECT_EQ(std::count(failed.err.begin(), failed.err.end(), '\n'), 1);
  EXPECT_TRUE(exists("run.partial/checkpoint.json"));
  EXPECT_FALSE(exists("run"));
  // fail_at cannot change a result, so the run may be resumed without it.
  const Result resumed = run("dev count --steps 6 --out run --resume");
  EXPECT_EQ(resumed.rc, 0) << resumed.err;
  EXPECT_TRUE(json("run/run.json")["resumed"].get<bool>());
  ASSERT_EQ(run("dev count --steps 6 --out straight").rc, 0);
  EXPECT_EQ(slurp(dir_ / "run/summary.json"), slurp(dir_ / "straight/summary.json"));
  EXPECT_EQ(slurp(dir_ / "run/values.csv"), slurp(dir_ / "straight/values.csv"));
}

// Kill -9 in the middle of a run; only --resume (with the same config) or --force may continue.
TEST_F(Cli, KilledRunResumesToTheSameResult) {
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    if (::chdir(dir_.c_str()) != 0) std::_Exit(127);
    std::freopen("/dev/null", "w", stderr);
    ::execl(PEGASUS_CLI_PATH, PEGASUS_CLI_PATH, "dev", "count", "--steps", "40", "--step-ms", "25", "--scale",
            "0.1", "--out", "run", static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  // Wait until a few steps are checkpointed, then kill without warning.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < deadline) {
    if (exists("run.partial/checkpoint.json")) {
      try {
        if (json("run.partial/checkpoint.json")["values"].size() >= 5) break;
      } catch (const nlohmann::json::exception&) {
        ADD_FAILURE() << "checkpoint.json was half written";
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run finished before it was killed";
  EXPECT_TRUE(exists("run.partial"));
  EXPECT_FALSE(exists("run"));

  const Result refused = run("dev count --steps 40 --scale 0.1 --out run");
  EXPECT_EQ(refused.rc, 2);
  EXPECT_NE(refused.err.find("--resume"), std::string::npos) << refused.err;
  const Result different = run("dev count --steps 40 --scale 0.2 --out run --resume");
  EXPECT_EQ(different.rc, 2);
  EXPECT_NE(different.err.find("key 'scale' is 0.1 in the interrupted run"), std::string::npos)
      << different.err;
  EXPECT_TRUE(exists("run.partial/checkpoint.json")) << "a refused resume must not touch the interrupted run";

  const Result resumed = run("dev count --steps 40 --scale 0.1 --out run --resume --threads 3");
  EXPECT_EQ(resumed.rc, 0) << resumed.err;
  EXPECT_FALSE(exists("run.partial"));
  EXPECT_TRUE(json("run/run.json")["resumed"].get<bool>());
  ASSERT_EQ(run("dev count --steps 40 --scale 0.1 --out straight").rc, 0);
  EXPECT_EQ(slurp(dir_ / "run/summary.json"), slurp(dir_ / "straight/summary.json"));
  EXPECT_EQ(slurp(dir_ / "run/values.csv"), slurp(dir_ / "straight/values.csv"));
  EXPECT_EQ(slurp(dir_ / "run/values.svg"), slurp(dir_ / "straight/values.svg"));
}

TEST_F(Cli, ForceStartsAnInterruptedRunOver) {
  ASSERT_EQ(run("dev count --steps 6 --fail-at 3 --out run").rc, 1);
  const Result forced = run("dev count --steps 6 --out run --force");
  EXPECT_EQ(forced.rc, 0) << forced.err;
  EXPECT_FALSE(json("run/run.json")["resumed"].get<bool>());
  EXPECT_FALSE(exists("run.partial"));
}

TEST_F(Cli, NoProgressBarWhenStderrIsNotATerminal) {
  const Result r = run("dev count --steps 20 --out run");
  EXPECT_EQ(r.rc, 0);
  EXPECT_EQ(r.err, "");
}

}  // namespace
