#pragma once
// Entries found by name that a build starts with and a program may add to at run time (MuJoCo policy classes,
// helicopter ground truths). Adding replaces an entry of the same name in its place, else appends, so the
// built-ins keep their order; every read copies under the lock, so what a caller holds stays valid while
// another thread registers. `Entry` has a `std::string name`.
#include <algorithm>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace pegasus {

template <class Entry>
class NamedRegistry {
 public:
  explicit NamedRegistry(std::vector<Entry> builtins) : entries_(std::move(builtins)) {}

  void add(Entry entry) {
    const std::lock_guard lock(mutex_);
    const auto it =
        std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == entry.name; });
    if (it != entries_.end())
      *it = std::move(entry);
    else
      entries_.push_back(std::move(entry));
  }
  std::optional<Entry> find(const std::string& name) const {
    const std::lock_guard lock(mutex_);
    const auto it =
        std::find_if(entries_.begin(), entries_.end(), [&](const Entry& e) { return e.name == name; });
    if (it == entries_.end()) return std::nullopt;
    return *it;
  }
  std::vector<Entry> entries() const {
    const std::lock_guard lock(mutex_);
    return entries_;
  }

 private:
  mutable std::mutex mutex_;
  std::vector<Entry> entries_;
};

}  // namespace pegasus
