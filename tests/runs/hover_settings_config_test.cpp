// Hover training's numbers, described once (HoverTrainingOptions::VisitFields, issue 49 item 1): each is
// `hover`'s option KEY with its default, help and bounds, read into the member it names, and IsValid's bound.
// A number added to the description is walked here too.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <type_traits>

#include "pegasus/heli/hover_task.hpp"
#include "pegasus/runs/heli_config.hpp"
#include "pegasus/runs/heli_runs.hpp"
#include "support/input_error.hpp"

namespace pegasus::heli {
namespace {

using test_support::input_error_message;

// The number `key` of o, and whether its member is an integer.
struct Number {
  double value = std::nan("");
  bool integer = false;
};
struct NumberReader {
  const HoverTrainingOptions& o;
  std::string key;
  Number out;
  template <class T>
  void setting(const NumberSetting& s, T HoverTrainingOptions::*member) {
    if (key == s.key) out = {static_cast<double>(o.*member), std::is_integral_v<T>};
  }
};
Number number_of(const HoverTrainingOptions& o, const std::string& key) {
  NumberReader reader{o, key, {}};
  HoverTrainingOptions::VisitFields(reader);
  return reader.out;
}

// Sets the number `key` of o to x (truncated for an integer).
struct NumberWriter {
  HoverTrainingOptions& o;
  std::string key;
  double x;
  template <class T>
  void setting(const NumberSetting& s, T HoverTrainingOptions::*member) {
    if (key == s.key) o.*member = static_cast<T>(x);
  }
};
void set_number(HoverTrainingOptions& o, const std::string& key, double x) {
  NumberWriter writer{o, key, x};
  HoverTrainingOptions::VisitFields(writer);
}

// Within the bounds, not the default, and an integer where the member is one; and just beyond the upper
// bound.
double inside(const NumberSetting& s, bool integer) {
  const double x = s.lower + (s.upper - s.lower) / 7;
  return integer ? std::ceil(x) : x;
}
double beyond(const NumberSetting& s) { return s.upper + 1; }
FieldValue option_value(double x, bool integer) {
  if (integer) return static_cast<std::int64_t>(x);
  return x;
}

TEST(HoverSettingsConfig, EveryNumberIsAnOptionOfHoverWithItsDefaultHelpAndBoundsAndIsReadIntoItsMember) {
  ASSERT_GE(HoverTrainingOptions::settings().size(), 14u);
  for (const NumberSetting& setting : HoverTrainingOptions::settings()) {
    SCOPED_TRACE(setting.key);
    const Number defaults = number_of(HoverTrainingOptions{}, setting.key);
    ConfigSchema s;
    declare_hover_config(s);
    const ConfigField& f = s.field(setting.key);
    EXPECT_EQ(f.help(), setting.help);
    EXPECT_EQ(f.type(), defaults.integer ? FieldType::kInt : FieldType::kDouble);
    if (defaults.integer)
      EXPECT_EQ(static_cast<double>(std::get<std::int64_t>(f.default_value())), defaults.value);
    else
      EXPECT_EQ(std::get<double>(f.default_value()), defaults.value);
    EXPECT_TRUE(setting.within(defaults.value));

    const std::string message =
        input_error_message([&] { s.set(setting.key, option_value(beyond(setting), defaults.integer)); });
    EXPECT_NE(message.find(setting.key), std::string::npos) << message;
    const std::string below = input_error_message([&] {
      s.set(setting.key, option_value(setting.lower - (setting.lower_open ? 0 : 1), defaults.integer));
    });
    EXPECT_NE(below, "(no error)");

    const double x = inside(setting, defaults.integer);
    ASSERT_NE(x, defaults.value);
    s.set(setting.key, option_value(x, defaults.integer), std::string("--") + setting.key);
    s.validate();
    EXPECT_EQ(number_of(read_hover_config(s, 7).training, setting.key).value, x);
  }
}

TEST(HoverSettingsConfig, IsValidRefusesEachNumberBeyondItsBoundsNamingItAndItsRange) {
  for (const NumberSetting& setting : HoverTrainingOptions::settings()) {
    SCOPED_TRACE(setting.key);
    const bool integer = number_of(HoverTrainingOptions{}, setting.key).integer;
    HoverTrainingOptions o;
    set_number(o, setting.key, inside(setting, integer));
    std::string error;
    EXPECT_TRUE(o.IsValid(&error)) << error;
    for (const double bad : {beyond(setting), setting.lower - (setting.lower_open ? 0 : 1)}) {
      set_number(o, setting.key, bad);
      EXPECT_FALSE(o.IsValid(&error)) << bad;
      EXPECT_EQ(error.rfind(std::string(setting.key) + ": expected", 0), 0u) << error;
      EXPECT_NE(error.find(setting.range()), std::string::npos) << error;
    }
    if (!integer) {
      set_number(o, setting.key, std::nan(""));
      EXPECT_FALSE(o.IsValid(&error));
    }
  }
}

// The flights of `fly` start as perturbed as hover training's scenarios, from the same description.
TEST(HoverSettingsConfig, FlyTakesTheStartPerturbationsFromTheDescription) {
  for (const char* key : {"start_pos_sigma", "start_vel_sigma"}) {
    SCOPED_TRACE(key);
    ConfigSchema hover;
    declare_hover_config(hover);
    ConfigSchema fly;
    declare_fly_config(fly);
    EXPECT_EQ(fly.field(key).help(), hover.field(key).help());
    EXPECT_EQ(fly.field(key).expectation(), hover.field(key).expectation());
    EXPECT_EQ(std::get<double>(fly.field(key).default_value()), number_of(HoverTrainingOptions{}, key).value);
  }
}

}  // namespace
}  // namespace pegasus::heli
