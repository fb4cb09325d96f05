// The `pegasus` CLI against hostile input and a hostile machine (issue 16): each case is a reproduction from
// the issue, kept as a regression test.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "pegasus/runs/config.hpp"
#include "support/cli_runner.hpp"

namespace {

namespace fs = std::filesystem;
using pegasus::test_support::read_text;
using pegasus::test_support::run_shell;

class CliRobustness : public pegasus::test_support::TempDirTest {
 protected:
  // `pegasus ARGS` run inside dir_, stdout and stderr apart.
  struct Run {
    int code = -1;
    std::string out, err;
  };
  Run run(const std::string& args) const {
    const auto r = run_shell("cd '" + dir_.string() + "' && '" PEGASUS_CLI_PATH "' " + args +
                             " >out.txt 2>err.txt; echo $?");
    return {std::stoi(r.output), read_text(dir_ / "out.txt"), read_text(dir_ / "err.txt")};
  }
  // The same with no file allowed to grow past `blocks` 512-byte blocks (POSIX sh's ulimit -f), which
  // fails writes with EFBIG as a full disk fails them with ENOSPC. SIGXFSZ is ignored so that the write
  // fails instead of killing the process; stdout and stderr are pipes, which the limit does not touch.
  // `err` gets the line(s) starting "pegasus:".
  Run run_with_file_limit(const std::string& args, int blocks) const {
    const auto r =
        run_shell("cd '" + dir_.string() + "' && (trap '' XFSZ; ulimit -f " + std::to_string(blocks) +
                  "; exec '" PEGASUS_CLI_PATH "' " + args + ") 2>&1; echo \"exit=$?\"");
    Run result;
    std::size_t start = 0;
    while (start < r.output.size()) {
      const std::size_t end = r.output.find('\n', start);
      const std::string line = r.output.substr(start, end - start);
      if (line.starts_with("exit=")) result.code = std::stoi(line.substr(5));
      if (line.starts_with("pegasus:")) result.err += line + "\n";
      start = end == std::string::npos ? r.output.size() : end + 1;
    }
    return result;
  }
  // Exit 2, one line on stderr naming `expected`, and no run directory.
  void expect_bad_input(const std::string& args, const std::string& expected) const {
    SCOPED_TRACE(args);
    const Run r = run(args + " --quiet --out bad");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
    EXPECT_NE(r.err.find(expected), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "bad"));
    EXPECT_FALSE(fs::exists(dir_ / "bad.partial"));
  }
  bool no_temporaries() const {
    for (const auto& e : fs::recursive_directory_iterator(dir_))
      if (e.path().filename().string().ends_with(".tmp")) return false;
    return true;
  }
};

// Case 3: --threads is bounded; values past int were silently wrapped (4294967297 ran with 1 thread).
TEST_F(CliRobustness, ThreadsOutsideOneToTheDocumentedMaximumAreRefusedByName) {
  for (const char* threads : {"4294967297", "2147483648", "1025", "0"}) {
    expect_bad_input(std::string("horizon --threads ") + threads, "--threads");
  }
  const Run r = run("horizon --threads 4294967297 --quiet");
  EXPECT_NE(r.err.find("expected an integer in [1, 1024], got '4294967297'"), std::string::npos) << r.err;
  EXPECT_EQ(run("horizon --threads 1024 --quiet").code, 0);
}

