#include "pegasus/runs/run_directory.hpp"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <thread>

#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/sha256.hpp"
#include "support/input_error.hpp"
#include "support/scratch_dir.hpp"

namespace pegasus {

using test_support::input_error_message;
namespace {

namespace fs = std::filesystem;

ConfigSchema schema(double gamma = 0.9, std::int64_t threads = 2) {
  ConfigSchema s;
  s.add_double("gamma", 0.9, "discount").range(0, 1);
  s.add_int("threads", 2, "threads").min(1).affects_results(false);
  s.set("gamma", gamma);
  s.set("threads", threads);
  return s;
}

// schema() with an input file `train` set to `log`, and a string that names no file.
ConfigSchema schema_with_log(const fs::path& log) {
  ConfigSchema s = schema();
  s.add_string("train", "", "training log").input_file();
  s.add_string("note", "", "not a file");
  s.set("train", log.string());
  return s;
}

TEST(RunDirectory, WritesIntoStagingAndCommitRenames) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  RunDirectory run = RunDirectory::open(root / "out", schema());
  EXPECT_EQ(run.path(), root / "out.partial");
  EXPECT_EQ(run.final_path(), root / "out");
  EXPECT_FALSE(run.resumed());
  EXPECT_TRUE(fs::is_regular_file(root / "out.partial" / "config.toml"));
  run.write_json("summary.json", {{"x", 0.1}});
  run.write_text("plots/a.svg", "<svg/>");
  CsvWriter csv({"a"});
  csv.add_row({1.5});
  run.write_csv("series.csv", csv);
  EXPECT_FALSE(fs::exists(root / "out"));
  run.commit();
  EXPECT_FALSE(fs::exists(root / "out.partial"));
  EXPECT_EQ(read_json_file(root / "out" / "summary.json")["x"], 0.1);
  EXPECT_EQ(read_file(root / "out" / "plots" / "a.svg"), "<svg/>");
  EXPECT_EQ(read_file(root / "out" / "series.csv"), "a\n1.5\n");
  ConfigSchema back = schema(0.5);
  back.load_toml_file(root / "out" / "config.toml");
  EXPECT_EQ(back.get_double("gamma"), 0.9);
}

TEST(RunDirectory, TrailingSlashNamesTheSameDirectory) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  RunDirectory run = RunDirectory::open((root / "out").string() + "/", schema());
  EXPECT_EQ(run.path(), root / "out.partial");
}

TEST(RunDirectory, RefusesAnExistingDirectoryAndCreatesNothing) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  fs::create_directory(root / "out");
  EXPECT_EQ(input_error_message([&] { RunDirectory::open(root / "out", schema()); }),
            "--out: '" + (root / "out").string() + "' already exists (use --force to replace it)");
  EXPECT_FALSE(fs::exists(root / "out.partial"));
  EXPECT_NE(input_error_message([&] {
              RunDirectory::open(root / "out", schema(), {.resume = true});
            }).find("already exists"),
            std::string::npos);
  EXPECT_FALSE(fs::exists(root / "out.partial"));
}

TEST(RunDirectory, ForceReplacesTheOldDirectoryOnlyAtCommit) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  fs::create_directory(root / "out");
  write_file_atomic(root / "out" / "old.txt", "old");
  RunDirectory run = RunDirectory::open(root / "out", schema(), {.force = true});
  EXPECT_TRUE(fs::exists(root / "out" / "old.txt"));  // a failed run keeps the old results
  run.write_text("new.txt", "new");
  run.commit();
  EXPECT_FALSE(fs::exists(root / "out" / "old.txt"));
  EXPECT_EQ(read_file(root / "out" / "new.txt"), "new");
  EXPECT_FALSE(fs::exists(root / "out.partial"));
}

TEST(RunDirectory, AnInterruptedRunNeedsResumeOrForce) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  {
    RunDirectory run = RunDirectory::open(root / "out", schema());
    run.save_checkpoint({{"next", 3}});
  }  // the process "dies": no commit
  ASSERT_TRUE(fs::exists(root / "out.partial"));
  const std::string refused = input_error_message([&] { RunDirectory::open(root / "out", schema()); });
  EXPECT_NE(refused.find("holds an interrupted run (use --resume to continue it or --force to start over)"),
            std::string::npos)
      << refused;

  {  // a run, which holds DIR until it ends
    RunDirectory resumed =
        RunDirectory::open(root / "out", schema(0.9, 8), {.resume = true});  // threads may differ
    EXPECT_TRUE(resumed.resumed());
    ASSERT_TRUE(resumed.load_checkpoint().has_value());
    EXPECT_EQ((*resumed.load_checkpoint())["next"], 3);
    ConfigSchema stored = schema();
    stored.load_toml_file(resumed.path() / "config.toml");
    EXPECT_EQ(stored.get_int("threads"), 8);  // the config of the run that finishes it
  }

  RunDirectory fresh = RunDirectory::open(root / "out", schema(), {.force = true});
  EXPECT_FALSE(fresh.resumed());
  EXPECT_FALSE(fresh.load_checkpoint().has_value());
}

