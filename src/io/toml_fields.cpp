#include "toml_fields.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <sstream>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"

namespace pegasus {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

void TomlFields::fail(const toml::node* node, std::string_view field, std::string_view what) const {
  const auto line = node ? node->source().begin.line : 0;
  throw InputError(printable(line ? fmt::format("{}:{}: {}: {}", file_, line, field, what)
                                  : fmt::format("{}: {}: {}", file_, field, what)));
}

std::string TomlFields::written(const toml::node& node) {
  if (const auto s = node.value_exact<std::string>()) return "'" + printable(*s) + "'";
  if (node.is_table()) return "a table";
  if (node.is_array()) return "an array";
  std::ostringstream text;  // a number, boolean, date or time as TOML writes it
  node.visit([&](const auto& value) { text << value; });
  return text.str();
}

double TomlFields::number(const toml::node* node, std::string_view field, double fallback, double lower,
                          double upper) const {
  if (!node) return fallback;
  const auto value = node->value<double>();
  const bool bounded = std::isfinite(lower) || std::isfinite(upper);
  const std::string expected =
      bounded ? fmt::format("expected a number in [{}, {}]", lower, upper) : "expected a finite number";
  if (!value || !(node->is_integer() || node->is_floating_point()))
    fail(node, field, fmt::format("{}, got {}", expected, written(*node)));
  if (!std::isfinite(*value) || *value < lower || *value > upper)
    fail(node, field, fmt::format("{}, got {}", expected, *value));
  return *value;
}

std::int64_t TomlFields::integer(const toml::node* node, std::string_view field, std::int64_t fallback,
                                 std::int64_t lower, std::int64_t upper) const {
  if (!node) return fallback;
  const auto value = node->value_exact<std::int64_t>();
  if (!value || *value < lower || *value > upper)
    fail(node, field, fmt::format("expected an integer in [{}, {}], got {}", lower, upper, written(*node)));
  return *value;
}

std::string TomlFields::string(const toml::node* node, std::string_view field, std::string fallback) const {
  if (!node) return fallback;
  const auto value = node->value_exact<std::string>();
  if (!value) fail(node, field, "expected a string, got " + written(*node));
  return *value;
}

std::string TomlFields::choice(const toml::node* node, std::string_view field, std::string fallback,
                               const std::vector<std::string>& choices) const {
  std::string value = string(node, field, std::move(fallback));
  if (node && std::find(choices.begin(), choices.end(), value) == choices.end()) {
    std::string list;
    for (const auto& c : choices) list += (list.empty() ? "" : " or ") + ("'" + c + "'");
    fail(node, field, fmt::format("expected {}, got {}", list, written(*node)));
  }
  return value;
}

std::vector<std::string> TomlFields::strings(const toml::node* node, std::string_view field) const {
  std::vector<std::string> out;
  if (!node) return out;
  const toml::array* array = node->as_array();
  if (!array) fail(node, field, "expected an array of strings, got " + written(*node));
  for (std::size_t i = 0; i < array->size(); ++i) {
    const toml::node& item = (*array)[i];
    const auto value = item.value_exact<std::string>();
    if (!value) fail(&item, fmt::format("{}[{}]", field, i), "expected a string, got " + written(item));
    out.push_back(*value);
  }
  return out;
}

void TomlFields::only_keys(const toml::table& table, std::string_view prefix,
                           const std::set<std::string>& known) const {
  for (const auto& [key, node] : table) {
    const std::string name(key.str());
    if (known.contains(name)) continue;
    std::string list;
    for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
    const std::string hint = did_you_mean(name, known);
    fail(&node, prefix.empty() ? name : fmt::format("{}.{}", prefix, name),
         fmt::format("unknown key{}; expected one of {}", hint, list));
  }
}

}  // namespace pegasus
