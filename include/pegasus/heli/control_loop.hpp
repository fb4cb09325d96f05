#pragma once
// The loop behind `pegasus heli control`: a learned controller served line by line, so that a flight computer
// or another simulator can fly it (thesis §5.3: the controller ran at 50 Hz on the helicopter's computer).
//
// Input, one line per 50 Hz step, comma-separated numbers (spaces around them allowed, '\r' ignored):
//   12 fields: x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate (the log's state columns);
//   13 fields: the time, then the 12 states (a log row without its controls);
//   17 fields: the time, the 12 states, a1..a4 (a whole log row; the controls are ignored).
// Units and frames as in the flight logs (vehicle/flight_log.hpp). The controller's time is the line's time
// when it has one, else the data line's index times dt (0, 0.02, 0.04, ... for a 50 Hz policy).
// Output: exactly one line per input line, "a1,a2,a3,a4" (shortest round-trip decimals), flushed at once.
// A first line with a field that is not a number is a header, answered with the header "a1,a2,a3,a4". It
// must name every state column (and "time", and the controls, at most once each): then later lines are read
// by those names, so rows of a CSV log in any column order work as they are; any other column (a log's
// battery voltage) is ignored and named once on the error stream. A header that lacks a state column (a
// misspelling: "yawrate") or names one twice is REFUSED: "stdin:1: header: <what>; every line is answered
// with the trim controls" goes to the error stream, every later line is answered with the safe output below
// (and one error line each), and the command ends with exit code 2 at the end of the input. A state is never
// read by position under a header that does not say where it is. A line longer than 64 KiB is malformed
// (memory stays bounded whatever the input).
// Another aircraft's layout (a vehicle file, vehicle/vehicle.hpp: `pegasus control --vehicle`) replaces the
// 12 state fields, their conversion, and the controls' names, order and scaling: ControlLineFormat. A
// malformed line (wrong field count, a field that is not a finite number) is answered with the SAFE OUTPUT,
// the hover trim controls stored in the policy file, and one line "stdin:LINE: <what was wrong>; answered the
// trim controls" goes to the error stream. Nothing stops the loop but the end of the input. The input is one
// flight, or several separated by the line "reset" (kResetLine, answered "reset"): a controller with memory
// (the hover class's integral term) starts a flight at its first well-formed line and advances it once per
// well-formed line (a malformed line leaves it as it was); "reset" clears it and the clock.
#include <array>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/heli/policy_file.hpp"

namespace pegasus::heli {

struct ControlLoopStats {
  std::int64_t lines = 0;         // input lines answered
  std::int64_t malformed = 0;     // of which answered with the safe output
  std::string header_refused;     // why the first line, a header, was refused (empty: it was not)
  std::int64_t resets = 0;        // reset lines (new flights)
  std::int64_t header_notes = 0;  // stderr lines about the header (refused, or columns ignored)
};

// The line that starts a new flight in the same process (a test harness, a flight computer between
// landings): answered with the line "reset", it clears the controller's memory (the hover class's integral
// term) and its clock (the next line without a time is t = 0 again).
inline constexpr std::string_view kResetLine = "reset";

// What a line holds and what the answer says. A line has the state fields (S of them), or the time and
// them, or the time, them and four controls (ignored): S, S + 1 or S + 5 fields.
struct ControlLineFormat {
  std::string time_field = "time";
  std::vector<std::string> state_fields{kLoggedStateNames.begin(), kLoggedStateNames.end()};
  std::vector<std::string> control_names{kControlNames.begin(), kControlNames.end()};
  // Columns a header may name besides the time, the state fields and control_names: a log row's control
  // columns where their names differ from the answer's (a vehicle's channel fields). Read past, not ignored.
  std::vector<std::string> control_columns;
  // The 12 states from the state fields' values; empty: they are the 12 states.
  std::function<LoggedState(std::span<const double>)> state_of;
  // The answer's values, in control_names order, from a1..a4; empty: a1..a4 as they are.
  std::function<std::array<double, 4>(const Controls&)> controls_of;
};

// Parses one input line (without its newline). Returns false with *why set when malformed; *has_time tells
// whether the line carried a time (then *time is set). `columns`, when not empty, gives each field's
// position in the line (the time's first, -1 for none, then the state fields'), from a header.
bool parse_state_line(std::string_view line, const ControlLineFormat& format, std::span<const int> columns,
                      LoggedState* state, bool* has_time, double* time, std::string* why);
// The pipeline's own layout.
bool parse_state_line(std::string_view line, LoggedState* state, bool* has_time, double* time,
                      std::string* why);

// Serves `controller` from `in` to `out` until the end of `in`; errors go to `err`. `safe` is in a1..a4.
ControlLoopStats run_control_loop(const HeliController& controller, const Controls& safe, std::FILE* in,
                                  std::FILE* out, std::FILE* err, double dt = 0.02,
                                  const ControlLineFormat& format = {});

// The loop timed on `lines` synthetic hover states in the pipeline's layout, each parsed, answered and
// flushed (to /dev/null): `control --bench-lines`.
struct ControlLoopTiming {
  std::int64_t lines = 0;
  double seconds = 0;
};
ControlLoopTiming time_control_loop(const HeliController& controller, const Controls& safe,
                                    std::int64_t lines);

}  // namespace pegasus::heli
