#include "pegasus/runs/config.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>

#include "pegasus/core/error.hpp"
#include "support/input_error.hpp"

namespace pegasus {

using test_support::input_error_message;
namespace {

ConfigSchema example_schema() {
  ConfigSchema s;
  s.add_double("gamma", 0.99, "discount factor").range(0, 1);
  s.add_int("scenarios", 30, "number of scenarios m").min(1);
  s.add_bool("shaping", true, "use the shaped reward");
  s.add_string("variant", "plain", "scenario variant").choices({"plain", "antithetic"});
  s.add_int_list("sizes", {1, 2, 4}, "scenario counts to sweep").min(1).min_size(1);
  s.add_double_list("noise", {0.0, 0.5}, "noise levels").min(0);
  s.add_int("threads", 4, "threads").min(1).affects_results(false);
  s.add_double("optimizer.step", 0.1, "step size").greater_than(0);
  s.add_int("optimizer.iterations", 100, "iterations").min(1);
  return s;
}

TEST(ConfigSchema, TypedGettersReturnDefaults) {
  const ConfigSchema s = example_schema();
  EXPECT_EQ(s.get_double("gamma"), 0.99);
  EXPECT_EQ(s.get_int("scenarios"), 30);
  EXPECT_TRUE(s.get_bool("shaping"));
  EXPECT_EQ(s.get_string("variant"), "plain");
  EXPECT_EQ(s.get_int_list("sizes"), (std::vector<std::int64_t>{1, 2, 4}));
  EXPECT_EQ(s.get_double_list("noise"), (std::vector<double>{0.0, 0.5}));
  EXPECT_EQ(s.get_double("optimizer.step"), 0.1);
  EXPECT_EQ(s.origin("gamma"), "default");
}

// A file field's relative value is found from the base directory, and named back as the config gives it;
// the recorded value (config.toml) stays the text given.
TEST(ConfigSchema, FileFieldsAreFoundFromTheBaseDirectoryAndRecordedAsGiven) {
  ConfigSchema s;
  s.add_string("model", "", "model file");
  s.add_string("absolute", "", "another file");
  s.add_string_list("logs", {}, "log files");
  s.set("model", std::string("identify/model.json"));
  s.set("absolute", std::string("/data/m.json"));
  s.set("logs", std::vector<std::string>{"a/log.csv", "", "/b/log.csv"});
  EXPECT_EQ(s.get_path("model"), "identify/model.json");  // no base: the working directory's
  const std::string text = s.to_toml();
  s.set_base_directory("/runs/demo.partial");
  EXPECT_EQ(s.get_path("model"), "/runs/demo.partial/identify/model.json");
  EXPECT_EQ(s.get_path("absolute"), "/data/m.json");
  EXPECT_EQ(s.get_path_list("logs"),
            (std::vector<std::string>{"/runs/demo.partial/a/log.csv", "", "/b/log.csv"}));
  EXPECT_EQ(s.get_string("model"), "identify/model.json");
  EXPECT_EQ(s.to_toml(), text);
  EXPECT_EQ(s.with_defaults().base_directory(), s.base_directory());

  EXPECT_EQ(path_named_from(s.base_directory(), s.get_path("model")), "identify/model.json");
  EXPECT_EQ(path_named_from(s.base_directory(), "/data/m.json"), "/data/m.json");
  EXPECT_EQ(path_named_from("/runs/demo", "/runs/demo.partial/x"), "/runs/demo.partial/x");  // not under it
  EXPECT_EQ(path_named_from("/runs/demo/", "/runs/demo/fly/a.svg"), "fly/a.svg");
  EXPECT_EQ(path_named_from("", "fly/a.svg"), "fly/a.svg");
}

TEST(ConfigSchema, FileOverridesDefaultsAndCliOverridesFile) {
  ConfigSchema s = example_schema();
  s.load_toml_string("gamma = 0.5\nscenarios = 7\nsizes = [3]\n[optimizer]\nstep = 2\n", "run.toml");
  EXPECT_EQ(s.get_double("gamma"), 0.5);
  EXPECT_EQ(s.get_double("optimizer.step"), 2.0);  // an integer is accepted for a number
  EXPECT_EQ(s.origin("gamma"), "run.toml:1");
  s.set_from_cli("gamma", "0.25");
  s.set_from_cli("sizes", "1,2, 8");
  s.set_from_cli("shaping", "false");
  s.set_from_cli("optimizer.iterations", "5");
  EXPECT_EQ(s.get_double("gamma"), 0.25);
  EXPECT_EQ(s.origin("gamma"), "--gamma");
  EXPECT_EQ(s.get_int("scenarios"), 7);
  EXPECT_EQ(s.get_int_list("sizes"), (std::vector<std::int64_t>{1, 2, 8}));
  EXPECT_FALSE(s.get_bool("shaping"));
  EXPECT_EQ(s.get_int("optimizer.iterations"), 5);
}

// where() names a field as the checks of its value name it, wherever its value came from.
TEST(ConfigSchema, WhereNamesAFieldAsItsValuesChecksDo) {
  ConfigSchema s = example_schema();
  EXPECT_EQ(s.where("gamma"), "gamma");
  s.load_toml_string("scenarios = 7\n[optimizer]\nstep = 2\n", "run.toml");
  EXPECT_EQ(s.where("optimizer.step"), "run.toml:3: key 'optimizer.step'");
  EXPECT_EQ(
      input_error_message([&] { s.load_toml_string("scenarios = 7\n[optimizer]\nstep = 0.0", "run.toml"); }),
      s.where("optimizer.step") + ": expected a number > 0, got 0.0");
  s.set_from_cli("gamma", "0.25");
  EXPECT_EQ(s.where("gamma"), "--gamma");
  s.set("scenarios", std::int64_t{3}, "V.toml: hover.scenarios");
  EXPECT_EQ(s.where("scenarios"), "V.toml: hover.scenarios");
  EXPECT_EQ(s.with_defaults().where("scenarios"), "scenarios");
}

TEST(ConfigSchema, OutOfRangeInFileNamesFileLineKeyExpectationAndValue) {
  ConfigSchema s = example_schema();
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("# comment\n\ngamma = 1.5\n", "config.toml"); }),
            "config.toml:3: key 'gamma': expected a number in [0, 1], got 1.5");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("scenarios = 0", "c.toml"); }),
            "c.toml:1: key 'scenarios': expected an integer >= 1, got 0");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("[optimizer]\nstep = 0.0", "c.toml"); }),
            "c.toml:2: key 'optimizer.step': expected a number > 0, got 0.0");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("sizes = [1, 0]", "c.toml"); }),
            "c.toml:1: key 'sizes': expected a list of integers (at least 1), each >= 1, got [1, 0]");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("sizes = []", "c.toml"); }),
            "c.toml:1: key 'sizes': expected a list of integers (at least 1), each >= 1, got []");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("variant = \"sobol\"", "c.toml"); }),
            "c.toml:1: key 'variant': expected one of \"plain\", \"antithetic\", got \"sobol\"");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("gamma = nan", "c.toml"); }),
            "c.toml:1: key 'gamma': expected a number in [0, 1], got nan");
}

