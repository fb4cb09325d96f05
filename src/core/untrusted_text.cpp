#include "pegasus/core/untrusted_text.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <utility>

namespace pegasus {

namespace {

// The length of the well-formed UTF-8 sequence at the start of `s` (RFC 3629, Table 3-7 of Unicode), or 0.
std::size_t utf8_sequence_length(std::string_view s) {
  const auto byte = [&](std::size_t i) { return static_cast<std::uint8_t>(s[i]); };
  const std::uint8_t b0 = byte(0);
  if (b0 < 0x80) return 1;
  std::size_t length = 0;
  std::uint8_t lo = 0x80, hi = 0xBF;  // the range of the second byte
  if (b0 >= 0xC2 && b0 <= 0xDF) {
    length = 2;
  } else if (b0 >= 0xE0 && b0 <= 0xEF) {
    length = 3;
    if (b0 == 0xE0) lo = 0xA0;  // no overlong forms
    if (b0 == 0xED) hi = 0x9F;  // no surrogates
  } else if (b0 >= 0xF0 && b0 <= 0xF4) {
    length = 4;
    if (b0 == 0xF0) lo = 0x90;
    if (b0 == 0xF4) hi = 0x8F;  // nothing above U+10FFFF
  } else {
    return 0;
  }
  if (s.size() < length) return 0;
  if (byte(1) < lo || byte(1) > hi) return 0;
  for (std::size_t i = 2; i < length; ++i)
    if (byte(i) < 0x80 || byte(i) > 0xBF) return 0;
  return length;
}

// Valid UTF-8 kept; each other byte as \xNN; control characters too when `controls` is set.
std::string escape_bytes(std::string_view bytes, bool controls) {
  std::string out;
  out.reserve(bytes.size());
  while (!bytes.empty()) {
    const std::size_t n = utf8_sequence_length(bytes);
    const auto b0 = static_cast<unsigned char>(bytes[0]);
    if (n == 0 || (controls && n == 1 && ((b0 < 0x20 && b0 != '\t') || b0 == 0x7F))) {
      out += fmt::format("\\x{:02X}", b0);
      bytes.remove_prefix(1);
    } else {
      out.append(bytes.substr(0, n));
      bytes.remove_prefix(n);
    }
  }
  return out;
}

}  // namespace

std::size_t first_invalid_utf8(std::string_view bytes) {
  std::size_t offset = 0;
  while (offset < bytes.size()) {
    const std::size_t n = utf8_sequence_length(bytes.substr(offset));
    if (n == 0) return offset;
    offset += n;
  }
  return offset;
}

bool is_valid_utf8(std::string_view bytes) { return first_invalid_utf8(bytes) == bytes.size(); }

std::string with_invalid_bytes_escaped(std::string_view bytes) { return escape_bytes(bytes, false); }

std::string printable(std::string_view bytes) { return escape_bytes(bytes, true); }

std::string one_line_message(const std::string& message) {
  std::string line = message;
  for (char& c : line)
    if (c == '\n') c = ' ';
  while (!line.empty() && line.back() == ' ') line.pop_back();
  line = printable(line);
  // A message that quotes what it was given (an unknown key, a value) must stay a line a terminal shows,
  // however large the input: its start and end are kept, cut at UTF-8 character boundaries.
  if (line.size() > kMaxMessageBytes) {
    const auto boundary = [&](std::size_t at) {
      while (at > 0 && (static_cast<unsigned char>(line[at]) & 0xC0) == 0x80) --at;
      return at;
    };
    const std::size_t head = boundary(kMaxMessageBytes * 3 / 4);
    const std::size_t tail = boundary(line.size() - kMaxMessageBytes / 8);
    line =
        line.substr(0, head) + fmt::format(" ... ({} bytes left out) ... ", tail - head) + line.substr(tail);
  }
  return line;
}

nlohmann::json with_valid_utf8(nlohmann::json value) {
  if (value.is_string()) {
    const auto& s = value.get_ref<const std::string&>();
    if (!is_valid_utf8(s)) value = escape_bytes(s, false);
  } else if (value.is_array()) {
    for (auto& element : value) element = with_valid_utf8(std::move(element));
  } else if (value.is_object()) {
    bool keys_valid = true;
    for (auto it = value.begin(); it != value.end(); ++it) keys_valid = keys_valid && is_valid_utf8(it.key());
    if (keys_valid) {
      for (auto& element : value) element = with_valid_utf8(std::move(element));
    } else {
      nlohmann::json fixed = nlohmann::json::object();
      for (auto it = value.begin(); it != value.end(); ++it)
        fixed[escape_bytes(it.key(), false)] = with_valid_utf8(std::move(it.value()));
      value = std::move(fixed);
    }
  }
  return value;
}

}  // namespace pegasus
