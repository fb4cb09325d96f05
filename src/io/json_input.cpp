#include "pegasus/io/json_input.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "toml_fields.hpp"

namespace pegasus {

namespace {

// nlohmann's message without its "[json.exception.KIND.ID] " prefix, which means nothing to a user.
std::string library_reason(const nlohmann::json::exception& e) {
  std::string text = e.what();
  if (text.starts_with("[json.exception.")) {
    if (const auto end = text.find("] "); end != std::string::npos) text.erase(0, end + 2);
  }
  return printable(text);
}

}  // namespace

nlohmann::json read_json_input(const std::filesystem::path& file, std::string_view what) {
  const std::string name = printable(file.string());
  std::string text;
  try {
    text = read_file(file);
  } catch (const std::exception& e) {
    // read_file's message names the file and the system's reason; keep only the reason.
    const std::string reason = read_failure_reason(e);
    throw InputError(fmt::format("{}: expected a readable {} file, got '{}'", name, what, reason));
  }
  return parse_json_input(text, file.string(), what);
}

nlohmann::json parse_json_input(std::string_view text, std::string_view file_name, std::string_view what) {
  const std::string name = printable(file_name);
  // The keys seen in each open object, to refuse a key given twice.
  std::vector<std::vector<std::string>> open_objects;
  std::string twice;
  const nlohmann::json::parser_callback_t keys_once = [&](int, nlohmann::json::parse_event_t event,
                                                          nlohmann::json& parsed) {
    using Event = nlohmann::json::parse_event_t;
    if (event == Event::object_start) {
      open_objects.emplace_back();
    } else if (event == Event::object_end) {
      if (!open_objects.empty()) open_objects.pop_back();
    } else if (event == Event::key && !open_objects.empty() && twice.empty()) {
      std::vector<std::string>& keys = open_objects.back();
      const std::string& key = parsed.get_ref<const std::string&>();
      if (std::find(keys.begin(), keys.end(), key) != keys.end()) twice = key;
      keys.push_back(key);
    }
    return true;
  };
  try {
    nlohmann::json j = nlohmann::json::parse(text, keys_once);
    if (!twice.empty())
      throw InputError(
          fmt::format("{}: expected each key once in an object, got '{}' twice", name, printable(twice)));
    return j;
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(
        fmt::format("{}: byte {}: expected a JSON {} file, got {}", name, e.byte, what, library_reason(e)));
  } catch (const nlohmann::json::out_of_range& e) {
    throw InputError(
        fmt::format("{}: expected numbers within the range of a double, got {}", name, library_reason(e)));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: expected a JSON {} file, got {}", name, what, library_reason(e)));
  }
}

void json_field_error(std::string_view file, std::string_view field, std::string_view expected,
                      const nlohmann::json& value) {
  std::string shown = with_valid_utf8(value).dump();
  constexpr std::size_t kLongest = 60;
  if (shown.size() > kLongest) shown = shown.substr(0, kLongest) + "...";
  throw InputError(fmt::format("{}: {}: expected {}, got {}", printable(file), printable(field),
                               printable(expected), printable(shown)));
}

void json_only_keys(const nlohmann::json& j, std::initializer_list<std::string_view> known,
                    std::string_view file, std::string_view field) {
  if (!j.is_object()) return;  // the caller's own check names what was expected
  for (const auto& [key, value] : j.items()) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string list;
    for (const std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
    const std::string hint = did_you_mean(key, known);
    throw InputError(fmt::format("{}: {}{}: unknown key{}; expected one of {}", printable(file),
                                 printable(field), field.empty() ? printable(key) : "." + printable(key),
                                 hint, list));
  }
}

const nlohmann::json& json_member(const nlohmann::json& j, const char* name, std::string_view file,
                                  std::string_view field) {
  const auto it = j.find(name);
  if (it == j.end()) throw InputError(fmt::format("{}: {}: missing", printable(file), printable(field)));
  return *it;
}

double json_finite_number(const nlohmann::json& j, std::string_view file, std::string_view field) {
  if (!j.is_number()) json_field_error(file, field, "a number", j);
  const double x = j.get<double>();
  if (!std::isfinite(x)) json_field_error(file, field, "a finite number", j);
  return x;
}

void json_format_header(const nlohmann::json& j, std::string_view file, std::string_view format, int version,
                        std::string_view made_by) {
  if (!j.is_object()) json_field_error(file, "(top level)", "a JSON object", j);
  const nlohmann::json& f = json_member(j, "format", file, "format");
  if (!f.is_string() || f.get_ref<const std::string&>() != format)
    json_field_error(
        file, "format",
        made_by.empty() ? fmt::format("\"{}\"", format) : fmt::format("\"{}\" ({})", format, made_by), f);
  const nlohmann::json& v = json_member(j, "version", file, "version");
  if (!v.is_number_integer() || v != version) json_field_error(file, "version", std::to_string(version), v);
}

double json_number_in(const nlohmann::json& j, std::string_view file, std::string_view field, double lo,
                      double hi, bool open_lo) {
  const auto expected = [&] { return fmt::format("a number in {}{}, {}]", open_lo ? "(" : "[", lo, hi); };
  if (!j.is_number()) json_field_error(file, field, expected(), j);
  const double x = j.get<double>();
  if (!(open_lo ? x > lo : x >= lo) || !(x <= hi)) json_field_error(file, field, expected(), j);
  return x;
}

long long json_integer(const nlohmann::json& j, std::string_view file, std::string_view field, long long lo,
                       long long hi) {
  const auto expected = [&] { return fmt::format("an integer in [{}, {}]", lo, hi); };
  if (!j.is_number_integer()) json_field_error(file, field, expected(), j);
  // An unsigned value above LLONG_MAX is out of any range a field takes.
  if (j.is_number_unsigned() && j.get<unsigned long long>() > static_cast<unsigned long long>(hi))
    json_field_error(file, field, expected(), j);
  const auto v = j.get<long long>();
  if (v < lo || v > hi) json_field_error(file, field, expected(), j);
  return v;
}

int json_index(const nlohmann::json& j, std::string_view file, std::string_view field, int count,
               std::string_view what) {
  const auto expected = [&] { return fmt::format("a {} in [0, {})", what, count); };
  if (!j.is_number_integer() || count < 1) json_field_error(file, field, expected(), j);
  if (j.is_number_unsigned() ? j.get<unsigned long long>() >= static_cast<unsigned long long>(count)
                             : (j.get<long long>() < 0 || j.get<long long>() >= count))
    json_field_error(file, field, expected(), j);
  return j.get<int>();
}

bool json_flag(const nlohmann::json& j, std::string_view file, std::string_view field) {
  if (!j.is_boolean()) json_field_error(file, field, "true or false", j);
  return j.get<bool>();
}

std::string json_nonempty_string(const nlohmann::json& j, std::string_view file, std::string_view field) {
  if (!j.is_string() || j.get_ref<const std::string&>().empty())
    json_field_error(file, field, "a non-empty string", j);
  return j.get<std::string>();
}

std::vector<double> json_finite_numbers(const nlohmann::json& j, std::string_view file,
                                        std::string_view field, std::size_t size) {
  if (!j.is_array() || (size > 0 && j.size() != size))
    json_field_error(file, field,
                     size > 0 ? fmt::format("an array of {} numbers", size) : "an array of numbers", j);
  std::vector<double> out;
  out.reserve(j.size());
  for (std::size_t i = 0; i < j.size(); ++i)
    out.push_back(json_finite_number(j[i], file, fmt::format("{}[{}]", field, i)));
  return out;
}

double json_number_or(const nlohmann::json& object, const char* name, double fallback, std::string_view file,
                      std::string_view field) {
  const auto it = object.find(name);
  return it == object.end() ? fallback : json_finite_number(*it, file, field);
}

bool json_flag_or(const nlohmann::json& object, const char* name, bool fallback, std::string_view file,
                  std::string_view field) {
  const auto it = object.find(name);
  return it == object.end() ? fallback : json_flag(*it, file, field);
}

}  // namespace pegasus