TEST(RunDirectory, ResumeRefusesADifferentConfigNamingTheKey) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  { RunDirectory::open(root / "out", schema(0.9)).save_checkpoint({{"next", 1}}); }
  const std::string message =
      input_error_message([&] { RunDirectory::open(root / "out", schema(0.95), {.resume = true}); });
  EXPECT_EQ(message.rfind("--resume: key 'gamma' is 0.9 in the interrupted run (", 0), 0u) << message;
  EXPECT_NE(message.find("but 0.95 now"), std::string::npos) << message;
  // The interrupted run is untouched.
  EXPECT_TRUE(fs::exists(root / "out.partial" / "checkpoint.json"));
}

// A run continued from its checkpoint was computed from its input files as they were when it began: a file
// whose bytes changed since (a log rewritten, a vehicle file edited) is refused by name, as a changed setting
// is; the same bytes (touched, or copied back) resume.
TEST(RunDirectory, ResumeRefusesAnInputFileWhoseContentsChanged) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  const fs::path log = root / "train.csv";
  write_file_atomic(log, "time,x\n0,1\n");
  const auto with_log = [&] { return schema_with_log(log); };
  { RunDirectory::open(root / "out", with_log()).save_checkpoint({{"next", 1}}); }
  EXPECT_TRUE(fs::exists(root / "out.partial" / "inputs.json"));
  write_file_atomic(log, "time,x\n0,2\n");
  const std::string message =
      input_error_message([&] { RunDirectory::open(root / "out", with_log(), {.resume = true}); });
  EXPECT_EQ(message,
            "--resume: " + log.string() +
                " (--train) changed since the interrupted run began; use the same inputs, or --force "
                "to start over");
  EXPECT_TRUE(fs::exists(root / "out.partial" / "checkpoint.json"));  // untouched
  fs::remove(log);
  EXPECT_NE(input_error_message([&] {
              RunDirectory::open(root / "out", with_log(), {.resume = true});
            }).find("(--train) cannot be read since"),
            std::string::npos);
  write_file_atomic(log, "time,x\n0,1\n");  // the bytes it began with
  RunDirectory resumed = RunDirectory::open(root / "out", with_log(), {.resume = true});
  EXPECT_TRUE(resumed.resumed());
  // A hand-edited inputs.json is one line too, not a crash.
  { RunDirectory::open(root / "edited", with_log()).save_checkpoint({{"next", 1}}); }
  write_file_atomic(root / "edited.partial" / "inputs.json", R"({"train": 7})");
  EXPECT_NE(input_error_message([&] {
              RunDirectory::open(root / "edited", with_log(), {.resume = true});
            }).find("inputs.json: train: expected the object this program writes"),
            std::string::npos);
  // Without input files there is nothing to record.
  { RunDirectory::open(root / "plain", schema()).save_checkpoint({{"next", 1}}); }
  EXPECT_FALSE(fs::exists(root / "plain.partial" / "inputs.json"));
}

// inputs.json carries its format and version; one written before (the object of files alone, version 0)
// still resumes and still catches a changed file, and a version this build does not know is one line.
TEST(RunDirectory, InputsFileIsVersionedAndAnOldOneStillResumes) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  const fs::path log = root / "train.csv";
  write_file_atomic(log, "time,x\n0,1\n");
  const auto with_log = [&] { return schema_with_log(log); };
  { RunDirectory::open(root / "out", with_log()).save_checkpoint({{"next", 1}}); }
  const fs::path inputs = root / "out.partial" / "inputs.json";
  nlohmann::json current = read_json_file(inputs);
  EXPECT_EQ(current.at("format"), "pegasus.run.inputs");
  EXPECT_EQ(current.at("version"), 1);
  write_file_atomic(inputs, current.at("files").dump());  // as version 0 wrote it
  EXPECT_TRUE(RunDirectory::open(root / "out", with_log(), {.resume = true}).resumed());
  write_file_atomic(log, "time,x\n0,2\n");
  EXPECT_NE(input_error_message([&] {
              RunDirectory::open(root / "out", with_log(), {.resume = true});
            }).find("(--train) changed since the interrupted run began"),
            std::string::npos);
  write_file_atomic(log, "time,x\n0,1\n");
  current["version"] = 2;
  write_file_atomic(inputs, current.dump());
  EXPECT_EQ(input_error_message([&] { RunDirectory::open(root / "out", with_log(), {.resume = true}); }),
            inputs.string() + ": version: expected 1, got 2");
  EXPECT_FALSE(fs::exists(root / "plain.partial" / "inputs.json"));
}

