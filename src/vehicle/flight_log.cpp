#include "pegasus/vehicle/flight_log.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"

namespace pegasus::sysid {

double FlightLog::dt() const {
  if (time.size() < 2) return 0;
  return (time.back() - time.front()) / static_cast<double>(time.size() - 1);
}
double FlightLog::seconds() const { return static_cast<double>(rows()) * dt(); }

std::string flight_log_csv(const FlightLog& log) {
  std::vector<std::string> header{"time"};
  for (const char* c : kLogStateColumns) header.emplace_back(c);
  for (const char* c : kLogControlColumns) header.emplace_back(c);
  CsvWriter csv(header);
  for (std::size_t i = 0; i < log.rows(); ++i) {
    std::vector<CsvCell> row{log.time[i]};
    for (double v : log.states[i]) row.emplace_back(v);
    for (double v : log.controls[i]) row.emplace_back(v);
    csv.add_row(std::move(row));
  }
  return csv.str();
}

void write_flight_log(const std::filesystem::path& file, const FlightLog& log) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw InputError(fmt::format("{}: cannot open for writing", file.string()));
  out << flight_log_csv(log);
  if (!out) throw InputError(fmt::format("{}: write failed", file.string()));
}

namespace {

std::vector<std::string_view> split(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    std::string_view f =
        line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
    while (!f.empty() && (f.front() == ' ' || f.front() == '\t')) f.remove_prefix(1);
    while (!f.empty() && (f.back() == ' ' || f.back() == '\t' || f.back() == '\r')) f.remove_suffix(1);
    out.push_back(f);
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

CsvColumns read_csv_columns(const std::string& text, const std::string& name,
                            const std::vector<std::string>& columns) {
  std::vector<std::string_view> lines;
  {
    // A UTF-8 byte order mark (spreadsheets write one) is not part of the first column's name.
    std::size_t start = text.starts_with(kUtf8ByteOrderMark) ? kUtf8ByteOrderMark.size() : 0;
    while (start < text.size()) {
      std::size_t nl = text.find('\n', start);
      if (nl == std::string::npos) nl = text.size();
      lines.emplace_back(text.data() + start, nl - start);
      start = nl + 1;
    }
  }
  if (lines.empty()) throw InputError(fmt::format("{}:1: empty file; expected a CSV header line", name));
  const auto header = split(lines[0]);
  std::vector<std::size_t> index(columns.size());
  for (std::size_t r = 0; r < columns.size(); ++r) {
    std::size_t found = header.size();
    for (std::size_t h = 0; h < header.size(); ++h) {
      if (header[h] != columns[r]) continue;
      if (found != header.size())  // which of the two would the user mean?
        throw InputError(fmt::format("{}:1:{}: the column appears twice in the header; expected it once",
                                     name, printable(columns[r])));
      found = h;
    }
    if (found == header.size()) {
      std::string need;
      for (const auto& c : columns) need += (need.empty() ? "" : ", ") + c;
      throw InputError(fmt::format("{}:1:{}: required column missing from the header (need {})", name,
                                   printable(columns[r]), printable(need)));
    }
    index[r] = found;
  }
  CsvColumns out;
  out.last_line = lines.size();
  for (std::size_t li = 1; li < lines.size(); ++li) {
    std::string_view line = lines[li];
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;  // blank lines
    const auto fields = split(line);
    if (fields.size() != header.size())
      throw InputError(fmt::format("{}:{}: expected {} comma-separated fields as in the header, found {}",
                                   name, li + 1, header.size(), fields.size()));
    std::vector<double> v(columns.size());
    for (std::size_t r = 0; r < columns.size(); ++r) {
      const std::string_view f = fields[index[r]];
      double x = 0;
      const auto res = std::from_chars(f.data(), f.data() + f.size(), x);
      if (f.empty() || res.ec != std::errc() || res.ptr != f.data() + f.size())
        throw InputError(fmt::format("{}:{}:{}: expected a number, found '{}'", name, li + 1,
                                     printable(columns[r]), printable(f)));
      if (!std::isfinite(x))
        throw InputError(fmt::format("{}:{}:{}: expected a finite number, found '{}'", name, li + 1,
                                     printable(columns[r]), printable(f)));
      v[r] = x;
    }
    out.rows.push_back(std::move(v));
    out.lines.push_back(li + 1);
  }
  return out;
}

void check_log_rows(const FlightLog& log, const std::vector<std::size_t>& lines, std::size_t last_line,
                    const std::string& name, const LogReadOptions& options, const std::string& time_column) {
  const std::string time = printable(time_column);
  if (log.rows() < static_cast<std::size_t>(options.min_rows))
    throw InputError(fmt::format("{}:{}: expected at least {} data rows, found {}", name, last_line,
                                 options.min_rows, log.rows()));
  for (std::size_t i = 1; i < log.rows(); ++i)
    if (!(log.time[i] > log.time[i - 1]))
      throw InputError(fmt::format("{}:{}:{}: expected time to increase strictly, found {} after {}", name,
                                   lines[i], time, log.time[i], log.time[i - 1]));
  const double dt = log.dt();
  for (std::size_t i = 1; i < log.rows(); ++i) {
    const double step = log.time[i] - log.time[i - 1];
    if (std::abs(step - dt) > options.rate_tolerance * dt)
      throw InputError(fmt::format(
          "{}:{}:{}: expected a constant sample interval (within {}% of the file's mean, {:.6g} s), "
          "found {:.6g} s (a missing or repeated row?)",
          name, lines[i], time, 100 * options.rate_tolerance, dt, step));
  }
}

FlightLog parse_flight_log(const std::string& text, const std::string& name, const LogReadOptions& options) {
  std::vector<std::string> required{"time"};
  for (const char* c : kLogStateColumns) required.emplace_back(c);
  for (const char* c : kLogControlColumns) required.emplace_back(c);
  const CsvColumns table = read_csv_columns(text, name, required);
  FlightLog log;
  for (std::size_t i = 0; i < table.rows.size(); ++i) {
    const std::vector<double>& v = table.rows[i];
    for (std::size_t r = 13; r < 17; ++r)
      if (std::abs(v[r]) > 1.0 + 1e-9)
        throw InputError(fmt::format("{}:{}:{}: expected a control in [-1, 1], found {}", name,
                                     table.lines[i], required[r], v[r]));
    log.time.push_back(v[0]);
    std::array<double, kLogStates> s{};
    for (int k = 0; k < kLogStates; ++k) s[static_cast<std::size_t>(k)] = v[static_cast<std::size_t>(1 + k)];
    log.states.push_back(s);
    log.controls.push_back({v[13], v[14], v[15], v[16]});
  }
  check_log_rows(log, table.lines, table.last_line, name, options);
  return log;
}

std::string read_log_text(const std::filesystem::path& file) {
  try {
    return read_file(file);  // refuses a directory by name, where a stream would throw from underflow
  } catch (const std::exception& e) {
    const std::string reason = read_failure_reason(e);
    throw InputError(fmt::format("{}: cannot read the flight log ({})", file.string(), reason));
  }
}

FlightLog read_flight_log(const std::filesystem::path& file, const LogReadOptions& options) {
  return parse_flight_log(read_log_text(file), file.string(), options);
}

}  // namespace pegasus::sysid
