#pragma once
// A request to stop long work early, for a caller that catches Ctrl-C instead of dying of it (the Python
// module: one long uhat or training call must stop within a second or two, issue 51). A signal handler sets
// it; the thread pools read it before each work item and then throw Interrupted, so a parallel_for stops
// within one item (one rollout) on every thread. Process-wide because a signal is; reading it never changes
// a result: an evaluation either completes as it always does or throws. The CLI does not use it (a signal
// ends the process there, keeping DIR.partial for --resume).
#include <atomic>
#include <stdexcept>

namespace pegasus {

class Interrupted : public std::runtime_error {
 public:
  Interrupted() : std::runtime_error("interrupted") {}
};

namespace detail {
inline std::atomic<bool> interrupt_requested{false};  // lock-free: safe to set from a signal handler
static_assert(std::atomic<bool>::is_always_lock_free);
}  // namespace detail

// Async-signal-safe.
inline void request_interrupt() noexcept {
  detail::interrupt_requested.store(true, std::memory_order_relaxed);
}
inline void clear_interrupt() noexcept {
  detail::interrupt_requested.store(false, std::memory_order_relaxed);
}
inline bool interrupt_requested() noexcept {
  return detail::interrupt_requested.load(std::memory_order_relaxed);
}
inline void throw_if_interrupted() {
  if (interrupt_requested()) throw Interrupted();
}

}  // namespace pegasus
