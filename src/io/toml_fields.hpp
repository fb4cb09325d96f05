#pragma once
// The fields of a TOML file a user wrote (a vehicle file, a MuJoCo task): what io/json_input's readers are
// for JSON. Every failure is one InputError line, `FILE:LINE: FIELD: expected X, got V` (without LINE where
// the node has none), and an unknown key names the closest known one. Private to the libraries, like toml++.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "toml_input.hpp"

namespace pegasus {

// Levenshtein distance: the insertions, deletions and substitutions that turn a into b.
std::size_t edit_distance(std::string_view a, std::string_view b);
// " (did you mean 'K'?)" for the known key K closest to an unknown `name` (within about a third of its
// letters, or one it cuts short: "hold" for "hold_steps"), else empty.
template <typename Keys>
std::string did_you_mean(std::string_view name, const Keys& known) {
  std::string hint;
  std::size_t best = std::max<std::size_t>(2, name.size() / 3) + 1;
  for (const auto& key : known) {
    const std::string_view k(key);
    const bool cut_short = name.size() >= 3 && k.starts_with(name);
    if (const std::size_t d = cut_short ? 1 : edit_distance(name, k); d < best) {
      best = d;
      hint = " (did you mean '" + std::string(k) + "'?)";
    }
  }
  return hint;
}

class TomlFields {
 public:
  explicit TomlFields(std::string file) : file_(std::move(file)) {}
  const std::string& file() const { return file_; }

  // "FILE:LINE: FIELD: WHAT" (LINE from the node, when given and known), as one printable line.
  [[noreturn]] void fail(const toml::node* node, std::string_view field, std::string_view what) const;
  // What a message says the user wrote: a string quoted, a number or boolean as TOML writes it, else its
  // kind ("a table", "an array").
  static std::string written(const toml::node& node);

  // Absent nodes give the fallback; present ones must be of the type, finite and within [lower, upper].
  double number(const toml::node* node, std::string_view field, double fallback, double lower = -INFINITY,
                double upper = INFINITY) const;
  std::int64_t integer(const toml::node* node, std::string_view field, std::int64_t fallback,
                       std::int64_t lower, std::int64_t upper) const;
  std::string string(const toml::node* node, std::string_view field, std::string fallback) const;
  // A string that must be one of `choices`.
  std::string choice(const toml::node* node, std::string_view field, std::string fallback,
                     const std::vector<std::string>& choices) const;
  // An array of strings (absent: none).
  std::vector<std::string> strings(const toml::node* node, std::string_view field) const;
  // Every key of `table` is one of `known` (a misspelt key would silently keep a default): "PREFIX.KEY:
  // unknown key (did you mean 'K'?); expected one of ...", at the key's line.
  void only_keys(const toml::table& table, std::string_view prefix, const std::set<std::string>& known) const;

 private:
  std::string file_;
};

}  // namespace pegasus