// Case 7: each message names the option the user gave, not an internal one it feeds.
TEST_F(CliRobustness, MessagesNameTheOptionTheUserGave) {
  expect_bad_input("heli hover --reward.position-m 4.9e-324",
                   "--reward.position-m: expected a number >= 1e-06");
  // Weights whose rollouts overflow a double: U-hat was inf or NaN and training "succeeded" (exit 0).
  expect_bad_input("bicycle train --shaping-per-metre 1e308",
                   "--shaping-per-metre: expected a number in [0, 1000000000000]");
  expect_bad_input("bicycle train --fall-reward -1e308",
                   "--fall-reward: expected a number in [-1000000000000, 0]");
  expect_bad_input("heli maneuver --reward.alpha-pos 1e308",
                   "--reward.alpha-pos: expected a number in [0, 1000000000000]");
  // Sizes within int that only ended in std::bad_alloc (exit 3, a resumable-looking empty DIR.partial).
  expect_bad_input("bicycle train --optimizer.cmaes.population-size 2147483647",
                   "--optimizer.cmaes.population-size: expected an integer in [0, 100000]");
  expect_bad_input("bicycle train --optimizer.hill-climbing.proposals-per-iteration 100001",
                   "--optimizer.hill-climbing.proposals-per-iteration: expected an integer in [1, 100000]");
  // A ride command with no rides (it rode once and said 1).
  expect_bad_input("bicycle ride --rides 0", "--rides: expected an integer in [1, 1000000]");
  expect_bad_input("bicycle ride --goal-km 0.3 --goal-radius 300",
                   "goal_radius: expected less than the goal's distance (300 m, goal_km), got 300 m");
  // Moves that always go where intended: some policy never reaches the undiscounted world's goal (the message
  // was about a gamma the user never set).
  // A hover scenario shorter than one control step scored the start alone, and trained.
  expect_bad_input("heli hover --seconds 0.001",
                   "seconds: expected at least one control step (1 / control_rate_hz = 0.02 s), got 0.001");
  expect_bad_input("heli hover --control-rate-hz 0.001",
                   "--control-rate-hz: expected a number in [0.1, 1000]");
  expect_bad_input("shaping gridworld --intended 1", "--intended: expected a number in (0, 1), got '1'");
  expect_bad_input("pendulum train --optimizer.hill-climbing.initial-step 4.9e-324",
                   "--optimizer.hill-climbing.initial-step: 5e-324 breaks optimizer.hill_climbing.min_step");
  expect_bad_input("pendulum train --optimizer.hill-climbing.initial-step inf",
                   "--optimizer.hill-climbing.initial-step: expected a number in (0, inf), got 'inf'");
  expect_bad_input("horizon --epsilon inf", "--epsilon: expected a finite number > 0, got 'inf'");
  expect_bad_input("pendulum train --refine.hill-climbing.initial-step 1e-9",
                   "--refine.hill-climbing.initial-step");
  expect_bad_input("heli pipeline --seed 9223372036854775807",
                   "--seed: expected an integer in [0, 9223372036854775805]");
  fs::create_directories(dir_ / "folder.json");
  expect_bad_input("shaping audit --mdp folder.json --shaping folder.json",
                   "folder.json: expected a readable MDP file, got 'Is a directory'");
}

// Case 7: a tiny epsilon is a long horizon, not "gamma too close to 1".
TEST_F(CliRobustness, TheEpsilonHorizonOfATinyEpsilonIsFinite) {
  const Run r = run("horizon --epsilon 4.9e-324 --gamma 0.99 --rmax 1");
  ASSERT_EQ(r.code, 0) << r.err;
  // ceil(ln(eps (1 - gamma) / 2) / ln gamma) with ln(4.9e-324) = -744.44.
  const auto h = nlohmann::json::parse(r.out)["horizon"].get<std::int64_t>();
  EXPECT_EQ(h, static_cast<std::int64_t>(
                   std::ceil((std::log(4.9e-324) + std::log(0.01) - std::log(2.0)) / std::log(0.99))));
}

// Case 4: a run directory whose name is not UTF-8 works, resumes, and its config.toml loads again.
TEST_F(CliRobustness, ARunDirectoryNamedWithInvalidUtf8WorksResumesAndReloads) {
  const std::string name = "run\xff";
  const std::string out = " --out \"$(printf 'run\\377')\"";
  const Run failed = run("dev count --steps 5 --fail-at 2 --quiet" + out);
  EXPECT_EQ(failed.code, 1) << failed.err;
  EXPECT_NE(failed.err.find("run\\xFF.partial"), std::string::npos) << failed.err;
  const Run resumed = run("dev count --steps 5 --quiet --resume" + out);
  ASSERT_EQ(resumed.code, 0) << resumed.err;
  const auto provenance = nlohmann::json::parse(read_text(dir_ / name / "run.json"));
  EXPECT_EQ(provenance["argv"].back(), "run\\xFF");
  EXPECT_TRUE(provenance["resumed"].get<bool>());
  const Run again = run("dev count --quiet --config \"$(printf 'run\\377/config.toml')\" --out copy");
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(read_text(dir_ / "copy" / "summary.json"), read_text(dir_ / name / "summary.json"));
  // A missing file so named: one line, the byte escaped.
  const Run missing = run("horizon --config \"$(printf 'c\\377.toml')\"");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.err.find("c\\xFF.toml"), std::string::npos) << missing.err;
  EXPECT_EQ(missing.err.find('\xff'), std::string::npos) << missing.err;
}

