#pragma once
// A fixed pool of worker threads. Work is split into indexed tasks; each task writes only its own output
// slot, and every reduction happens afterwards in index order, so results never depend on the number of
// threads (ARCHITECTURE.md, determinism rule 2).
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "pegasus/parallel/interrupt.hpp"

namespace pegasus {

class ThreadPool {
 public:
  // threads >= 1; the calling thread is one of them, so ThreadPool(1) starts no worker.
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()) + 1; }

  // True while the calling thread is inside a parallel_for of any pool (the caller runs chunks too). MPI
  // collectives are not entered there: other ranks' threads would not enter them in the same order.
  static bool inside_parallel_for();

  // Runs body(begin, end) over [0, n) in chunks of at most `grain` indices, on all threads; returns when
  // every chunk has run. grain = 0 picks about 8 chunks per thread. The first exception thrown by a chunk
  // is rethrown here; Interrupted when an interrupt was requested before a chunk.
  void parallel_for_chunks(std::size_t n, std::size_t grain,
                           const std::function<void(std::size_t, std::size_t)>& body);

  // Runs body(i) for every i in [0, n). Throws Interrupted (parallel/interrupt.hpp) before an item when an
  // interrupt was requested.
  template <class Body>
  void parallel_for(std::size_t n, Body&& body, std::size_t grain = 0) {
    parallel_for_chunks(n, grain, [&body](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        throw_if_interrupted();
        body(i);
      }
    });
  }

 private:
  void worker_loop();
  // One parallel_for's work, copied by each worker under the mutex when it joins, so that a worker that wakes
  // late never reads the fields while the next call rewrites them.
  struct Job {
    const std::function<void(std::size_t, std::size_t)>* body = nullptr;
    std::size_t n = 0, grain = 1;
  };
  void run_chunks(const Job& job);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  Job job_;  // body null between calls
  std::atomic<std::size_t> next_{0};
  std::atomic<bool> failed_{false};
  std::size_t generation_ = 0;
  int active_ = 0;
  bool stop_ = false;
  std::exception_ptr error_;
};

// A pool for one call: the caller's `pool`, not owned by the returned pointer, or when there is none a new
// pool of `threads` that the pointer owns.
inline std::shared_ptr<ThreadPool> borrow_pool(ThreadPool* pool, int threads) {
  if (pool != nullptr) return std::shared_ptr<ThreadPool>(std::shared_ptr<ThreadPool>(), pool);
  return std::make_shared<ThreadPool>(threads);
}

}  // namespace pegasus
