#pragma once
// A one-line progress bar with ETA on stderr, for long work:
//   label [##########..........] 45% 12/30 ETA 0:03
// It draws only when enabled (by default: not --quiet), at most ~10 times a second; otherwise every call is
// a cheap atomic add. On stderr that is not a terminal (a log file, CI, a pipe) it prints plain lines
// instead of redrawing one: the first after kLineInterval, then one per kLineInterval, and the final state
// when any was printed, so work shorter than that prints nothing. advance() may be called from any thread.
// Time is used for the display only, never in results.
//
//   Progress bar("scenarios", m, Progress::default_enabled(quiet));
//   pool.parallel_for(m, [&](std::size_t i) { work(i); bar.advance(); });
//   bar.finish();
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <mutex>
#include <span>
#include <string>
#include <thread>

#include "pegasus/parallel/execution_context.hpp"

namespace pegasus {

class Progress {
 public:
  using Clock = std::chrono::steady_clock;

  enum class Style {
    kAuto,   // plain lines on stderr that is not a terminal (at least kLineInterval apart), else the bar
    kBar,    // one line redrawn in place
    kLines,  // plain lines at least min_interval apart, the first one min_interval after the start
  };
  // `out` is where the bar is drawn (stderr by default); `min_interval` the least time between redraws.
  Progress(std::string label, std::uint64_t total, bool enabled, std::FILE* out = stderr,
           Clock::duration min_interval = std::chrono::milliseconds(100), Style style = Style::kAuto);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Between two plain lines (stderr not a terminal).
  static constexpr Clock::duration kLineInterval = std::chrono::seconds(10);

  // True when not quiet, on the first of `ranks` (parallel/mpi.hpp: every rank of a
  // job runs the same work, so one draws; a run that only this process makes draws here).
  static bool default_enabled(bool quiet, const mpi::Communicator& ranks = mpi::Communicator::job());

  // Counts k more units done.
  void advance(std::uint64_t k = 1);
  // Counts k units as already done (a resumed run) without counting them in the speed used for the ETA.
  void skip(std::uint64_t k);
  // Draws the final state and ends the line; idempotent (the destructor calls it).
  void finish();

  std::uint64_t done() const { return done_.load(std::memory_order_relaxed); }
  std::uint64_t total() const { return total_; }
  bool enabled() const { return enabled_; }

  // The text of one line, e.g. render("fit", 12, 30, 2.0, 10) -> "fit [########............] 40% 12/30 ETA
  // 0:03". `done_this_run` units took `elapsed_s` seconds; the ETA is unknown ("ETA -:--") until one is done.
  static std::string render(const std::string& label, std::uint64_t done, std::uint64_t total,
                            double elapsed_s, std::uint64_t done_this_run, int width = 24);

 private:
  void draw(bool final_line);

  std::string label_;
  std::uint64_t total_;
  bool enabled_;
  std::FILE* out_;
  Clock::duration min_interval_;
  Clock::time_point start_;
  std::atomic<std::uint64_t> done_{0};
  std::atomic<std::uint64_t> skipped_{0};
  std::atomic<Clock::rep> last_draw_;
  std::mutex draw_mutex_;
  bool finished_ = false;
  bool lines_ = false;      // plain lines: stderr that is not a terminal
  bool drew_line_ = false;  // a plain line was printed
};

// The U-hat evaluations an optimizer has run and the best value among them, counted from any thread, for a
// ticker's line.
class EvaluationTally {
 public:
  void add(std::span<const double> values);
  // "3 of 40 optimizer iterations done, 212 U-hat evaluations, best U-hat evaluated -981.2"
  std::string text(std::uint64_t iterations, std::uint64_t total_iterations) const;

 private:
  mutable std::mutex mutex_;
  std::uint64_t evaluations_ = 0;
  double best_ = -std::numeric_limits<double>::infinity();
};

// What a long command is doing now ("calibrating the noise"), set by the work and read by a ticker's thread.
class ProgressStatus {
 public:
  explicit ProgressStatus(std::string text = {}) : text_(std::move(text)) {}
  void set(std::string text) {
    std::lock_guard lock(mutex_);
    text_ = std::move(text);
  }
  std::string text() const {
    std::lock_guard lock(mutex_);
    return text_;
  }

 private:
  mutable std::mutex mutex_;
  std::string text_;
};

// Plain status lines on a clock, for work whose units come too seldom for a bar to move (one optimizer
// iteration of hover training on a 25 Hz model took minutes; issues 48 and 53): where `out` is no terminal
// (a log file, CI, a pipe), a thread prints "label: status(), m:ss elapsed" every `interval`, the first one
// interval after the start, until the ticker is destroyed. Nothing on a terminal (the bars draw there) or
// when disabled (--quiet). status() is called from that thread: it must be safe against the work's own.
// Display only: nothing it reads or prints reaches a result.
//
//   ProgressTicker ticker("hover", [&] { return state.text(); }, Progress::default_enabled(quiet));
class ProgressTicker {
 public:
  using Clock = std::chrono::steady_clock;
  ProgressTicker(std::string label, std::function<std::string()> status, bool enabled,
                 std::FILE* out = stderr, Clock::duration interval = default_interval());
  ~ProgressTicker();
  ProgressTicker(const ProgressTicker&) = delete;
  ProgressTicker& operator=(const ProgressTicker&) = delete;

  // 15 s, or PEGASUS_PROGRESS_INTERVAL_S seconds when that is set to a positive number (tests use a short
  // one).
  static Clock::duration default_interval();
  bool ticking() const { return thread_.joinable(); }

 private:
  void run();

  std::string label_;
  std::function<std::string()> status_;
  std::FILE* out_;
  Clock::duration interval_;
  Clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable stop_signal_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace pegasus
