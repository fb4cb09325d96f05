// The training options' numbers, described once (HoverTrainingOptions::VisitFields and
// ManeuverTrainingOptions::VisitFields, issue 49 item 1): each is its command's option KEY with its default,
// help and bounds, read into the member it names, and IsValid's bound. A number added to a description is
// walked here too.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <map>
#include <string>
#include <type_traits>

#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/maneuver_task.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/heli/runs/log_import_run.hpp"
#include "pegasus/heli/runs/maneuver_config.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/sysid/identify.hpp"
#include "support/input_error.hpp"

namespace pegasus::heli {
namespace {

using test_support::input_error_message;

// The number `key` of o, and whether its member is an integer.
struct Number {
  double value = std::nan("");
  bool integer = false;
};
template <class Options>
struct NumberReader {
  const Options& o;
  std::string key;
  Number out;
  template <class T>
  void setting(const NumberSetting& s, T Options::*member) {
    if (key == s.key) out = {static_cast<double>(o.*member), std::is_integral_v<T>};
  }
};
template <class Options>
Number number_of(const Options& o, const std::string& key) {
  NumberReader<Options> reader{o, key, {}};
  Options::VisitFields(reader);
  return reader.out;
}

// Within the bounds, not the default, and an integer where the member is one; and just beyond each bound.
double inside(const NumberSetting& s, bool integer) {
  const double x = s.lower + (s.upper - s.lower) / 7;
  return integer ? std::ceil(x) : x;
}
double above(const NumberSetting& s) { return s.upper + 1; }
double below(const NumberSetting& s) { return s.lower_open ? s.lower : s.lower - 1; }
FieldValue option_value(double x, bool integer) {
  if (integer) return static_cast<std::int64_t>(x);
  return x;
}

// Each number is an option of the command `declare` declares, with its default, help and bounds, and the
// command's reading (`read`) puts a value given into its member.
template <class Options>
void expect_every_number_is_an_option(const std::function<void(ConfigSchema&)>& declare,
                                      const std::function<Options(const ConfigSchema&)>& read,
                                      const std::string& key_prefix = {}) {
  for (const NumberSetting& setting : number_settings<Options>()) {
    SCOPED_TRACE(setting.key);
    const Number defaults = number_of(Options{}, setting.key);
    const std::string key = key_prefix + setting.key;
    ConfigSchema s;
    declare(s);
    const ConfigField& f = s.field(key);
    EXPECT_EQ(f.help(), setting.help);
    EXPECT_EQ(f.type(), defaults.integer ? FieldType::kInt : FieldType::kDouble);
    if (defaults.integer)
      EXPECT_EQ(static_cast<double>(std::get<std::int64_t>(f.default_value())), defaults.value);
    else
      EXPECT_EQ(std::get<double>(f.default_value()), defaults.value);
    EXPECT_TRUE(setting.within(defaults.value));
    for (const double bad : {above(setting), below(setting)}) {
      const std::string message =
          input_error_message([&] { s.set(key, option_value(bad, defaults.integer)); });
      EXPECT_NE(message.find(key), std::string::npos) << bad << ": " << message;
    }
    const double x = inside(setting, defaults.integer);
    ASSERT_NE(x, defaults.value);
    s.set(key, option_value(x, defaults.integer), "--" + key);
    s.validate();
    EXPECT_EQ(number_of(read(s), setting.key).value, x);
  }
}

// IsValid takes each number within its bounds and refuses it past either, naming it and its range.
template <class Options>
void expect_is_valid_bounds_every_number() {
  for (const NumberSetting& setting : number_settings<Options>()) {
    SCOPED_TRACE(setting.key);
    const bool integer = number_of(Options{}, setting.key).integer;
    Options o;
    set_number(o, setting.key, inside(setting, integer));
    std::string error;
    EXPECT_TRUE(o.IsValid(&error)) << error;
    for (const double bad : {above(setting), below(setting)}) {
      set_number(o, setting.key, bad);
      EXPECT_FALSE(o.IsValid(&error)) << bad;
      EXPECT_NE(error.find(std::string(setting.key) + ": expected"), std::string::npos) << error;
      EXPECT_NE(error.find(setting.range()), std::string::npos) << error;
    }
    if (!integer) {
      set_number(o, setting.key, std::nan(""));
      EXPECT_FALSE(o.IsValid(&error));
    }
  }
}

TEST(HoverSettingsConfig, EveryNumberIsAnOptionOfHoverWithItsDefaultHelpAndBoundsAndIsReadIntoItsMember) {
  ASSERT_EQ(HoverTrainingOptions::settings().size(), 14u);
  expect_every_number_is_an_option<HoverTrainingOptions>(
      [](ConfigSchema& s) { declare_hover_config(s); },
      [](const ConfigSchema& s) { return read_hover_config(s, 7).training; });
}

TEST(HoverSettingsConfig, IsValidRefusesEachNumberBeyondItsBoundsNamingItAndItsRange) {
  expect_is_valid_bounds_every_number<HoverTrainingOptions>();
}

TEST(ManeuverSettingsConfig,
     EveryNumberIsAnOptionOfManeuverWithItsDefaultHelpAndBoundsAndIsReadIntoItsMember) {
  ASSERT_EQ(number_settings<ManeuverTrainingOptions>().size(), 7u);
  expect_every_number_is_an_option<ManeuverTrainingOptions>(
      [](ConfigSchema& s) { declare_maneuver_config(s); },
      [](const ConfigSchema& s) { return read_maneuver_config(s, 7).training; });
}

TEST(ManeuverSettingsConfig, IsValidRefusesEachNumberBeyondItsBoundsNamingItAndItsRange) {
  expect_is_valid_bounds_every_number<ManeuverTrainingOptions>();
}

// identify's model structure (ModelStructure): rate_hz as every number is, with IdentifyOptions::IsValid
// taking its bounds, and each switch an option of its default and help whose value is read into its member.
struct Flag {
  std::string help;
  bool value = false;
};
template <class Options>
struct FlagReader {
  const Options& o;
  std::map<std::string, Flag> flags;
  void flag(const FlagSetting& f, bool Options::*member) { flags[f.key] = {f.help, o.*member}; }
};
template <class Options>
std::map<std::string, Flag> flags_of(const Options& o) {
  FlagReader<Options> reader{o, {}};
  Options::VisitFlags(reader);
  return reader.flags;
}

// Each switch is a boolean option of the command `declare` declares, with its default and help, and the
// command's reading (`read`) puts the other value, given, into its member and leaves the others alone.
template <class Options>
void expect_every_flag_is_an_option(const std::function<void(ConfigSchema&)>& declare,
                                    const std::function<Options(const ConfigSchema&)>& read) {
  const std::map<std::string, Flag> defaults = flags_of(Options{});
  for (const auto& [key, flag] : defaults) {
    SCOPED_TRACE(key);
    ConfigSchema s;
    declare(s);
    const ConfigField& f = s.field(key);
    EXPECT_EQ(f.type(), FieldType::kBool);
    EXPECT_EQ(std::get<bool>(f.default_value()), flag.value);
    EXPECT_EQ(f.help(), flag.help);
    s.set(key, !flag.value, "--" + key);
    s.validate();
    for (const auto& [other, got] : flags_of(read(s)))
      EXPECT_EQ(got.value, other == key ? !flag.value : defaults.at(other).value) << other;
  }
}

TEST(IdentifySettingsConfig, TheModelStructureIsDescribedOnceAsIdentifysOptions) {
  ASSERT_EQ(number_settings<sysid::ModelStructure>().size(), 1u);
  expect_every_number_is_an_option<sysid::ModelStructure>(
      [](ConfigSchema& s) { declare_identify_config(s); },
      [](const ConfigSchema& s) { return read_identify_config(s).identify.structure; });
  sysid::IdentifyOptions o;
  std::string error;
  for (const double bad : {0.5, 100.0, std::nan("")}) {
    o.structure.rate_hz = bad;
    EXPECT_FALSE(o.IsValid(&error)) << bad;
    EXPECT_EQ(error, fmt::format("identify: rate_hz: expected a number in [1, 50] Hz, got {}", bad));
  }
  ASSERT_EQ(flags_of(sysid::ModelStructure{}).size(), 3u);
  expect_every_flag_is_an_option<sysid::ModelStructure>(
      [](ConfigSchema& s) { declare_identify_config(s); },
      [](const ConfigSchema& s) { return read_identify_config(s).identify.structure; });
}

// fly's switches (FlyRunOptions::VisitFlags), each an option read into its member.
TEST(FlySettingsConfig, EverySwitchIsAnOptionOfFlyReadIntoItsMember) {
  ASSERT_EQ(flags_of(FlyRunOptions{}).size(), 4u);
  expect_every_flag_is_an_option<FlyRunOptions>([](ConfigSchema& s) { declare_fly_config(s); },
                                                [](const ConfigSchema& s) { return read_fly_config(s, 7); });
}

// The ground truth's settings a user sets (GroundTruthSettings): fly's steady wind, a list of three numbers
// each within its bounds, and the estimate_noise switch of pilot and fly, one help for both, each read into
// its member.
TEST(FlySettingsConfig, TheGroundTruthsWindAndEstimateNoiseAreDescribedOnce) {
  ASSERT_EQ(number_settings<GroundTruthSettings>().size(), 1u);
  const NumberSetting wind = number_settings<GroundTruthSettings>()[0];
  ConfigSchema s;
  declare_fly_config(s);
  const ConfigField& f = s.field("wind");
  EXPECT_EQ(f.type(), FieldType::kDoubleList);
  EXPECT_EQ(f.help(), wind.help);
  EXPECT_EQ(std::get<std::vector<double>>(f.default_value()), (std::vector<double>{0, 0, 0}));
  for (const std::vector<double>& bad :
       {std::vector<double>{wind.upper + 1, 0, 0}, std::vector<double>{0, wind.lower - 1, 0},
        std::vector<double>{1, 2}}) {
    const std::string message = input_error_message([&] { s.set("wind", bad); });
    EXPECT_NE(message.find("wind: expected a list of 3 numbers, each in [-30, 30]"), std::string::npos)
        << message;
  }
  s.set("wind", std::vector<double>{1.5, -2, 0.25}, "--wind");
  s.validate();
  EXPECT_EQ(read_fly_config(s, 7).settings.mean_wind_W, Vec3(1.5, -2, 0.25));
  // IsValid's bound on the list, element by element.
  GroundTruthSettings g;
  EXPECT_EQ(numbers_out_of_bounds(g), "");
  g.mean_wind_W = Vec3(0, 31, 0);
  EXPECT_EQ(numbers_out_of_bounds(g), "wind: expected numbers in [-30, 30] m/s, got 31");

  ASSERT_EQ(flags_of(GroundTruthSettings{}).size(), 1u);
  expect_every_flag_is_an_option<GroundTruthSettings>(
      [](ConfigSchema& schema) { declare_fly_config(schema); },
      [](const ConfigSchema& c) { return read_fly_config(c, 7).settings; });
  expect_every_flag_is_an_option<GroundTruthSettings>(
      [](ConfigSchema& schema) { declare_pilot_config(schema); },
      [](const ConfigSchema& c) { return read_pilot_config(c, 7).settings; });
}

// heli maneuver's flights and flight_start_sigma (ManeuverFlightOptions): options, reading and IsValid from
// one description; IsValid now bounds the start perturbation as the option does.
TEST(ManeuverSettingsConfig, EveryFlightNumberIsAnOptionOfManeuverWithItsBoundsInIsValidToo) {
  ASSERT_EQ(number_settings<ManeuverFlightOptions>().size(), 2u);
  expect_every_number_is_an_option<ManeuverFlightOptions>(
      [](ConfigSchema& s) { declare_maneuver_config(s); },
      [](const ConfigSchema& s) { return read_maneuver_config(s, 7).flights; });
  expect_is_valid_bounds_every_number<ManeuverFlightOptions>();
  ManeuverFlightOptions o;
  o.start_pos_sigma = 11;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_EQ(error, "flight_start_sigma: expected a number in [0, 10] m, got 11");
}

TEST(IdentifySettingsConfig,
     EveryNumberIsAnOptionOfIdentifyWithItsDefaultHelpAndBoundsAndIsReadIntoItsMember) {
  ASSERT_EQ(number_settings<sysid::IdentifyOptions>().size(), 5u);
  expect_every_number_is_an_option<sysid::IdentifyOptions>(
      [](ConfigSchema& s) { declare_identify_config(s); },
      [](const ConfigSchema& s) { return read_identify_config(s).identify; });
}

TEST(IdentifySettingsConfig, IsValidRefusesEachNumberBeyondItsBoundsNamingItAndItsRange) {
  expect_is_valid_bounds_every_number<sysid::IdentifyOptions>();
}

// The report's numbers (IdentifyRunOptions) and the bandwidth floors (bandwidth_floor.KEY) the same way.
TEST(IdentifySettingsConfig, EveryReportNumberAndBandwidthFloorIsAnOptionReadIntoItsMemberWithinItsBounds) {
  ASSERT_EQ(number_settings<IdentifyRunOptions>().size(), 4u);
  expect_every_number_is_an_option<IdentifyRunOptions>(
      [](ConfigSchema& s) { declare_identify_config(s); },
      [](const ConfigSchema& s) { return read_identify_config(s); });
  expect_is_valid_bounds_every_number<IdentifyRunOptions>();
  ASSERT_EQ(number_settings<sysid::BandwidthFloor>().size(), 5u);
  for (const auto& declare :
       {std::function<void(ConfigSchema&)>([](ConfigSchema& s) { declare_identify_config(s); }),
        std::function<void(ConfigSchema&)>([](ConfigSchema& s) { declare_log_import_config(s); })})
    expect_every_number_is_an_option<sysid::BandwidthFloor>(
        declare, [](const ConfigSchema& s) { return read_bandwidth_floor(s); }, sysid::kBandwidthFloorPrefix);
  expect_is_valid_bounds_every_number<sysid::BandwidthFloor>();
}

// fly's flights, seconds and trace_flights (FlightOptions), and the pipeline's flights and flight_seconds
// from the same description.
TEST(FlySettingsConfig, EveryFlightNumberIsAnOptionOfFlyAndThePipelineTakesItsOwnFromTheDescription) {
  ASSERT_EQ(number_settings<FlightOptions>().size(), 3u);
  expect_every_number_is_an_option<FlightOptions>(
      [](ConfigSchema& s) { declare_fly_config(s); },
      [](const ConfigSchema& s) { return read_fly_config(s, 7).flights; });
  expect_is_valid_bounds_every_number<FlightOptions>();
  ConfigSchema fly, pipeline;
  declare_fly_config(fly);
  declare_pipeline_config(pipeline);
  EXPECT_EQ(pipeline.field("flights").expectation(), fly.field("flights").expectation());
  EXPECT_EQ(pipeline.field("flight_seconds").expectation(), fly.field("seconds").expectation());
  EXPECT_EQ(pipeline.field("flight_seconds").help(), "on the ground truth: " + fly.field("seconds").help());
  EXPECT_FALSE(pipeline.has("seconds"));
  EXPECT_FALSE(pipeline.has("trace_flights"));
}

// identify's control_rate_hz is the rate hover training steps at: the bounds are hover's, so what one refuses
// the other does.
TEST(IdentifySettingsConfig, ControlRateTakesHoverTrainingsBounds) {
  const NumberSetting& identify = number_setting<IdentifyRunOptions>("control_rate_hz");
  const NumberSetting& hover = HoverTrainingOptions::setting("control_rate_hz");
  EXPECT_EQ(identify.range_in_unit(), hover.range_in_unit());
  IdentifyRunOptions o;
  o.control_rate_hz = 0.05;  // accepted before the bounds were hover's, though hover refuses it
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_EQ(error, "identify: control_rate_hz: expected a number in [0.1, 1000] Hz, got 0.05");
}

// `pipeline` and `log import` take some of identify's numbers, from the same description (log import with its
// own default window).
TEST(IdentifySettingsConfig, PipelineAndLogImportTakeIdentifysNumbersFromTheDescription) {
  ConfigSchema identify, pipeline, import;
  declare_identify_config(identify);
  declare_pipeline_config(pipeline);
  declare_log_import_config(import);
  for (const char* key : {"cv_points", "coordinate_passes"}) {
    SCOPED_TRACE(key);
    EXPECT_EQ(pipeline.field(key).help(), "identification: " + identify.field(key).help());
    EXPECT_EQ(pipeline.field(key).expectation(), identify.field(key).expectation());
  }
  for (const char* key : {"window_s", "cv_points", "coordinate_passes"}) {
    SCOPED_TRACE(key);
    EXPECT_EQ(import.field(key).help(), identify.field(key).help());
    EXPECT_EQ(import.field(key).expectation(), identify.field(key).expectation());
  }
  EXPECT_EQ(std::get<double>(import.field("window_s").default_value()), 8.0);
  import.set("window_s", 3.5, "--window-s");
  import.set("cv_points", std::int64_t{40}, "--cv-points");
  EXPECT_EQ(read_log_import_config(import).identification.window_s, 3.5);
  EXPECT_EQ(read_log_import_config(import).identification.cv_points, 40);
}

// The flights of `fly` start as perturbed as hover training's scenarios, from the same description; a
// manoeuvre's command margin is hover's, described once.
TEST(HoverSettingsConfig, FlyAndManeuverTakeTheSharedNumbersFromTheDescription) {
  ConfigSchema hover;
  declare_hover_config(hover);
  for (const char* key : {"start_pos_sigma", "start_vel_sigma"}) {
    SCOPED_TRACE(key);
    ConfigSchema fly;
    declare_fly_config(fly);
    EXPECT_EQ(fly.field(key).help(), hover.field(key).help());
    EXPECT_EQ(fly.field(key).expectation(), hover.field(key).expectation());
    EXPECT_EQ(std::get<double>(fly.field(key).default_value()), number_of(HoverTrainingOptions{}, key).value);
  }
  ConfigSchema maneuver;
  declare_maneuver_config(maneuver);
  EXPECT_EQ(maneuver.field("command_margin").help(), hover.field("command_margin").help());
  EXPECT_EQ(maneuver.field("command_margin").expectation(), hover.field("command_margin").expectation());
  EXPECT_EQ(ManeuverTrainingOptions{}.command_margin, HoverTrainingOptions{}.command_margin);
}

}  // namespace
}  // namespace pegasus::heli