// An option given on the command line replaces the file's value before the file's is range-checked; its type
// is still checked.
TEST(ConfigSchema, AFieldOverriddenOnTheCommandLineIsOnlyTypeCheckedInTheFile) {
  ConfigSchema s = example_schema();
  s.load_toml_string("gamma = 1.5\nscenarios = 7\n", "c.toml", {"gamma"});
  EXPECT_EQ(s.get_int("scenarios"), 7);
  s.set_from_cli("gamma", "0.25");
  EXPECT_EQ(s.get_double("gamma"), 0.25);
  EXPECT_EQ(s.origin("gamma"), "--gamma");
  EXPECT_EQ(
      input_error_message([&] { example_schema().load_toml_string("gamma = \"x\"", "c.toml", {"gamma"}); }),
      "c.toml:1: key 'gamma': expected a number in [0, 1], got the string \"x\"");
  EXPECT_EQ(
      input_error_message([&] { example_schema().load_toml_string("gamma = 1.5", "c.toml", {"scenarios"}); }),
      "c.toml:1: key 'gamma': expected a number in [0, 1], got 1.5");
}

TEST(ConfigSchema, WrongTypeInFileNamesFileLineKeyAndExpectation) {
  ConfigSchema s = example_schema();
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("gamma = \"high\"", "c.toml"); }),
            "c.toml:1: key 'gamma': expected a number in [0, 1], got the string \"high\"");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("\nscenarios = 2.5", "c.toml"); }),
            "c.toml:2: key 'scenarios': expected an integer >= 1, got the float 2.5");
  // A whole number written as a float is not an integer either, and the message says why.
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("scenarios = 7.0", "c.toml"); }),
            "c.toml:1: key 'scenarios': expected an integer >= 1, got the float 7.0");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("shaping = 1", "c.toml"); }),
            "c.toml:1: key 'shaping': expected true or false, got 1");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("sizes = [1, \"2\"]", "c.toml"); }),
            "c.toml:1: key 'sizes': expected a list of integers (at least 1), each >= 1, got an array");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("gamma = [0.5]", "c.toml"); }),
            "c.toml:1: key 'gamma': expected a number in [0, 1], got an array");
  EXPECT_EQ(
      input_error_message([&] { s.load_toml_string("optimizer = 3", "c.toml"); }),
      "c.toml:1: unknown key 'optimizer' (known keys: gamma, scenarios, shaping, variant, sizes, noise, "
      "threads, optimizer.step, optimizer.iterations)");
}

