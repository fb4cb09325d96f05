#include "pegasus/runs/progress.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <thread>
#include <vector>

namespace pegasus {
namespace {

std::string contents(std::FILE* f) {
  std::fflush(f);
  std::rewind(f);
  std::string out;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, f)) > 0;) out.append(buffer, n);
  return out;
}

TEST(Progress, RenderShowsBarPercentCountAndEta) {
  EXPECT_EQ(Progress::render("fit", 12, 30, 2.0, 12, 10), "fit [####......] 40% 12/30 ETA 0:03");
  EXPECT_EQ(Progress::render("fit", 0, 30, 2.0, 0, 10), "fit [..........] 0% 0/30 ETA -:--");
  EXPECT_EQ(Progress::render("fit", 30, 30, 75.0, 30, 10), "fit [##########] 100% 30/30 in 1:15");
  // Resumed: 20 units were done before, 5 in 10 s now -> 5 left take 10 s.
  EXPECT_EQ(Progress::render("fit", 25, 30, 10.0, 5, 10), "fit [########..] 83% 25/30 ETA 0:10");
  EXPECT_EQ(Progress::render("x", 1, 2, 7200.0, 1, 2), "x [#.] 50% 1/2 ETA 2:00:00");
}

TEST(Progress, DisabledBarWritesNothing) {
  std::FILE* f = std::tmpfile();
  {
    Progress bar("work", 10, false, f, std::chrono::nanoseconds(0));
    for (int i = 0; i < 10; ++i) bar.advance();
    bar.finish();
    EXPECT_EQ(bar.done(), 10u);
  }
  EXPECT_EQ(contents(f), "");
  std::fclose(f);
}

TEST(Progress, EnabledBarRedrawsOneLineAndEndsIt) {
  std::FILE* f = std::tmpfile();
  {
    Progress bar("work", 4, true, f, std::chrono::nanoseconds(0));
    bar.advance(2);
    bar.advance(2);
  }  // the destructor finishes
  const std::string out = contents(f);
  EXPECT_EQ(out.front(), '\r');
  EXPECT_EQ(out.back(), '\n');
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1);
  EXPECT_NE(out.find("work [############............] 50% 2/4"), std::string::npos) << out;
  EXPECT_NE(out.find("100% 4/4 in 0:00\x1b[K\n"), std::string::npos) << out;
  std::fclose(f);
}

TEST(Progress, RedrawsAreRateLimited) {
  std::FILE* f = std::tmpfile();
  {
    Progress bar("work", 100000, true, f, std::chrono::hours(1));
    for (int i = 0; i < 100000; ++i) bar.advance();
  }
  const std::string out = contents(f);
  EXPECT_EQ(std::count(out.begin(), out.end(), '\r'), 2) << "the first advance and finish";
  std::fclose(f);
}

// Issue 48/53: where stderr is no terminal (a log, CI), long work prints plain lines a log keeps, and work
// shorter than the interval prints nothing.
TEST(Progress, PlainLinesComeOnePerIntervalAndOnlyForLongWork) {
  std::FILE* f = std::tmpfile();
  {
    Progress bar("work", 4, true, f, std::chrono::milliseconds(20), Progress::Style::kLines);
    bar.advance();  // before the first interval: nothing
    std::this_thread::sleep_for(std::chrono::milliseconds(40));
    bar.advance();
    bar.advance(2);  // within the interval of the line before
  }
  const std::string out = contents(f);
  EXPECT_EQ(out.find('\r'), std::string::npos) << out;
  EXPECT_EQ(out.find('\x1b'), std::string::npos) << out;
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 2) << out;
  EXPECT_EQ(out.substr(0, out.find('\n')).find("work [############............] 50% 2/4 ETA"), 0u) << out;
  EXPECT_NE(out.find("100% 4/4 in 0:00\n"), std::string::npos) << out;
  std::fclose(f);
  std::FILE* g = std::tmpfile();
  {
    Progress quick("work", 4, true, g, std::chrono::hours(1), Progress::Style::kLines);
    quick.advance(4);
  }
  EXPECT_EQ(contents(g), "");
  std::fclose(g);
}

// Issues 48/53: a ticker prints a status line on the clock where its stream is no terminal, however seldom
// the work moves, and nothing when disabled or when the work ends within the first interval.
TEST(ProgressTicker, PrintsStatusLinesOnTheClockUntilDestroyed) {
  std::FILE* f = std::tmpfile();
  EvaluationTally tally;
  // The ticker's thread is waited on by its own status calls, never by a sleep of a guessed length: on a busy
  // machine it may not run for a while. A line is written once the next status call has begun.
  std::atomic<int> calls = 0;
  const auto wait_for_calls = [&](int n) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (calls.load() < n && std::chrono::steady_clock::now() < deadline)
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    ASSERT_GE(calls.load(), n) << "the ticker did not tick within 60 s";
  };
  {
    const ProgressTicker ticker(
        "training",
        [&] {
          ++calls;
          return tally.text(1, 4);
        },
        true, f, std::chrono::milliseconds(20));
    EXPECT_TRUE(ticker.ticking());
    wait_for_calls(2);  // the first line, before any evaluation, is written
    const std::vector<double> values = {-3.5, -1.25, -2};
    tally.add(values);
    wait_for_calls(calls.load() + 2);  // a line begun after the add is written
  }
  const std::string out = contents(f);
  EXPECT_GE(std::count(out.begin(), out.end(), '\n'), 3) << out;
  // Each line ends with the time elapsed ("0:00 elapsed" unless the machine stalled the thread a second).
  EXPECT_EQ(out.find("training: 1 of 4 optimizer iterations done, 0 U-hat evaluations, best U-hat evaluated "
                     "(none yet), 0:0"),
            0u)
      << out;
  EXPECT_NE(out.find("training: 1 of 4 optimizer iterations done, 3 U-hat evaluations, best U-hat evaluated "
                     "-1.25, 0:0"),
            std::string::npos)
      << out;
  std::fclose(f);
  std::FILE* g = std::tmpfile();
  {
    const ProgressTicker off(
        "training", [] { return std::string("x"); }, false, g, std::chrono::milliseconds(1));
    EXPECT_FALSE(off.ticking());
    const ProgressTicker quick(
        "training", [] { return std::string("x"); }, true, g, std::chrono::hours(1));
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(contents(g), "");
  std::fclose(g);
}

TEST(ProgressTicker, IntervalComesFromTheEnvironmentWhenSet) {
  ::setenv("PEGASUS_PROGRESS_INTERVAL_S", "0.25", 1);
  EXPECT_EQ(ProgressTicker::default_interval(), std::chrono::milliseconds(250));
  ::setenv("PEGASUS_PROGRESS_INTERVAL_S", "nonsense", 1);
  EXPECT_EQ(ProgressTicker::default_interval(), std::chrono::seconds(15));
  ::unsetenv("PEGASUS_PROGRESS_INTERVAL_S");
  EXPECT_EQ(ProgressTicker::default_interval(), std::chrono::seconds(15));
}

TEST(Progress, AdvanceFromManyThreadsCountsEveryUnit) {
  std::FILE* f = std::tmpfile();
  Progress bar("work", 8 * 20000, true, f, std::chrono::microseconds(10));
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([&] {
      for (int i = 0; i < 20000; ++i) bar.advance();
    });
  }
  for (auto& t : threads) t.join();
  bar.finish();
  EXPECT_EQ(bar.done(), 8u * 20000u);
  EXPECT_NE(contents(f).find("100% 160000/160000"), std::string::npos);
  std::fclose(f);
}

}  // namespace
}  // namespace pegasus
