// The library when the machine says no or the numbers are extreme (issue 16, cases 2, 3, 8 and 9): a
// thread that cannot be started, a file that cannot grow, a plot of 1e308, a control line with NUL bytes.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>

#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/parallel/thread_limits.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/run_directory.hpp"
#include "pegasus/runs/svg_plot.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace {

namespace fs = std::filesystem;

// Runs `body` in a child process (it may lower the child's limits) and returns its exit code; a child that
// has not finished within `seconds` is killed by SIGALRM and counts as -1 (a hang).
template <class Body>
int in_child(Body body, unsigned seconds = 60) {
  const pid_t child = ::fork();
  if (child == 0) {
    ::alarm(seconds);
    std::_Exit(body());
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ThreadPoolLimits, MoreThanTheDocumentedMaximumIsBadInput) {
  EXPECT_NE(pegasus::test_support::input_error_message([] {
              pegasus::ThreadPool pool(pegasus::kMaxThreads + 1);
            }).find("threads: expected an integer in [1, 1024], got 1025"),
            std::string::npos);
  EXPECT_NE(pegasus::test_support::input_error_message([] { pegasus::ThreadPool pool(0); }), "(no error)");
}

// Case 3: with `ulimit -v` too low for the threads asked for, the constructor deadlocked with hundreds of
// threads alive. Now the threads it started are joined and EnvironmentError says how far it got.
TEST(ThreadPoolLimits, AThreadTheSystemRefusesIsAnEnvironmentErrorNotAHang) {
  if (std::getenv("PEGASUS_SANITIZED") != nullptr)
    GTEST_SKIP() << "AddressSanitizer needs far more address space";
  const int code = in_child([] {
    // Each thread reserves an 8 MiB stack: 512 MiB of address space runs out long before 1000 threads.
    const rlimit limit{512u << 20, 512u << 20};
    if (::setrlimit(RLIMIT_AS, &limit) != 0) return 10;
    try {
      pegasus::ThreadPool pool(1000);
      return 11;  // every thread started: the limit did not bite
    } catch (const pegasus::EnvironmentError& e) {
      return std::string(e.what()).find("use fewer --threads") != std::string::npos ? 0 : 12;
    } catch (...) {
      return 13;
    }
  });
  EXPECT_EQ(code, 0) << "-1: the constructor hung; 11: no thread was refused; 12, 13: wrong error";
}

// Case 8: a write that fails (the file-size limit fails it with EFBIG as a full disk does with ENOSPC)
// removes its temporary and is an EnvironmentError.
TEST(FullDisk, AFailedAtomicWriteLeavesNoTemporaryBehind) {
  const fs::path dir = fs::temp_directory_path() / ("pegasus-full-disk-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const int code = in_child([&] {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{100, 100};
    if (::setrlimit(RLIMIT_FSIZE, &limit) != 0) return 10;
    try {
      pegasus::write_file_atomic(dir / "big.txt", std::string(1000, 'x'));
      return 11;
    } catch (const pegasus::EnvironmentError&) {
    }
    // The run directory's first write (config.toml) failing leaves no DIR.partial.
    pegasus::ConfigSchema schema;
    schema.add_string("text", std::string(500, 'y'), "a long value");
    try {
      (void)pegasus::RunDirectory::open(dir / "run", schema);
      return 12;
    } catch (const pegasus::EnvironmentError&) {
    }
    return 0;
  });
  EXPECT_EQ(code, 0);
  EXPECT_FALSE(fs::exists(dir / "big.txt"));
  EXPECT_FALSE(fs::exists(pegasus::atomic_temp_path(dir / "big.txt")));
  EXPECT_FALSE(fs::exists(dir / "run.partial"));
  EXPECT_FALSE(fs::exists(dir / "run.lock"));
  fs::remove_all(dir);
}

// Case 2: Axis::fit took the range 1e308 - (-1e308) = inf and read the first of no ticks.
TEST(SvgPlotExtremes, HugeTinyAndEqualValuesGiveAFinitePlot) {
  const double big = std::numeric_limits<double>::max(), tiny = std::numeric_limits<double>::denorm_min();
  const std::vector<std::vector<double>> ys = {
      {-big, big}, {big, big}, {tiny, tiny}, {-1e308, 1e308}, {0, tiny}};
  for (const auto& y : ys) {
    SCOPED_TRACE(y[0]);
    pegasus::SvgPlot plot;
    plot.add_series({.name = "s", .x = {1, 2}, .y = y});
    plot.add_reference_line(1e308, "goal");
    const std::string svg = plot.render();
    EXPECT_NE(svg.find("</svg>"), std::string::npos);
    EXPECT_EQ(svg.find("nan"), std::string::npos) << "a coordinate is not a number";
    EXPECT_EQ(svg.find("inf"), std::string::npos) << "a coordinate is infinite";
  }
}

// Case 9: a NUL byte cut the stderr message and lost its newline, so two malformed lines shared one line.
TEST(ControlLoop, EachMalformedLineGetsExactlyOneStderrLineWhateverItsBytes) {
  class Fixed : public pegasus::heli::HeliController {
   public:
    pegasus::heli::Controls act(const pegasus::heli::LoggedState&, double,
                                pegasus::heli::ControllerMemory&) const override {
      return {0.1, 0, 0, 0};
    }
    pegasus::heli::SetPoint target(double) const override { return {}; }
  };
  const std::string good = "0.1,-0.2,-10,0.01,0.02,0.5,0.1,0,-0.1,0.01,0,0.02";
  std::string input =
      "\xEF\xBB\xBFtime,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate\r\n";
  input += std::string("0.1,0\0,0\n", 9);  // NUL inside a field
  input += "1,2\r3\r\n";                   // CR inside a field
  input += "0.02," + good + "\r\n";
  input += "\xff\xfe\n";
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  char *out_text = nullptr, *err_text = nullptr;
  std::size_t out_size = 0, err_size = 0;
  std::FILE* out = open_memstream(&out_text, &out_size);
  std::FILE* err = open_memstream(&err_text, &err_size);
  const auto stats = pegasus::heli::run_control_loop(Fixed(), {0, 0, 0, 0}, in, out, err);
  std::fclose(in);
  std::fclose(out);
  std::fclose(err);
  const std::string answers(out_text, out_size), errors(err_text, err_size);
  std::free(out_text);
  std::free(err_text);
  EXPECT_EQ(stats.lines, 5);
  EXPECT_EQ(stats.malformed, 3);
  // The header (behind a byte order mark) is answered with the header, not as a malformed line.
  EXPECT_EQ(answers.substr(0, answers.find('\n')), "a1,a2,a3,a4");
  EXPECT_EQ(std::count(answers.begin(), answers.end(), '\n'), 5);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 3) << errors;
  EXPECT_NE(errors.find("stdin:2: field 2: expected a finite number, got '0\\x00'"), std::string::npos)
      << errors;
  EXPECT_NE(errors.find("stdin:3: field 2: expected a finite number, got '2\\x0D3'"), std::string::npos)
      << errors;
  EXPECT_NE(errors.find("stdin:5: field 1: expected a finite number, got '\\xFF\\xFE'"), std::string::npos)
      << errors;
  EXPECT_EQ(errors.find('\0'), std::string::npos);
  EXPECT_EQ(errors.find('\r'), std::string::npos);
}

}  // namespace