TEST(ConfigSchema, UnknownKeyNamesFileLineAndSuggestsTheClosestField) {
  ConfigSchema s = example_schema();
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("scenarios = 3\ngama = 0.5\n", "c.toml"); }),
            "c.toml:2: unknown key 'gama' (did you mean 'gamma'?)");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("[optimizer]\nsteps = 0.5\n", "c.toml"); }),
            "c.toml:2: unknown key 'optimizer.steps' (did you mean 'optimizer.step'?)");
  EXPECT_EQ(input_error_message([&] {
              s.load_toml_string("[solver]\nx = 1\n", "c.toml");
            }).rfind("c.toml:1: unknown key 'solver' (", 0),
            0u);
}

// Settings a program gives by name (call_command, Python's keyword arguments) are read as a file is, and
// messages name the caller and the setting, never a line of text the caller did not write.
TEST(ConfigSchema, SettingsGivenByAProgramNameTheSettingNotALine) {
  ConfigSchema s = example_schema();
  s.load_settings("scenarios = 7\noptimizer.step = 2\n", "heli pipeline");
  EXPECT_EQ(s.get_int("scenarios"), 7);
  EXPECT_EQ(s.get_double("optimizer.step"), 2.0);
  EXPECT_EQ(s.origin("scenarios"), "heli pipeline: scenarios");
  EXPECT_EQ(input_error_message([&] { s.load_settings("scenarios = 3\ngamma = 1.5\n", "heli pipeline"); }),
            "heli pipeline: setting 'gamma': expected a number in [0, 1], got 1.5");
  EXPECT_EQ(input_error_message([&] { s.load_settings("scenarios = \"x\"\n", "heli pipeline"); }),
            "heli pipeline: setting 'scenarios': expected an integer >= 1, got the string \"x\"");
  EXPECT_EQ(input_error_message([&] { s.load_settings("gama = 0.5\n", "heli pipeline"); }),
            "heli pipeline: unknown setting 'gama' (did you mean 'gamma'?)");
}

