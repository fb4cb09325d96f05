#pragma once
// A number setting described once (issue 49 item 1): its key, bounds, unit and one-line help. A settings
// struct lists its numbers in a VisitFields (sysid::Disturbance, heli::HoverTrainingOptions); from that one
// list come the command's options with their bounds, the reading of a config, IsValid's bounds and the Python
// fields with their docs.
#include <string>

namespace pegasus {

struct NumberSetting {
  const char* key;      // the config key (the option is `--KEY`, `_` written `-`)
  double lower, upper;  // bounds of the value (each element of a list)
  bool lower_open;      // (lower, upper] rather than [lower, upper]
  const char* unit;     // "" for a count or a fraction
  const char* help;     // the option's one line

  bool within(double x) const { return (lower_open ? x > lower : x >= lower) && x <= upper; }
  // "[0, 30]" or "(0, 3600]".
  std::string range() const;
  // The range and the unit: "[0, 30] m/s", "[0, 1]".
  std::string range_in_unit() const;
  // "NAME: expected WHAT in RANGE UNIT, got X" (what: "a number", "an integer", "numbers").
  std::string refusal(const std::string& name, const char* what, double x) const;
};

}  // namespace pegasus
