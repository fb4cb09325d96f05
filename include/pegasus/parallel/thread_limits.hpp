#pragma once
// How many threads a pool may have (ThreadPool, `--threads`).

namespace pegasus {

// Far above any machine we run on, low enough that a typo (`--threads 5000`, issue 16) is refused by name
// instead of exhausting the process's address space; documented in the README.
inline constexpr int kMaxThreads = 1024;

}  // namespace pegasus