TEST(ConfigSchema, SyntaxErrorAndUnreadableFileNameTheFile) {
  ConfigSchema s = example_schema();
  const std::string syntax =
      input_error_message([&] { s.load_toml_string("gamma = 0.5\nscenarios = = 3\n", "c.toml"); });
  EXPECT_EQ(syntax.rfind("c.toml:2: invalid TOML: ", 0), 0u) << syntax;
  EXPECT_EQ(input_error_message([&] {
              s.load_toml_string("gamma = 0.5\ngamma = 0.6\n", "c.toml");
            }).rfind("c.toml:2:", 0),
            0u);
  const std::string missing = input_error_message([&] { s.load_toml_file("/nonexistent/dir/run.toml"); });
  EXPECT_EQ(missing, "/nonexistent/dir/run.toml: cannot read config file: No such file or directory");
  EXPECT_EQ(input_error_message([&] { s.load_toml_file("/tmp"); }).rfind("/tmp: cannot read config file", 0),
            0u);
}

TEST(ConfigSchema, CliErrorsNameTheOptionAndExpectation) {
  ConfigSchema s = example_schema();
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("gamma", "1.5"); }),
            "--gamma: expected a number in [0, 1], got '1.5'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("gamma", "abc"); }),
            "--gamma: expected a number in [0, 1], got 'abc'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("gamma", ""); }),
            "--gamma: expected a number in [0, 1], got an empty value");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("scenarios", "0"); }),
            "--scenarios: expected an integer >= 1, got '0'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("scenarios", "2.5"); }),
            "--scenarios: expected an integer >= 1, got '2.5'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("scenarios", "99999999999999999999"); }),
            "--scenarios: expected an integer >= 1 and at most 9223372036854775807, got "
            "'99999999999999999999'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("shaping", "maybe"); }),
            "--shaping: expected true or false, got 'maybe'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("sizes", "1,x"); }),
            "--sizes: expected a list of integers (at least 1), each >= 1, got '1,x'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("noise", "0.1,-1"); }),
            "--noise: expected a list of numbers, each >= 0, got '0.1,-1'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("optimizer.iterations", "0"); }),
            "--optimizer.iterations: expected an integer >= 1, got '0'");
  // A rejected value leaves the old one in place.
  EXPECT_EQ(s.get_double("gamma"), 0.99);
}

TEST(ConfigSchema, CustomValidatorsAndConstraints) {
  ConfigSchema s;
  s.add_int("m", 8, "scenarios").min(1).validate([](const FieldValue& v) {
    const auto m = std::get<std::int64_t>(v);
    return (m & (m - 1)) == 0 ? std::string() : std::string("a power of two");
  });
  s.add_double("lo", 0, "low end");
  s.add_double("hi", 1, "high end");
  s.add_constraint([](const ConfigSchema& c) {
    return c.get_double("lo") < c.get_double("hi") ? std::string()
                                                   : "--lo/--hi: expected lo < hi, got lo (" +
                                                         c.origin("lo") + ") >= hi (" + c.origin("hi") + ")";
  });
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("m", "6"); }), "--m: expected a power of two, got '6'");
  s.set_from_cli("m", "16");
  s.validate();
  s.set_from_cli("lo", "2");
  EXPECT_EQ(input_error_message([&] { s.validate(); }),
            "--lo/--hi: expected lo < hi, got lo (--lo) >= hi (default)");
}

