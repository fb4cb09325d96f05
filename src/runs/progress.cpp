#include "pegasus/runs/progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace pegasus {

namespace {

std::string clock_text(double seconds) {
  const auto s = static_cast<std::uint64_t>(std::llround(std::max(0.0, seconds)));
  if (s >= 3600) return fmt::format("{}:{:02}:{:02}", s / 3600, s / 60 % 60, s % 60);
  return fmt::format("{}:{:02}", s / 60, s % 60);
}

}  // namespace

Progress::Progress(std::string label, std::uint64_t total, bool enabled, std::FILE* out,
                   Clock::duration min_interval, Style style)
    : label_(std::move(label)),
      total_(total),
      enabled_(enabled && out != nullptr),
      out_(out),
      min_interval_(min_interval),
      start_(Clock::now()),
      last_draw_(start_.time_since_epoch().count() - min_interval.count()) {
  // A log file or a pipe gets lines it can keep, not a redrawn bar; the first one interval after the start.
  const bool auto_lines = style == Style::kAuto && out_ == stderr && ::isatty(STDERR_FILENO) != 1;
  lines_ = enabled_ && (style == Style::kLines || auto_lines);
  if (auto_lines) min_interval_ = std::max(min_interval_, kLineInterval);
  if (lines_) last_draw_ = start_.time_since_epoch().count();
}

Progress::~Progress() { finish(); }

bool Progress::default_enabled(bool quiet, const mpi::Communicator& ranks) {
  return !quiet && ranks.rank() == 0;
}

void Progress::advance(std::uint64_t k) {
  done_.fetch_add(k, std::memory_order_relaxed);
  if (!enabled_) return;
  const Clock::rep now = Clock::now().time_since_epoch().count();
  Clock::rep last = last_draw_.load(std::memory_order_relaxed);
  // One thread wins the right to draw this interval; the others return at once.
  if (now - last < min_interval_.count() ||
      !last_draw_.compare_exchange_strong(last, now, std::memory_order_relaxed)) {
    return;
  }
  std::unique_lock lock(draw_mutex_, std::try_to_lock);
  if (lock.owns_lock() && !finished_) draw(false);
}

void Progress::skip(std::uint64_t k) {
  skipped_.fetch_add(k, std::memory_order_relaxed);
  done_.fetch_add(k, std::memory_order_relaxed);
}

void Progress::finish() {
  std::lock_guard lock(draw_mutex_);
  if (finished_) return;
  finished_ = true;
  if (enabled_ && (!lines_ || drew_line_)) draw(true);
}

void Progress::draw(bool final_line) {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  const std::uint64_t done = done_.load(std::memory_order_relaxed);
  const std::string line =
      render(label_, done, total_, elapsed, done - std::min(done, skipped_.load(std::memory_order_relaxed)));
  if (lines_) {
    std::fprintf(out_, "%s\n", line.c_str());
    drew_line_ = true;
  } else {
    // \r returns to the line start, \x1b[K clears what a longer previous line left.
    std::fprintf(out_, "\r%s\x1b[K%s", line.c_str(), final_line ? "\n" : "");
  }
  std::fflush(out_);
}

std::string Progress::render(const std::string& label, std::uint64_t done, std::uint64_t total,
                             double elapsed_s, std::uint64_t done_this_run, int width) {
  const double fraction =
      total == 0 ? 1.0 : std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
  const int filled = static_cast<int>(fraction * width);
  std::string eta = "ETA -:--";
  if (done >= total) {
    eta = "in " + clock_text(elapsed_s);
  } else if (done_this_run > 0) {
    eta = "ETA " +
          clock_text(elapsed_s / static_cast<double>(done_this_run) * static_cast<double>(total - done));
  }
  return fmt::format("{} [{}{}] {}% {}/{} {}", label, std::string(filled, '#'),
                     std::string(width - filled, '.'), static_cast<int>(fraction * 100), done, total, eta);
}

void EvaluationTally::add(std::span<const double> values) {
  std::lock_guard lock(mutex_);
  evaluations_ += values.size();
  for (const double v : values)
    if (v > best_) best_ = v;
}

std::string EvaluationTally::text(std::uint64_t iterations, std::uint64_t total_iterations) const {
  std::lock_guard lock(mutex_);
  return fmt::format("{} of {} optimizer iterations done, {} U-hat evaluations, best U-hat evaluated {}",
                     iterations, total_iterations, evaluations_,
                     evaluations_ == 0 ? std::string("(none yet)") : fmt::format("{:.6g}", best_));
}

ProgressTicker::ProgressTicker(std::string label, std::function<std::string()> status, bool enabled,
                               std::FILE* out, Clock::duration interval)
    : label_(std::move(label)),
      status_(std::move(status)),
      out_(out),
      interval_(interval),
      start_(Clock::now()) {
  if (enabled && out_ != nullptr && ::isatty(::fileno(out_)) != 1) thread_ = std::thread([this] { run(); });
}

ProgressTicker::~ProgressTicker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  stop_signal_.notify_all();
  if (thread_.joinable()) thread_.join();
}

ProgressTicker::Clock::duration ProgressTicker::default_interval() {
  if (const char* v = std::getenv("PEGASUS_PROGRESS_INTERVAL_S"); v != nullptr) {
    char* end = nullptr;
    const double s = std::strtod(v, &end);
    if (end != v && s > 0 && s <= 3600)
      return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
  return std::chrono::seconds(15);
}

void ProgressTicker::run() {
  std::unique_lock lock(mutex_);
  for (auto next = start_ + interval_;; next += interval_) {
    if (stop_signal_.wait_until(lock, next, [this] { return stop_; })) return;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    std::fprintf(out_, "%s: %s, %s elapsed\n", label_.c_str(), status_().c_str(),
                 clock_text(elapsed).c_str());
    std::fflush(out_);
  }
}

}  // namespace pegasus
