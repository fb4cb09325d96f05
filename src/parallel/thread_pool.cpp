#include "pegasus/parallel/thread_pool.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <system_error>

#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/parallel/thread_limits.hpp"

namespace pegasus {

namespace {
thread_local int t_parallel_depth = 0;
struct ParallelRegion {
  ParallelRegion() { ++t_parallel_depth; }
  ~ParallelRegion() { --t_parallel_depth; }
};
}  // namespace

bool ThreadPool::inside_parallel_for() { return t_parallel_depth > 0; }

ThreadPool::ThreadPool(int threads) {
  if (threads < 1 || threads > kMaxThreads) {
    throw InputError(fmt::format("threads: expected an integer in [1, {}], got {}", kMaxThreads, threads));
  }
  workers_.reserve(static_cast<std::size_t>(threads - 1));
  try {
    for (int i = 1; i < threads; ++i) workers_.emplace_back([this] { worker_loop(); });
  } catch (const std::system_error& e) {
    // The destructor does not run for a half-made pool: the started workers are stopped here, or they
    // would wait on wake_ while it is destroyed (issue 16: a hang in pthread_cond_destroy).
    const std::size_t refused = workers_.size() + 2;  // the caller is thread 1
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& w : workers_) w.join();
    throw EnvironmentError(
        fmt::format("threads: the system refused to start thread {} of {} ({}); use fewer --threads", refused,
                    threads, e.what()));
  }
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  for (auto& w : workers_) w.join();
}

void ThreadPool::run_chunks(const Job& job) {
  for (;;) {
    const std::size_t begin = next_.fetch_add(job.grain, std::memory_order_relaxed);
    if (begin >= job.n || failed_.load(std::memory_order_relaxed)) return;
    const std::size_t end = std::min(job.n, begin + job.grain);
    try {
      throw_if_interrupted();
      (*job.body)(begin, end);
    } catch (...) {
      std::lock_guard lock(mutex_);
      if (!error_) error_ = std::current_exception();
      failed_ = true;
    }
  }
}

void ThreadPool::worker_loop() {
  std::size_t seen = 0;
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      // A worker that wakes after its call has returned finds no body: the call's chunks were all run, and
      // the caller, which waits only for the workers counted in active_, has moved on.
      if (job_.body == nullptr) continue;
      job = job_;
      ++active_;
    }
    run_chunks(job);
    {
      std::lock_guard lock(mutex_);
      --active_;
    }
    done_.notify_all();
  }
}

void ThreadPool::parallel_for_chunks(std::size_t n, std::size_t grain,
                                     const std::function<void(std::size_t, std::size_t)>& body) {
  if (n == 0) return;
  const ParallelRegion region;
  if (grain == 0) grain = std::max<std::size_t>(1, n / (8 * static_cast<std::size_t>(size())));
  if (workers_.empty() || n <= grain) {
    for (std::size_t b = 0; b < n; b += grain) {
      throw_if_interrupted();
      body(b, std::min(n, b + grain));
    }
    return;
  }
  const Job job{.body = &body, .n = n, .grain = grain};
  {
    // No worker is inside run_chunks here (the previous call waited for active_ == 0), so next_ and failed_
    // are reset before any worker can claim a chunk of this job.
    std::lock_guard lock(mutex_);
    job_ = job;
    next_ = 0;
    failed_ = false;
    error_ = nullptr;
    ++generation_;
  }
  wake_.notify_all();
  run_chunks(job);
  std::exception_ptr error;
  {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [&] { return active_ == 0; });
    job_ = Job{};
    error = error_;
    error_ = nullptr;
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace pegasus
