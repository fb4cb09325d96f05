#pragma once
// Flight logs: the 50 Hz record of a flight that system identification learns from (thesis §5.2).
//
// CSV format (anyone's data can be imported): a header line, then one row per sample. Required columns, in
// any order (extra columns are ignored), units m, rad, s:
//   time                      s, strictly increasing at a constant rate (every step within 1% of the mean)
//   x, y, z                   position in the world frame W, north-east-down (z < 0 is above the ground), m
//   roll, pitch, yaw          Z-Y-X Euler angles, rad (yaw may wrap at +-pi)
//   xdot, ydot, zdot          velocity in the world frame W, m/s
//   roll_rate, pitch_rate, yaw_rate   Euler angle rates d(roll)/dt, d(pitch)/dt, d(yaw)/dt, rad/s
//   a1, a2, a3, a4            controls in [-1, 1]: longitudinal cyclic, lateral cyclic, collective, tail
// The control of row t is the one applied from time t to time t + dt. Values must be finite numbers.
#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include "pegasus/vehicle/state.hpp"

namespace pegasus::sysid {

// The state and control columns are heli::LoggedState's and heli::Controls' (vehicle/state.hpp), defined
// there once.
inline constexpr int kLogStates = heli::kLoggedStates;
inline constexpr const std::array<const char*, kLogStates>& kLogStateColumns = heli::kLoggedStateNames;
inline constexpr const std::array<const char*, 4>& kLogControlColumns = heli::kControlNames;

struct FlightLog {
  std::vector<double> time;                            // s
  std::vector<std::array<double, kLogStates>> states;  // columns kLogStateColumns
  std::vector<std::array<double, 4>> controls;         // a1..a4
  std::size_t rows() const { return time.size(); }
  double dt() const;       // mean sample interval, s
  double seconds() const;  // rows * dt
  // The same flight: every time, state and control equal.
  friend bool operator==(const FlightLog&, const FlightLog&) = default;
};

// The CSV text (header plus rows; doubles in shortest round-trip form).
std::string flight_log_csv(const FlightLog& log);
void write_flight_log(const std::filesystem::path& file, const FlightLog& log);

struct LogReadOptions {
  int min_rows = 100;            // fewer rows: error
  double rate_tolerance = 0.01;  // every time step within this fraction of the mean step
};
// Reads and checks a log; InputError "FILE:LINE:COLUMN: what was expected" (LINE 1-based as in an editor,
// COLUMN the column's name) on any problem.
FlightLog read_flight_log(const std::filesystem::path& file, const LogReadOptions& options = {});
// The same checks on CSV text; `name` stands for the file in messages.
FlightLog parse_flight_log(const std::string& text, const std::string& name,
                           const LogReadOptions& options = {});

// A log file's text; InputError "FILE: cannot read the flight log (why)".
std::string read_log_text(const std::filesystem::path& file);

// The numeric columns `columns` of a CSV text with a header line (any column order, extra columns ignored),
// row by row with each row's 1-based line; blank lines skipped. InputError "NAME:LINE:COLUMN: ..." for a
// missing column (listing `columns`), a row of another width, or a field that is not a finite number.
struct CsvColumns {
  std::vector<std::vector<double>> rows;  // per row, the values in `columns` order
  std::vector<std::size_t> lines;         // per row
  std::size_t last_line = 0;              // the text's last line
};
CsvColumns read_csv_columns(const std::string& text, const std::string& name,
                            const std::vector<std::string>& columns);
// The checks every log gets: at least options.min_rows rows, time strictly increasing at a constant rate
// (within options.rate_tolerance); `lines` are the rows' lines and `time_column` the log's name for its time,
// for the messages.
void check_log_rows(const FlightLog& log, const std::vector<std::size_t>& lines, std::size_t last_line,
                    const std::string& name, const LogReadOptions& options,
                    const std::string& time_column = "time");

}  // namespace pegasus::sysid