// Each file of a list of input files (heli identify --noise-check-logs) is recorded and checked alike.
TEST(RunDirectory, ResumeRefusesAChangedFileOfAListOfInputFiles) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  const fs::path first = root / "a.csv", second = root / "b.csv";
  write_file_atomic(first, "time,x\n0,1\n");
  write_file_atomic(second, "time,x\n0,2\n");
  const auto with_logs = [&] {
    ConfigSchema s = schema();
    s.add_string_list("logs", {}, "more logs").input_file();
    s.set("logs", std::vector<std::string>{first.string(), second.string()});
    return s;
  };
  { RunDirectory::open(root / "out", with_logs()).save_checkpoint({{"next", 1}}); }
  const auto recorded = read_json_file(root / "out.partial" / "inputs.json");
  EXPECT_EQ(recorded.at("files").at("logs[1]").at("file"), second.string());
  EXPECT_EQ(recorded.at("files").at("logs[1]").at("sha256"), file_sha256(second));
  write_file_atomic(second, "time,x\n0,3\n");
  EXPECT_EQ(input_error_message([&] { RunDirectory::open(root / "out", with_logs(), {.resume = true}); }),
            "--resume: " + second.string() +
                " (--logs) changed since the interrupted run began; use the same inputs, or --force to start "
                "over");
  write_file_atomic(second, "time,x\n0,2\n");
  EXPECT_TRUE(RunDirectory::open(root / "out", with_logs(), {.resume = true}).resumed());
}

TEST(RunDirectory, ResumeWithoutAnInterruptedRunStartsFresh) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  RunDirectory run = RunDirectory::open(root / "out", schema(), {.resume = true});
  EXPECT_FALSE(run.resumed());
  EXPECT_FALSE(run.load_checkpoint().has_value());
}

TEST(RunDirectory, AbandonRemovesOnlyWhatThisProcessCreated) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  RunDirectory run = RunDirectory::open(root / "out", schema());
  run.abandon();
  EXPECT_FALSE(fs::exists(root / "out.partial"));
  { RunDirectory::open(root / "out", schema()).save_checkpoint({{"next", 1}}); }
  RunDirectory resumed = RunDirectory::open(root / "out", schema(), {.resume = true});
  resumed.abandon();
  EXPECT_TRUE(fs::exists(root / "out.partial" / "checkpoint.json"));
}

TEST(RunDirectory, WritesMustStayInsideTheDirectory) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  RunDirectory run = RunDirectory::open(root / "out", schema());
  EXPECT_THROW(run.write_text("../escape.txt", "x"), std::logic_error);
  EXPECT_THROW(run.write_text("/tmp/escape.txt", "x"), std::logic_error);
  EXPECT_THROW(run.write_text("a/../../escape.txt", "x"), std::logic_error);
}

TEST(RunDirectory, ResumeRemovesTemporariesOfInterruptedWrites) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  { RunDirectory::open(root / "out", schema()); }
  write_file_atomic(root / "out.partial" / ".checkpoint.json.tmp", "half");
  RunDirectory run = RunDirectory::open(root / "out", schema(), {.resume = true});
  EXPECT_FALSE(fs::exists(root / "out.partial" / ".checkpoint.json.tmp"));
}

// A child process rewrites a file in a loop, alternating two large contents, and is killed with SIGKILL at
// varying moments: the file must always be one of the two contents, never a mix or a truncation.
TEST(AtomicFile, SigkillNeverLeavesAHalfWrittenFile) {
  const fs::path root = test_support::fresh_test_dir("pegasus_runs_");
  const fs::path file = root / "data.txt";
  const std::string a(1 << 20, 'a'), b(1 << 20, 'b');
  write_file_atomic(file, a);
  for (int trial = 0; trial < 8; ++trial) {
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      for (int i = 0;; ++i) write_file_atomic(file, i % 2 ? a : b);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(3 + 7 * trial));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));
    const std::string content = read_file(file);
    ASSERT_TRUE(content == a || content == b) << "trial " << trial << ": " << content.size() << " bytes";
  }
}

}  // namespace
}  // namespace pegasus
