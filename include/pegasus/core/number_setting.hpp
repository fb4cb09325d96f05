#pragma once
// A number setting described once (issue 49 item 1): its key, bounds, unit and one-line help. A settings
// struct lists its numbers in a VisitFields (sysid::Disturbance, heli::HoverTrainingOptions,
// heli::ManeuverTrainingOptions, sysid::IdentifyOptions, sysid::BandwidthFloor, heli::IdentifyRunOptions);
// from that one list come the command's options with their bounds, the reading of a config, IsValid's
// bounds and the Python fields or arguments with their docs and bounds.
#include <concepts>
#include <stdexcept>
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

// A switch a user sets (a bool member): its config key and the option's one line. A settings struct offers
// its switches in VisitFlags, `flag(FlagSetting, &Options::member)` for each, as it offers its numbers in
// VisitFields.
struct FlagSetting {
  const char* key;   // the config key (the option is `--KEY`, `_` written `-`)
  const char* help;  // the option's one line
};

// A fixed-length list of numbers a setting may describe beside an int or a double (a steady wind's three
// components: std::array<double, 3>, Vec3): each element within the setting's bounds, and its length the
// default's.
template <class T>
concept NumberList = requires(const T& t) {
  t.size();
  { t[0] } -> std::convertible_to<double>;
};

// For a settings struct whose VisitFields offers `setting(NumberSetting, &Options::member)` for each of its
// numbers (an int, a double or a NumberList member, named by the key): the settings in order, and the first
// value out of its bounds.
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
    if (!error.empty()) return;
    if constexpr (NumberList<T>) {
      const T& list = o.*member;
      for (decltype(list.size()) i = 0; i < list.size() && error.empty(); ++i)
        if (!s.within(list[i])) error = s.refusal(s.key, "numbers", list[i]);
    } else {
      const auto x = static_cast<double>(o.*member);
      if (!s.within(x)) error = s.refusal(s.key, std::is_integral_v<T> ? "an integer" : "a number", x);
    }
  }
};
template <class Options>
struct NumberAssign {
  Options& o;
  std::string_view key;
  double value;
  bool found = false;
  template <class T>
  void setting(const NumberSetting& s, T Options::*member) {
    if constexpr (!NumberList<T>) {  // one number; a list is set whole, by its member
      if (key != s.key) return;
      o.*member = static_cast<T>(value);
      found = true;
    }
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
// The setting named `key` of Options's list; std::logic_error when none is (a key is the code's, not a
// user's).
template <class Options>
const NumberSetting& number_setting(std::string_view key) {
  static const std::vector<NumberSetting> list = number_settings<Options>();
  for (const NumberSetting& s : list)
    if (key == s.key) return s;
  throw std::logic_error("no number setting named " + std::string(key));
}
// Sets the number named `key` (an integer member takes the value truncated; check it with
// numbers_out_of_bounds first where that matters); false when no setting has that key (or it is a list).
template <class Options>
bool set_number(Options& o, std::string_view key, double value) {
  detail::NumberAssign<Options> v{o, key, value};
  Options::VisitFields(v);
  return v.found;
}

}  // namespace pegasus
