#include "pegasus/io/json_input.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"

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
    std::string reason = e.what();
    if (const auto colon = reason.rfind(": "); colon != std::string::npos) reason.erase(0, colon + 2);
    throw InputError(fmt::format("{}: expected a readable {} file, got '{}'", name, what, reason));
  }
  return parse_json_input(text, file.string(), what);
}

nlohmann::json parse_json_input(std::string_view text, std::string_view file_name, std::string_view what) {
  const std::string name = printable(file_name);
  try {
    return nlohmann::json::parse(text);
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

}  // namespace pegasus