// Case 2: a goal radius of 1e308 crashed the rides plot (Axis::fit); a goal circle that holds the start is
// now refused before anything rides (every ride counted as reached at 0 km).
TEST_F(CliRobustness, AGoalCircleAroundTheStartIsRefusedBeforeAnythingRides) {
  const Run r =
      run("bicycle train --scenarios 2 --horizon 50 --optimizer.gradient.max-iterations 1 --rides 1 "
          "--goal-radius 1e308 --quiet "
          "--out t");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("goal_radius: expected less than the goal's distance (1000 m, goal_km), got 1e+308 m"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "t"));
  EXPECT_FALSE(fs::exists(dir_ / "t.partial"));
}

// Case 8: a disk that fills (here: a file-size limit, which fails writes the same way) at the start leaves
// no DIR.partial to be mistaken for an interrupted run; exit 3, the environment's code.
TEST_F(CliRobustness, AFullDiskAtTheStartLeavesNothingAndExitsWithTheEnvironmentCode) {
  const Run full = run_with_file_limit("dev count --steps 3 --quiet --out run", 1);
  EXPECT_EQ(full.code, 3) << full.err;
  EXPECT_NE(full.err.find("config.toml"), std::string::npos) << full.err;
  EXPECT_EQ(full.err.find('\n'), full.err.size() - 1) << full.err;
  EXPECT_FALSE(fs::exists(dir_ / "run.partial"));
  EXPECT_FALSE(fs::exists(dir_ / "run"));
  EXPECT_TRUE(no_temporaries());
  EXPECT_EQ(run("dev count --steps 3 --quiet --out run").code, 0) << "the next plain run must not be refused";
}

// Issue 51, item 6: a full disk at the report step (here: a file-size limit, which fails writes as a full
// disk does) is the machine's refusal like any other: exit 3, one line, nothing committed, DIR.partial kept
// with no temporary, and --resume on a disk with room finishes the run with its report. A committed DIR
// always holds report.html.
TEST_F(CliRobustness, AFullDiskAtTheReportExitsWithTheEnvironmentCodeAndResumes) {
  // report.html embeds its script and data: far above 64 KiB, while the results are a few hundred bytes.
  const Run r = run_with_file_limit("dev count --steps 3 --quiet --out run", 64);
  EXPECT_EQ(r.code, 3) << r.err;
  EXPECT_NE(r.err.find("report.html"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("rerun with --resume"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "run"));
  EXPECT_TRUE(fs::exists(dir_ / "run.partial" / "summary.json"));
  EXPECT_TRUE(no_temporaries());
  const Run resumed = run("dev count --steps 3 --quiet --resume --out run");
  EXPECT_EQ(resumed.code, 0) << resumed.err;
  EXPECT_TRUE(fs::exists(dir_ / "run" / "report.html"));
  EXPECT_FALSE(fs::exists(dir_ / "run.partial"));
}

// Case 1, the loser's side: "partial results kept in DIR.partial" only when DIR.partial holds them.
TEST_F(CliRobustness, AFailureNamesAPartialRunOnlyWhenOneIsKept) {
  const Run failed = run("dev count --steps 4 --fail-at 1 --quiet --out run");
  EXPECT_EQ(failed.code, 1);
  EXPECT_NE(failed.err.find("partial results kept in run.partial"), std::string::npos) << failed.err;
  EXPECT_TRUE(fs::exists(dir_ / "run.partial" / "config.toml"));
}

}  // namespace
