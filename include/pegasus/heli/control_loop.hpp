#pragma once
// The loop behind `pegasus heli control`: a learned controller served line by line, so that a flight computer
// or another simulator can fly it (thesis §5.3: the controller ran at 50 Hz on the helicopter's computer).
//
// Input, one line per 50 Hz step, comma-separated numbers (spaces around them allowed, '\r' ignored):
//   12 fields  x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate   (the log's state columns)
//   13 fields  time, then the 12 states                                            (a log row without
//   controls) 17 fields  time, the 12 states, a1..a4 (the controls are ignored)              (a whole log
//   row)
// Units and frames as in the flight logs (sysid/flight_log.hpp). The controller's time is the line's time
// when it has one, else the data line's index times dt (0, 0.02, 0.04, ...).
// Output: exactly one line per input line, "a1,a2,a3,a4" (shortest round-trip decimals), flushed at once.
// A header line (first field "time" or "x") is answered with the header "a1,a2,a3,a4". A malformed line
// (wrong field count, a field that is not a finite number) is answered with the SAFE OUTPUT, the hover trim
// controls stored in the policy file, and one line "stdin:LINE: <what was wrong>; answered the trim
// controls" goes to the error stream. Nothing stops the loop but the end of the input.
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include "pegasus/heli/policy_file.hpp"

namespace pegasus::heli {

struct ControlLoopStats {
  std::int64_t lines = 0;      // input lines answered
  std::int64_t malformed = 0;  // of which answered with the safe output
};

// Parses one input line (without its newline). Returns false with *why set when malformed; *has_time tells
// whether the line carried a time (then *time is set).
bool parse_state_line(std::string_view line, LoggedState* state, bool* has_time, double* time,
                      std::string* why);

// Serves `controller` from `in` to `out` until the end of `in`; errors go to `err`.
ControlLoopStats run_control_loop(const HeliController& controller, const Controls& safe, std::FILE* in,
                                  std::FILE* out, std::FILE* err, double dt = 0.02);

}  // namespace pegasus::heli
