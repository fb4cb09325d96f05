#include "pegasus/heli/control_loop.hpp"

#include <fmt/format.h>

#include <array>
#include <charconv>
#include <cmath>
#include <cstdlib>

#include "pegasus/core/untrusted_text.hpp"

namespace pegasus::heli {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n'))
    s.remove_suffix(1);
  return s;
}

bool is_header(std::string_view line) {
  const std::string_view first = trim(line.substr(0, line.find(',')));
  return first == "time" || first == "x";
}

void write_controls(std::FILE* out, const Controls& a) {
  fmt::memory_buffer buf;
  fmt::format_to(std::back_inserter(buf), "{},{},{},{}\n", a[0], a[1], a[2], a[3]);
  std::fwrite(buf.data(), 1, buf.size(), out);
  std::fflush(out);
}

}  // namespace

bool parse_state_line(std::string_view line, LoggedState* state, bool* has_time, double* time,
                      std::string* why) {
  std::array<double, 17> v{};
  std::size_t n = 0;
  std::string_view rest = line;
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view field = trim(rest.substr(0, comma));
    if (n == v.size()) {
      *why = "expected 12, 13 or 17 fields, got more than 17";
      return false;
    }
    double x = 0;
    const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), x);
    if (field.empty() || ec != std::errc() || end != field.data() + field.size() || !std::isfinite(x)) {
      *why = fmt::format("field {}: expected a finite number, got '{}'", n + 1,
                         field.size() > 30 ? std::string(field.substr(0, 27)) + "..." : std::string(field));
      return false;
    }
    v[n++] = x;
    if (comma == std::string_view::npos) break;
    rest.remove_prefix(comma + 1);
  }
  if (n != 12 && n != 13 && n != 17) {
    *why = fmt::format("expected 12, 13 or 17 fields, got {}", n);
    return false;
  }
  const std::size_t first = n == 12 ? 0 : 1;
  *has_time = n != 12;
  if (*has_time) *time = v[0];
  for (std::size_t k = 0; k < kLoggedStates; ++k) (*state)[k] = v[first + k];
  return true;
}

ControlLoopStats run_control_loop(const HeliController& controller, const Controls& safe, std::FILE* in,
                                  std::FILE* out, std::FILE* err, double dt) {
  ControlLoopStats stats;
  char* buffer = nullptr;
  std::size_t capacity = 0;
  std::int64_t data_lines = 0;
  LoggedState s{};
  std::string why;
  while (true) {
    const ssize_t len = getline(&buffer, &capacity, in);
    if (len < 0) break;
    ++stats.lines;
    std::string_view line = trim(std::string_view(buffer, static_cast<std::size_t>(len)));
    if (stats.lines == 1 && line.starts_with(kUtf8ByteOrderMark))
      line.remove_prefix(kUtf8ByteOrderMark.size());
    if (stats.lines == 1 && is_header(line)) {
      std::fputs("a1,a2,a3,a4\n", out);
      std::fflush(out);
      continue;
    }
    bool has_time = false;
    double time = 0;
    if (parse_state_line(line, &s, &has_time, &time, &why)) {
      write_controls(out, controller.act(s, has_time ? time : static_cast<double>(data_lines) * dt));
    } else {
      ++stats.malformed;
      write_controls(out, safe);
      // One line per malformed input line, whatever bytes it held (NUL, CR, invalid UTF-8).
      const std::string msg =
          fmt::format("stdin:{}: {}; answered the trim controls\n", stats.lines, printable(why));
      std::fwrite(msg.data(), 1, msg.size(), err);
      std::fflush(err);
    }
    ++data_lines;
  }
  std::free(buffer);
  return stats;
}

}  // namespace pegasus::heli