TEST(ConfigSchema, ResolvedTomlLoadsBackToTheSameValues) {
  ConfigSchema s = example_schema();
  s.add_string("note", "", "free text");
  s.add_double("tiny", 5e-324, "denormal");
  s.add_double("negative_zero", -0.0, "signed zero");
  s.add_double("third", 1.0 / 3.0, "not a short decimal");
  s.add_double("huge", 1e300, "large");
  s.add_double("infinite", std::numeric_limits<double>::infinity(), "unbounded");
  s.add_int("big", std::numeric_limits<std::int64_t>::min(), "extreme integer");
  s.add_double_list("empty", {}, "empty list");
  s.add_double_list("grid", {0.1, 0.2, 0.30000000000000004, 1e-5, 12345678.9}, "grid");
  s.set("note", std::string("quote \" backslash \\ tab \t newline \n unicode \xC3\xA9 ctrl \x01 end"));
  s.set_from_cli("optimizer.step", "0.7000000000000001");
  const std::string toml = s.to_toml();

  ConfigSchema back = s.with_defaults();
  EXPECT_TRUE(back.first_difference(s).has_value());
  back.load_toml_string(toml, "resolved.toml");
  EXPECT_EQ(back.first_difference(s), std::nullopt) << toml;
  EXPECT_EQ(back.to_toml(), toml);
  EXPECT_EQ(back.get_string("note"), s.get_string("note"));
  EXPECT_TRUE(std::signbit(back.get_double("negative_zero")));
  EXPECT_EQ(back.get_double("tiny"), 5e-324);
  EXPECT_EQ(back.get_double("third"), 1.0 / 3.0);
  // The help of every field is a comment right above it.
  EXPECT_NE(toml.find("# discount factor [a number in [0, 1]]\ngamma = 0.99\n"), std::string::npos) << toml;
  EXPECT_NE(toml.find("[optimizer]\n"), std::string::npos);
}

// A list of a fixed length (a NumberList setting's, fly's wind): fewer and more elements are refused, saying
// the length; the bounds still hold for each element.
TEST(ConfigSchema, AListOfAFixedSizeRefusesOtherLengths) {
  ConfigSchema s;
  s.add_double_list("wind", {0, 0, 0}, "steady wind").range(-30, 30).size(3);
  s.add_string_list("pair", {"a", "b"}, "two names").size(2);
  for (const char* bad : {"1,2", "1,2,3,4", "1,2,31"})
    EXPECT_EQ(input_error_message([&] { s.set_from_cli("wind", bad); }),
              fmt::format("--wind: expected a list of 3 numbers, each in [-30, 30], got '{}'", bad));
  s.set_from_cli("wind", "1,-2,0.5");
  EXPECT_EQ(s.get_double_list("wind"), (std::vector<double>{1, -2, 0.5}));
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("pair", "a,b,c"); }),
            "--pair: expected a list of 2 strings, got 'a,b,c'");
}

// Lists of files (heli identify --noise-check-logs): TOML arrays of strings, commas on the command line.
TEST(ConfigSchema, StringListsReadFromTomlAndCliAndLoadBack) {
  ConfigSchema s = example_schema();
  s.add_string_list("logs", {}, "more logs").min_size(0);
  s.add_string_list("two", {"a", "b"}, "at least two").min_size(2);
  EXPECT_TRUE(s.get_string_list("logs").empty());
  s.load_toml_string("logs = [\"x.csv\", \"dir with space/y.csv\"]\n", "run.toml");
  EXPECT_EQ(s.get_string_list("logs"), (std::vector<std::string>{"x.csv", "dir with space/y.csv"}));
  EXPECT_EQ(s.origin("logs"), "run.toml:1");
  // A space after a comma is not part of the next file's name.
  s.set_from_cli("logs", "a.csv, b.csv,c.csv");
  EXPECT_EQ(s.get_string_list("logs"), (std::vector<std::string>{"a.csv", "b.csv", "c.csv"}));
  s.set_from_cli("logs", "");
  EXPECT_TRUE(s.get_string_list("logs").empty());
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("logs", "a.csv,,b.csv"); }),
            "--logs: expected a list of strings, got 'a.csv,,b.csv'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("two", "one.csv"); }),
            "--two: expected a list of strings (at least 2), got 'one.csv'");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("logs = [\"x.csv\", 3]\n", "run.toml"); }),
            "run.toml:1: key 'logs': expected a list of strings, got an array");
  EXPECT_EQ(input_error_message([&] { s.load_toml_string("logs = \"x.csv\"\n", "run.toml"); }),
            "run.toml:1: key 'logs': expected a list of strings, got the string \"x.csv\"");

  s.set("logs", std::vector<std::string>{"q\"uote.csv", "back\\slash.csv"});
  const std::string toml = s.to_toml();
  EXPECT_NE(toml.find("logs = [\"q\\\"uote.csv\", \"back\\\\slash.csv\"]\n"), std::string::npos) << toml;
  ConfigSchema back = s.with_defaults();
  EXPECT_EQ(back.first_difference(s), "logs");
  back.load_toml_string(toml, "resolved.toml");
  EXPECT_EQ(back.first_difference(s), std::nullopt) << toml;
  EXPECT_EQ(back.get_string_list("logs"), s.get_string_list("logs"));
  EXPECT_EQ(s.to_json().at("logs"), nlohmann::json::parse(R"(["q\"uote.csv", "back\\slash.csv"])"));
}

