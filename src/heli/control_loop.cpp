#include "pegasus/heli/control_loop.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "pegasus/core/untrusted_text.hpp"

namespace pegasus::heli {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r' || s.back() == '\n'))
    s.remove_suffix(1);
  return s;
}

// The fields of a line, trimmed.
std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::string_view rest = line;
  while (true) {
    const std::size_t comma = rest.find(',');
    fields.push_back(trim(rest.substr(0, comma)));
    if (comma == std::string_view::npos) return fields;
    rest.remove_prefix(comma + 1);
  }
}

bool is_number(std::string_view field) {
  double x = 0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), x);
  return !field.empty() && ec == std::errc() && end == field.data() + field.size();
}

// The first line is a header when one of its fields is not a number: a header is what it means to be, and
// is checked as one (a misspelt name must not leave the lines read by position).
bool is_header(std::string_view line) {
  for (const std::string_view field : split_fields(line))
    if (!is_number(field)) return true;
  return false;
}

void write_values(std::FILE* out, std::span<const double> a) {
  fmt::memory_buffer buf;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (i) buf.push_back(',');
    fmt::format_to(fmt::appender(buf), "{}", a[i]);  // straight into the buffer, no iterator adaptor
  }
  buf.push_back('\n');
  std::fwrite(buf.data(), 1, buf.size(), out);
  std::fflush(out);
}

void write_controls(std::FILE* out, const Controls& a, const ControlLineFormat& format) {
  if (format.controls_of) {
    const std::array<double, 4> native = format.controls_of(a);
    write_values(out, native);
  } else {
    write_values(out, a);
  }
}

// Each field's position from a header (the time's first, -1 when absent, then the state fields'). Every
// state field must be named, and no known name twice: otherwise *why says what is wrong and the result is
// empty. Other columns (a log's battery voltage) are ignored, each named in *ignored.
std::vector<int> header_columns(std::string_view header, const ControlLineFormat& format, std::string* why,
                                std::string* ignored) {
  const std::vector<std::string_view> names = split_fields(header);
  auto known = [&](std::string_view name) {
    if (name == format.time_field) return true;
    for (const auto& f : format.state_fields)
      if (name == f) return true;
    for (const auto& c : format.control_names)
      if (name == c) return true;
    for (const auto& c : format.control_columns)
      if (name == c) return true;
    return false;
  };
  ignored->clear();
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!known(names[i])) {
      *ignored += fmt::format("{}{} '{}'", ignored->empty() ? "" : ", ", i + 1, names[i].substr(0, 40));
      continue;
    }
    for (std::size_t j = 0; j < i; ++j)
      if (names[j] == names[i]) {
        *why = fmt::format("header: column '{}' is named twice (columns {} and {})", names[i], j + 1, i + 1);
        return {};
      }
  }
  auto find = [&](const std::string& name) {
    for (std::size_t i = 0; i < names.size(); ++i)
      if (names[i] == name) return static_cast<int>(i);
    return -1;
  };
  std::vector<int> columns{find(format.time_field)};
  std::string missing;
  for (const auto& f : format.state_fields) {
    columns.push_back(find(f));
    if (columns.back() < 0) missing += (missing.empty() ? "" : ", ") + f;
  }
  if (!missing.empty()) {
    std::string expected = format.time_field;
    for (const auto& f : format.state_fields) expected += "," + f;
    *why = fmt::format("header: no column for the state field(s) {} (expected the columns {}{})", missing,
                       expected, ignored->empty() ? "" : "; not fields of this layout: " + *ignored);
    return {};
  }
  return columns;
}

// One input line of at most kMaxLineBytes into *line (without its newline); false at the end of the input.
// A longer line is cut there (*too_long) and the rest of it is read and dropped, so no input, however long
// its lines, makes memory grow.
constexpr std::size_t kMaxLineBytes = 64 * 1024;

bool read_line(std::FILE* in, std::string* line, bool* too_long) {
  line->clear();
  *too_long = false;
  // Characters gather in a small array and join the line a block at a time: a std::string's push_back per
  // character cost the loop a fifth of its speed (bench/heli_bench.cpp BM_HeliControlLoop). getc_unlocked
  // takes what the stream has, so a line is answered as soon as it arrives.
  std::array<char, 256> block{};
  std::size_t held = 0;
  auto keep = [&] {
    const std::size_t room = kMaxLineBytes - line->size();
    if (held > room) *too_long = true;
    line->append(block.data(), std::min(held, room));
    held = 0;
  };
  int c = 0;
  bool any = false;
  while ((c = getc_unlocked(in)) != EOF) {  // the loop's only reader of `in`
    any = true;
    if (c == '\n') break;
    block[held++] = static_cast<char>(c);
    if (held == block.size()) keep();
  }
  keep();
  return any;
}

constexpr std::size_t kMaxFields = 256;

}  // namespace

