#pragma once
// Helpers for end-to-end tests that run the built `pegasus` CLI (PEGASUS_CLI_PATH).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

#include "support/scratch_dir.hpp"

namespace pegasus::test_support {

struct CliResult {
  int code = -1;       // exit code, -1 when the process did not exit normally
  std::string output;  // stdout and stderr together
};

// Runs a shell command line and collects its output (stdout and stderr together).
inline CliResult run_shell(const std::string& command) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  CliResult result;
  if (!pipe) return result;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe)) result.output += buffer;
  const int status = pclose(pipe);
  result.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// Runs `pegasus <args>` through the shell and collects its output.
inline CliResult run_pegasus(const std::string& args) {
  return run_shell(std::string(PEGASUS_CLI_PATH) + " " + args);
}

enum class KillOutcome { kKilled, kNoCheckpoint, kFinishedFirst };

// Starts `pegasus <args> --out OUT` in a child process, waits (at most 120 s) for
// OUT.partial/checkpoint.json, then sends it `signal_number` (SIGKILL: as a crash would; SIGINT: Ctrl-C): the
// kill/resume tests' way of interrupting a run after its first checkpoint. kKilled when the signal ended the
// run mid-way; kFinishedFirst when the run ended before it. `stderr_text`, when given, gets what the run said
// on stderr.
inline KillOutcome kill_pegasus_after_first_checkpoint(const std::string& args,
                                                       const std::filesystem::path& out,
                                                       int signal_number = SIGKILL,
                                                       std::string* stderr_text = nullptr) {
  const std::filesystem::path said = out.string() + ".stderr";
  const pid_t child = fork();
  if (child == 0) {
    const std::string command = std::string(PEGASUS_CLI_PATH) + " " + args + " --out " + out.string() +
                                " >/dev/null 2>" + (stderr_text ? said.string() : std::string("&1"));
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const std::filesystem::path checkpoint =
      std::filesystem::path(out.string() + ".partial") / "checkpoint.json";
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!std::filesystem::exists(checkpoint) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const bool checkpointed = std::filesystem::exists(checkpoint);
  kill(child, signal_number);
  int status = 0;
  waitpid(child, &status, 0);
  if (stderr_text) {
    std::ifstream in(said);
    *stderr_text = std::string(std::istreambuf_iterator<char>(in), {});
    std::filesystem::remove(said);
  }
  if (!checkpointed) return KillOutcome::kNoCheckpoint;
  return WIFSIGNALED(status) && WTERMSIG(status) == signal_number ? KillOutcome::kKilled
                                                                  : KillOutcome::kFinishedFirst;
}

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A fresh temporary directory per test, removed afterwards.
class TempDirTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = fresh_test_dir("pegasus-"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

}  // namespace pegasus::test_support