TEST(ConfigSchema, RandomDoublesRoundTripBitForBit) {
  std::mt19937_64 bits(12345);  // a fixed seed: the test is deterministic
  for (int trial = 0; trial < 2000; ++trial) {
    double x;
    do {
      x = std::bit_cast<double>(bits());
    } while (std::isnan(x));
    ConfigSchema s;
    s.add_double("x", 0, "any");
    s.add_double_list("xs", {}, "any");
    s.set("x", x);
    s.set("xs", std::vector<double>{x, -x});
    ConfigSchema back = s.with_defaults();
    back.load_toml_string(s.to_toml(), "t.toml");
    ASSERT_EQ(std::bit_cast<std::uint64_t>(back.get_double("x")), std::bit_cast<std::uint64_t>(x)) << x;
    ASSERT_EQ(back.first_difference(s), std::nullopt) << x;
    // And through the command line.
    ConfigSchema cli = s.with_defaults();
    cli.set_from_cli("x", format_double(x));
    ASSERT_EQ(std::bit_cast<std::uint64_t>(cli.get_double("x")), std::bit_cast<std::uint64_t>(x));
  }
}

TEST(ConfigSchema, FirstDifferenceIgnoresFieldsThatCannotChangeResults) {
  ConfigSchema a = example_schema();
  ConfigSchema b = example_schema();
  b.set_from_cli("threads", "16");
  EXPECT_EQ(a.first_difference(b), std::nullopt);
  b.set_from_cli("optimizer.step", "0.2");
  EXPECT_EQ(a.first_difference(b), "optimizer.step");
  ConfigSchema c = example_schema();
  c.set("gamma", -0.0);
  ConfigSchema d = example_schema();
  d.set("gamma", 0.0);
  EXPECT_EQ(c.first_difference(d), "gamma");  // compared by bits
}

TEST(ConfigSchema, ToJsonNestsSections) {
  const nlohmann::json j = example_schema().to_json();
  EXPECT_EQ(j["gamma"], 0.99);
  EXPECT_EQ(j["optimizer"]["iterations"], 100);
  EXPECT_EQ(j["sizes"], nlohmann::json::array({1, 2, 4}));
}

TEST(ConfigSchema, ProgrammingErrorsAreLogicErrors) {
  ConfigSchema s = example_schema();
  EXPECT_THROW(s.get_int("gamma"), std::logic_error);
  EXPECT_THROW(s.get_double("nope"), std::logic_error);
  EXPECT_THROW(s.set_from_cli("nope", "1"), std::logic_error);
  EXPECT_THROW(s.add_int("gamma", 1, "twice"), std::logic_error);
  EXPECT_THROW(s.add_int("CamelCase", 1, "bad name"), std::logic_error);
  EXPECT_THROW(s.add_int("optimizer", 1, "clashes with the section"), std::logic_error);
  EXPECT_THROW(s.add_bool("flag", true, "x").min(0), std::logic_error);
}

TEST(ConfigSchema, OptionNamesAreKebabCase) {
  EXPECT_EQ(ConfigSchema::option_name("step_ms"), "--step-ms");
  EXPECT_EQ(ConfigSchema::option_name("optimizer.max_iterations"), "--optimizer.max-iterations");
}

}  // namespace
}  // namespace pegasus
