#include "toml_input.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"

namespace pegasus {

namespace detail {
void toml_assertion_failed(const char* expression) { throw TomlAssertionFailed(expression); }
}  // namespace detail

toml::table parse_toml_input(std::string_view text, std::string_view name) {
  if (const std::size_t bad = first_invalid_utf8(text); bad != text.size()) {
    const auto line = 1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(bad), '\n');
    throw InputError(fmt::format("{}:{}: expected UTF-8 text, got the byte 0x{:02X}", printable(name), line,
                                 static_cast<unsigned>(static_cast<unsigned char>(text[bad]))));
  }
  try {
    return toml::parse(text, std::string(name));
  } catch (const toml::parse_error& e) {
    std::string description(e.description());
    std::replace(description.begin(), description.end(), '\n', ' ');
    throw InputError(fmt::format("{}:{}: invalid TOML: {}", printable(name), e.source().begin.line,
                                 printable(description)));
  } catch (const detail::TomlAssertionFailed& e) {
    // A check inside toml++ that Debian's build would have skipped: text that 3.3.0 misreads.
    throw InputError(fmt::format("{}: invalid TOML (the parser's own check \"{}\" failed)", printable(name),
                                 printable(e.what())));
  }
}

toml::table read_toml_input(const std::filesystem::path& file, std::string_view what) {
  std::string text;
  try {
    text = read_file(file, kMaxSettingsFileBytes);
  } catch (const std::exception& e) {
    // read_file's message names the file and the system's reason; keep only the reason.
    const std::string reason = read_failure_reason(e);
    throw InputError(
        fmt::format("{}: expected a readable {} file, got {}", printable(file.string()), what, reason));
  }
  return parse_toml_input(text, file.string());
}

}  // namespace pegasus
