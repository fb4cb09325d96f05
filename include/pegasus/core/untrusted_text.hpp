#pragma once
// Text that came from outside (paths, file contents, control lines) on its way into a message or a JSON
// file: any byte sequence is accepted, and what is not printable UTF-8 is shown as \xNN. A path like
// `run\xff` is legal on Linux, so it must never make a message unreadable or a JSON writer throw (issue 16).
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace pegasus {

// What some editors and spreadsheets put at the start of a UTF-8 text file.
inline constexpr std::string_view kUtf8ByteOrderMark = "\xEF\xBB\xBF";

// True when `bytes` is well-formed UTF-8 (no overlong forms, no surrogates, nothing above U+10FFFF).
bool is_valid_utf8(std::string_view bytes);

// `bytes` with each byte that is not part of well-formed UTF-8 written as \xNN (text kept as it is): the form
// in which such a string is stored where only UTF-8 may go (config.toml, JSON).
std::string with_invalid_bytes_escaped(std::string_view bytes);

// The offset of the first byte of `bytes` that is not part of well-formed UTF-8; bytes.size() if none.
std::size_t first_invalid_utf8(std::string_view bytes);

// `bytes` with every byte that is not part of well-formed UTF-8, and every control character (NUL, CR, LF,
// ESC, ...; tab kept), written as \xNN: one printable line, whatever the input.
std::string printable(std::string_view bytes);

// `message` as one printable line: line breaks become spaces, other control bytes and bytes that are not
// UTF-8 are written \xNN, and a line longer than kMaxMessageBytes keeps its start and end around a note of
// how much was left out. What the CLI prints of every error.
inline constexpr std::size_t kMaxMessageBytes = 2000;
std::string one_line_message(const std::string& message);

// `value` with every string and key that is not well-formed UTF-8 made so (its bad bytes written as \xNN):
// what nlohmann's dump() needs to never throw. Valid strings are unchanged, so most values are returned as
// they came.
nlohmann::json with_valid_utf8(nlohmann::json value);

}  // namespace pegasus
