// Walking a summary's keys, matching them against the key table (summary_keys_table.cpp) and the manual's
// page (include/pegasus/report/summary_keys.hpp).
#include "pegasus/report/summary_keys.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

namespace pegasus::report {

namespace {

using json = nlohmann::json;

// Deepest object the report opens: its keys at depth 2 are listed, an object below is one key.
constexpr std::size_t kDepth = 2;
// Longest array of scalars the report prints as one value.
constexpr std::size_t kShortArray = 6;

bool printable(const json& value) {
  if (value.is_object()) return false;
  if (!value.is_array()) return true;
  return value.size() <= kShortArray &&
         std::none_of(value.begin(), value.end(), [](const json& v) { return v.is_structured(); });
}

void visit(const json& value, std::vector<std::string>& path,
           const std::function<void(const std::vector<std::string>&, const json&, bool)>& f) {
  if (value.is_object() && !value.empty() && path.size() < kDepth) {
    for (const auto& [k, v] : value.items()) {
      path.push_back(k);
      visit(v, path, f);
      path.pop_back();
    }
    return;
  }
  if (!path.empty()) f(path, value, printable(value));
}

// The components of a pattern ("a.<b>.c"); a placeholder is one component.
std::vector<std::string_view> components(std::string_view pattern) {
  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    const std::size_t dot = pattern.find('.', start);
    parts.push_back(pattern.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) return parts;
    start = dot + 1;
  }
}

// One component against a pattern's: a placeholder <name> in it stands for any non-empty text
// ("rms_path_deviation_<ablation>_m").
bool component_matches(std::string_view pattern, std::string_view text) {
  const std::size_t open = pattern.find('<');
  if (open == std::string_view::npos) return pattern == text;
  const std::size_t close = pattern.find('>', open);
  if (close == std::string_view::npos) return pattern == text;
  const std::string_view head = pattern.substr(0, open), rest = pattern.substr(close + 1);
  if (text.substr(0, head.size()) != head) return false;
  for (std::size_t end = head.size() + 1; end <= text.size(); ++end)
    if (component_matches(rest, text.substr(end))) return true;
  return false;
}

bool matches(std::string_view pattern, const std::vector<std::string>& path) {
  const auto parts = components(pattern);
  if (parts.size() != path.size()) return false;
  for (std::size_t i = 0; i < parts.size(); ++i)
    if (!component_matches(parts[i], path[i])) return false;
  return true;
}

}  // namespace

void visit_summary_keys(const json& summary,
                        const std::function<void(const std::vector<std::string>&, const json&, bool)>& f) {
  std::vector<std::string> path;
  visit(summary, path, f);
}

const SummaryKey* describe_summary_key(std::string_view command, const std::vector<std::string>& path) {
  for (const SummaryKeyGroup& group : summary_key_groups()) {
    if (std::find(group.commands.begin(), group.commands.end(), command) == group.commands.end()) continue;
    for (const SummaryKey& key : group.keys)
      if (matches(key.pattern, path)) return &key;
  }
  return nullptr;
}

std::vector<std::string> undescribed_summary_keys(std::string_view command, const json& summary) {
  std::vector<std::string> missing;
  visit_summary_keys(summary, [&](const std::vector<std::string>& path, const json&, bool) {
    if (describe_summary_key(command, path) == nullptr)
      missing.push_back(fmt::format("{}", fmt::join(path, ".")));
  });
  return missing;
}

}  // namespace pegasus::report