bool parse_state_line(std::string_view line, const ControlLineFormat& format, std::span<const int> columns,
                      LoggedState* state, bool* has_time, double* time, std::string* why) {
  std::array<double, kMaxFields> v{};
  const std::size_t count = format.state_fields.size();
  const std::size_t longest = columns.empty() ? count + 5 : kMaxFields;
  std::size_t n = 0;
  std::string_view rest = line;
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view field = trim(rest.substr(0, comma));
    if (n == longest) {
      *why = columns.empty() ? fmt::format("expected {}, {} or {} fields, got more than {}", count, count + 1,
                                           count + 5, count + 5)
                             : fmt::format("expected the header's fields, got more than {}", kMaxFields);
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
  std::array<double, kMaxFields> fields{};
  if (columns.empty()) {
    if (n != count && n != count + 1 && n != count + 5) {
      *why = fmt::format("expected {}, {} or {} fields, got {}", count, count + 1, count + 5, n);
      return false;
    }
    const std::size_t first = n == count ? 0 : 1;
    *has_time = n != count;
    if (*has_time) *time = v[0];
    for (std::size_t k = 0; k < count; ++k) fields[k] = v[first + k];
  } else {
    int widest = 0;
    for (int c : columns) widest = std::max(widest, c);
    if (n <= static_cast<std::size_t>(widest)) {
      *why = fmt::format("expected at least {} fields, as the header says, got {}", widest + 1, n);
      return false;
    }
    *has_time = columns[0] >= 0;
    if (*has_time) *time = v[static_cast<std::size_t>(columns[0])];
    for (std::size_t k = 0; k < count; ++k) fields[k] = v[static_cast<std::size_t>(columns[k + 1])];
  }
  if (format.state_of) {
    *state = format.state_of(std::span<const double>(fields.data(), count));
    for (double x : *state)
      if (!std::isfinite(x)) {
        *why = "the state fields give no finite state (an all-zero quaternion?)";
        return false;
      }
  } else {
    for (std::size_t k = 0; k < kLoggedStates; ++k) (*state)[k] = fields[k];
  }
  return true;
}

bool parse_state_line(std::string_view line, LoggedState* state, bool* has_time, double* time,
                      std::string* why) {
  static const ControlLineFormat kOwn;
  return parse_state_line(line, kOwn, {}, state, has_time, time, why);
}

ControlLoopStats run_control_loop(const HeliController& controller, const Controls& safe, std::FILE* in,
                                  std::FILE* out, std::FILE* err, double dt,
                                  const ControlLineFormat& format) {
  ControlLoopStats stats;
  std::string buffer;
  std::int64_t data_lines = 0;
  LoggedState s{};
  ControllerMemory memory;  // the flight's (the input is one flight)
  std::string why;
  std::vector<int> columns;  // from a header naming the fields
  auto say = [&](const std::string& what) {
    const std::string msg = fmt::format("stdin:{}: {}\n", stats.lines, printable(what));
    std::fwrite(msg.data(), 1, msg.size(), err);
    std::fflush(err);
  };
  bool too_long = false;
  while (read_line(in, &buffer, &too_long)) {
    ++stats.lines;
    std::string_view line = trim(buffer);
    if (stats.lines == 1 && line.starts_with(kUtf8ByteOrderMark))
      line.remove_prefix(kUtf8ByteOrderMark.size());
    if (!too_long && line == kResetLine) {  // a new flight: no memory, and the clock from 0
      memory = ControllerMemory{};
      data_lines = 0;
      ++stats.resets;
      std::fputs("reset\n", out);
      std::fflush(out);
      continue;
    }
    if (stats.lines == 1 && !too_long && is_header(line)) {
      std::string header;
      for (const auto& name : format.control_names) header += (header.empty() ? "" : ",") + name;
      header += '\n';
      std::fputs(header.c_str(), out);
      std::fflush(out);
      std::string ignored;
      columns = header_columns(line, format, &why, &ignored);
      if (columns.empty()) {
        stats.header_refused = why;
        ++stats.header_notes;
        say(why + "; every line is answered with the trim controls");
      } else if (!ignored.empty()) {
        ++stats.header_notes;
        say("header: columns not of this layout, ignored: " + ignored);
      }
      continue;
    }
    bool has_time = false;
    double time = 0;
    if (!stats.header_refused.empty()) {
      ++stats.malformed;
      write_controls(out, safe, format);
      say("the header (line 1) was refused; answered the trim controls");
    } else if (!too_long && parse_state_line(line, format, columns, &s, &has_time, &time, &why)) {
      write_controls(out, controller.act(s, has_time ? time : static_cast<double>(data_lines) * dt, memory),
                     format);
    } else {
      ++stats.malformed;
      write_controls(out, safe, format);
      if (too_long) why = fmt::format("expected a line of at most {} bytes", kMaxLineBytes);
      // One line per malformed input line, whatever bytes it held (NUL, CR, invalid UTF-8).
      say(why + "; answered the trim controls");
    }
    ++data_lines;
  }
  return stats;
}

ControlLoopTiming time_control_loop(const HeliController& controller, const Controls& safe,
                                    std::int64_t lines) {
  std::string input;
  for (std::int64_t i = 0; i < lines; ++i) {
    const double t = 0.02 * static_cast<double>(i);
    input += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{}\n", 0.3 * std::sin(t), -0.2 * std::cos(t),
                         -10 + 0.1 * std::sin(0.5 * t), 0.05, -0.01, 0.02 * std::sin(t), 0.1, -0.1, 0.02,
                         0.01, 0.0, 0.01);
  }
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  std::FILE* out = std::fopen("/dev/null", "w");
  if (!in || !out) {
    if (in) std::fclose(in);
    if (out) std::fclose(out);
    throw std::runtime_error("bench: cannot open the in-memory input or /dev/null");
  }
  const auto start = std::chrono::steady_clock::now();
  const ControlLoopStats stats = run_control_loop(controller, safe, in, out, stderr);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fclose(in);
  std::fclose(out);
  return {.lines = stats.lines, .seconds = seconds};
}

}  // namespace pegasus::heli
