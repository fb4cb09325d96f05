#pragma once
// The alternatives an error message lists: "expected linear or mlp, got ...".
#include <string>
#include <vector>

namespace pegasus {

// "a", "a or b", "a, b or c".
inline std::string or_list(const std::vector<std::string>& items) {
  std::string list;
  for (std::size_t i = 0; i < items.size(); ++i)
    list += (i == 0 ? "" : i + 1 == items.size() ? " or " : ", ") + items[i];
  return list;
}

}  // namespace pegasus
