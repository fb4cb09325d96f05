#pragma once
// A number setting described once (issue 49 item 1): its key, bounds, unit and one-line help. A settings
// struct lists its numbers in a VisitFields (sysid::Disturbance, heli::HoverTrainingOptions,
// heli::ManeuverTrainingOptions); from that one list come the command's options with their bounds, the
// reading of a config, IsValid's bounds and the Python fields with their docs.
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace pegasus {

struct NumberSetting {
  const char* key;      // the config key (the option is `--KEY`, `_` written `-`)
  double lower, upper;  // bounds of the value (each element of a list)
  bool lower_open;      // (lower, upper] rather than [lower, upper]
  const char* unit;     // "" for a count or a fraction
  const char* help;     // the option's one line

  bool within(double x) const { return (lower_open ? x > lower : x >= lower) && x <= upper; }
  // "[0, 30]" or "(0, 3600]", the numbers written as an option's expectation writes them (1e12:
  // 1000000000000).
  std::string range() const;
  // The range and the unit: "[0, 30] m/s", "[0, 1]".
  std::string range_in_unit() const;
  // "NAME: expected WHAT in RANGE UNIT, got X" (what: "a number", "an integer", "numbers").
  std::string refusal(const std::string& name, const char* what, double x) const;
};

// For a settings struct whose VisitFields offers `setting(NumberSetting, &Options::member)` for each of its
// numbers (an int or a double member, named by the key): the settings in order, and the first value out of
// its bounds.
namespace detail {
template <class Options>
struct NumberSettingsList {
  std::vector<NumberSetting> settings;
  template <class T>
  void setting(const NumberSetting& s, T Options::* /*member*/) {
    settings.push_back(s);
  }
};
template <class Options>
struct NumberBoundsCheck {
  const Options& o;
  std::string error;
  template <class T>
  void setting(const NumberSetting& s, T Options::*member) {
    const auto x = static_cast<double>(o.*member);
    if (error.empty() && !s.within(x))
      error = s.refusal(s.key, std::is_integral_v<T> ? "an integer" : "a number", x);
  }
};
}  // namespace detail

template <class Options>
std::vector<NumberSetting> number_settings() {
  detail::NumberSettingsList<Options> v;
  Options::VisitFields(v);
  return v.settings;
}
// "KEY: expected a number in [0, 1], got 2" for the first number outside its bounds (NaN included), or "".
template <class Options>
std::string numbers_out_of_bounds(const Options& o) {
  detail::NumberBoundsCheck<Options> v{o, {}};
  Options::VisitFields(v);
  return v.error;
}

}  // namespace pegasus
