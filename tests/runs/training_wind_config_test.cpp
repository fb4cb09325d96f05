// The training wind's settings, described once (sysid::Disturbance::VisitFields, issue 49 item 1): each
// setting is `hover`'s and `maneuver`'s option wind.KEY with its default, help and bounds, a vehicle file's
// [hover.wind] KEY within the same bounds, the member it names, IsValid's bound, and its key in
// summary.json's `wind`, described in the key table. A setting added to the description is walked here too.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "logs/outside_aircraft.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/heli/runs/maneuver_config.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/report/summary_keys.hpp"
#include "pegasus/sysid/learned_model.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace pegasus::heli {
namespace {

using sysid::Disturbance;
using sysid::DisturbanceSetting;
using test_support::input_error_message;

// The value of the setting `key` in d, every element.
std::vector<double> value_of(const Disturbance& d, const std::string& key) {
  struct Reader {
    const Disturbance& d;
    std::string key;
    std::vector<double> out;
    void setting(const DisturbanceSetting& s, double Disturbance::*member) {
      if (key == s.key) out = {d.*member};
    }
    void setting(const DisturbanceSetting& s, std::array<double, 3> Disturbance::*member) {
      if (key == s.key) out.assign((d.*member).begin(), (d.*member).end());
    }
  } reader{d, key, {}};
  Disturbance::VisitFields(reader);
  return reader.out;
}

bool is_list(const DisturbanceSetting& s) { return value_of(Disturbance{}, s.key).size() == 3; }

// Within the bounds and not a default; and just beyond the upper one.
double inside(const DisturbanceSetting& s) { return s.lower + (s.upper - s.lower) / 7; }
double beyond(const DisturbanceSetting& s) { return s.upper + 1; }
FieldValue option_value(const DisturbanceSetting& s, double x) {
  if (is_list(s)) return std::vector<double>{x, -x / 2, x / 4};
  return x;
}
std::vector<double> values(const DisturbanceSetting& s, double x) {
  if (is_list(s)) return {x, -x / 2, x / 4};
  return {x};
}
std::string toml_value(const DisturbanceSetting& s, double x) {
  if (is_list(s)) return fmt::format("[{}, {}, {}]", x, -x / 2, x / 4);
  return fmt::format("{}", x);
}
std::string option_of(const DisturbanceSetting& s) { return std::string("wind.") + s.key; }

class TrainingWindConfig : public test_support::TempDirTest {
 protected:
  // The outside helicopter's vehicle file (NED) with `more` appended; its path.
  std::string vehicle(const std::string& more) const {
    const std::filesystem::path file = dir_ / "v.toml";
    std::ofstream(file) << test_support::kOutsideVehicle << "\n" << more;
    return file.string();
  }
};

TEST_F(TrainingWindConfig, EverySettingIsAnOptionOfHoverAndManeuverWithItsDefaultHelpAndBounds) {
  ASSERT_EQ(Disturbance::settings().size(), 4u);
  for (const DisturbanceSetting& setting : Disturbance::settings()) {
    SCOPED_TRACE(setting.key);
    ConfigSchema hover;
    declare_hover_config(hover);
    ConfigSchema maneuver;
    declare_maneuver_config(maneuver);
    for (ConfigSchema* s : {&hover, &maneuver}) {
      const ConfigField& f = s->field(option_of(setting));
      EXPECT_EQ(f.help(), setting.help);
      if (is_list(setting)) {
        EXPECT_EQ(std::get<std::vector<double>>(f.default_value()), value_of(Disturbance{}, setting.key));
      } else {
        EXPECT_EQ(std::get<double>(f.default_value()), value_of(Disturbance{}, setting.key)[0]);
      }
      const std::string message =
          input_error_message([&] { s->set(option_of(setting), option_value(setting, beyond(setting))); });
      EXPECT_NE(message.find(option_of(setting)), std::string::npos) << message;
      if (setting.lower_open) {
        EXPECT_NE(
            input_error_message([&] { s->set(option_of(setting), option_value(setting, setting.lower)); }),
            "(no error)");
      }
    }
    hover.set(option_of(setting), option_value(setting, inside(setting)), "--" + option_of(setting));
    hover.validate();
    const Disturbance d = read_hover_config(hover, 7).training.disturbance;
    EXPECT_EQ(value_of(d, setting.key), values(setting, inside(setting)));
  }
}

TEST_F(TrainingWindConfig, EverySettingIsAVehicleFileKeyWithinTheSameBounds) {
  for (const DisturbanceSetting& setting : Disturbance::settings()) {
    SCOPED_TRACE(setting.key);
    const std::string file =
        vehicle(fmt::format("[hover.wind]\n{} = {}\n", setting.key, toml_value(setting, inside(setting))));
    const logs::Vehicle v = logs::read_vehicle(file);
    ASSERT_TRUE(v.wind.has_value());
    EXPECT_EQ(value_of(*v.wind, setting.key), values(setting, inside(setting)));
    ConfigSchema s;
    declare_hover_config(s);
    s.set("vehicle", file, "--vehicle");
    resolve_hover_config(s);
    s.validate();
    EXPECT_EQ(s.origin(option_of(setting)), file + ": hover.wind." + setting.key);
    EXPECT_EQ(value_of(read_hover_config(s, 7).training.disturbance, setting.key),
              values(setting, inside(setting)));

    const std::string bad =
        vehicle(fmt::format("[hover.wind]\n{} = {}\n", setting.key, toml_value(setting, beyond(setting))));
    const std::string message = input_error_message([&] { (void)logs::read_vehicle(bad); });
    EXPECT_NE(message.find(fmt::format("hover.wind.{}: expected", setting.key)), std::string::npos)
        << message;
    EXPECT_NE(message.find(setting.range()), std::string::npos) << message;
  }
}

TEST_F(TrainingWindConfig, IsValidBoundsEverySettingAndTheSummaryWritesAndDescribesEach) {
  for (const DisturbanceSetting& setting : Disturbance::settings()) {
    SCOPED_TRACE(setting.key);
    Disturbance d;
    // Set through the description, as the config reads it.
    struct Writer {
      Disturbance& d;
      const DisturbanceSetting& target;
      double x;
      void setting(const DisturbanceSetting& s, double Disturbance::*member) {
        if (std::string(s.key) == target.key) d.*member = x;
      }
      void setting(const DisturbanceSetting& s, std::array<double, 3> Disturbance::*member) {
        if (std::string(s.key) == target.key) d.*member = {x, -x / 2, x / 4};
      }
    };
    Writer writer{d, setting, inside(setting)};
    Disturbance::VisitFields(writer);
    std::string error;
    EXPECT_TRUE(d.IsValid(&error)) << error;
    const nlohmann::json summary = wind_summary(d);
    ASSERT_TRUE(summary.contains(setting.summary_key));
    EXPECT_EQ(summary[setting.summary_key].is_array()
                  ? summary[setting.summary_key].get<std::vector<double>>()
                  : std::vector<double>{summary[setting.summary_key]},
              values(setting, inside(setting)));
    for (const char* command : {"hover", "maneuver"})
      EXPECT_NE(report::describe_summary_key(command, {"wind", setting.summary_key}), nullptr) << command;

    Writer out_of_bounds{d, setting, beyond(setting)};
    Disturbance::VisitFields(out_of_bounds);
    EXPECT_FALSE(d.IsValid(&error));
    EXPECT_EQ(error.rfind(std::string(setting.field) + ": expected", 0), 0u) << error;
    EXPECT_NE(error.find(setting.range()), std::string::npos) << error;
  }
  EXPECT_EQ(wind_summary(Disturbance{}).size(), Disturbance::settings().size());
}

}  // namespace
}  // namespace pegasus::heli
