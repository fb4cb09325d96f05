// Every reader of a user's file reports every failure as one line "FILE: FIELD: expected ..., got ..."
// (issue 16, cases 5, 6 and 9): numbers beyond a double, sizes that would allocate gigabytes, a directory
// where a file belongs, values that parse but mean nothing (model.json), bytes that are not UTF-8.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/logs/ulog_import.hpp"
#include "pegasus/mdp/mdp_json.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/shaping/shaping_table.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using pegasus::test_support::input_error_message;

class InputFiles : public pegasus::test_support::TempDirTest {
 protected:
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return (dir_ / name).string();
  }
};

// One line, beginning with the file's name, containing `expected`.
void expect_names(const std::string& message, const std::string& file, const std::string& expected) {
  EXPECT_EQ(message.rfind(file, 0), 0u) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  EXPECT_NE(message.find(expected), std::string::npos) << message;
}

TEST_F(InputFiles, ANumberBeyondADoubleIsBadInputNamingTheFileInEveryJsonReader) {
  const std::string mdp = write("m.json", R"({"format": "pegasus-mdp", "version": 1, "gamma": 1e999})");
  expect_names(input_error_message([&] { (void)pegasus::load_mdp(mdp); }), mdp,
               "within the range of a double");
  const std::string shaping =
      write("s.json", R"({"format": "pegasus-shaping", "entries": [[0, 0, 0, 1e999]]})");
  expect_names(input_error_message([&] { (void)pegasus::load_shaping(shaping); }), shaping,
               "within the range of a double");
  const std::string heli = write("h.json", R"({"format": "pegasus-heli-policy", "trim": [1e999, 0, 0, 0]})");
  expect_names(input_error_message([&] { (void)pegasus::heli::read_policy_file(heli); }), heli,
               "within the range of a double");
  const std::string bicycle =
      write("b.json", R"({"policy": "bicycle-sigmoid-15", "parameters": {"w0": -1e999}})");
  expect_names(input_error_message([&] { (void)pegasus::read_bicycle_policy(bicycle); }), bicycle,
               "within the range of a double");
  const std::string model = write("model.json", R"({"format": "pegasus-heli-model", "dt": 1e400})");
  expect_names(input_error_message([&] { (void)pegasus::sysid::IdentifiedModel::load(model); }), model,
               "within the range of a double");
}

TEST_F(InputFiles, ADirectoryWhereAFileBelongsIsNamedInEveryReader) {
  const fs::path folder = dir_ / "folder.json";
  fs::create_directories(folder);
  const std::string f = folder.string();
  expect_names(input_error_message([&] { (void)pegasus::load_mdp(f); }), f, "Is a directory");
  expect_names(input_error_message([&] { (void)pegasus::load_shaping(f); }), f, "Is a directory");
  expect_names(input_error_message([&] { (void)pegasus::heli::read_policy_file(f); }), f, "Is a directory");
  expect_names(input_error_message([&] { (void)pegasus::read_bicycle_policy(f); }), f, "Is a directory");
  expect_names(input_error_message([&] { (void)pegasus::sysid::IdentifiedModel::load(f); }), f,
               "Is a directory");
  expect_names(input_error_message([&] { (void)pegasus::sysid::read_flight_log(f); }), f, "Is a directory");
  expect_names(input_error_message([&] { (void)pegasus::logs::read_vehicle_log_spec(f); }), f,
               "Is a directory");
}

// Every TOML reader (run configs, vehicle files, MuJoCo tasks) goes through io/toml_input: bytes that are not
// UTF-8 never reach toml++ (Debian's 3.3.0 reads past its buffer on some), and the message names the line.
TEST_F(InputFiles, TomlReadersRefuseInvalidUtf8NamingTheLine) {
  const std::string vehicle = write("v.toml",
                                    "[vehicle]\nname = \"q\"\n[log]\nrate_hz = 5\xff"
                                    "0\n");
  expect_names(input_error_message([&] { (void)pegasus::logs::read_vehicle_log_spec(vehicle); }),
               vehicle + ":4", "expected UTF-8 text, got the byte 0xFF");
  const std::string syntax = write("s.toml", "[log]\nrate_hz = = 5\n");
  expect_names(input_error_message([&] { (void)pegasus::logs::read_vehicle_log_spec(syntax); }),
               syntax + ":2", "invalid TOML");
}

// What Debian's toml++ 3.3.0 misreads in valid UTF-8 (each fixed upstream) is read as upstream reads it now,
// or refused with one line, never undefined behaviour (io/toml_input.hpp): a character other than ASCII where
// the parser asks whether it is whitespace (3.3.0 reached __builtin_unreachable for U+00E9), "[&" as a table
// header (a broken precondition of its key parser), nesting beyond 64.
TEST(TomlInput, WhatToml330MisreadsIsReadAsUpstreamReadsItOrRefusedWithOneLine) {
  pegasus::ConfigSchema schema;
  schema.add_string("policy", "", "a path");
  schema.add_double("gamma", 0.5, "discount").range(0, 1);
  const auto refusal = [&](const std::string& text) {
    pegasus::ConfigSchema config = schema.with_defaults();
    return input_error_message([&] { config.load_toml_string(text, "c.toml"); });
  };
  expect_names(refusal("gamma = 0.1\npolicy = \"p\" \xc3\xa9\n"), "c.toml:2", "invalid TOML");
  expect_names(refusal("gamma = 0.1 \xc3\xa9\n"), "c.toml:1", "invalid TOML");
  expect_names(refusal("[\xcc\xaa]\n"), "c.toml", "invalid TOML");
  expect_names(refusal("[&]\ngamma = 0.1\n"), "c.toml", "invalid TOML");
  expect_names(refusal("policy = " + std::string(100, '[') + std::string(100, ']') + "\n"), "c.toml:1",
               "invalid TOML");

  // Characters other than ASCII where TOML allows them: strings, comments, and after a line-ending backslash.
  pegasus::ConfigSchema config = schema.with_defaults();
  ASSERT_NO_THROW(config.load_toml_string(
      "# caf\xc3\xa9\npolicy = \"r\xc3\xa9sum\xc3\xa9\\\\\" # \xe2\x82\xac\n", "c.toml"));
  EXPECT_EQ(config.get_string("policy"), "r\xc3\xa9sum\xc3\xa9\\");
  ASSERT_NO_THROW(config.load_toml_string("policy = \"\"\"a\\\n  \xe2\x82\xac\"\"\"\n", "c.toml"));
  EXPECT_EQ(config.get_string("policy"), "a\xe2\x82\xac");
  ASSERT_NO_THROW(config.load_toml_string("policy = \'\'\'\xc3\xa9\n\xc3\xa9\'\'\'\n", "c.toml"));
  EXPECT_EQ(config.get_string("policy"), "\xc3\xa9\n\xc3\xa9");
}

TEST_F(InputFiles, DeclaredMdpSizesAreRefusedBeforeAnythingIsAllocated) {
  const std::string huge =
      write("huge.json", R"({"format": "pegasus-mdp", "version": 1, "num_states": 2147483647,
    "num_actions": 2, "gamma": 0.5, "transitions": [{"state": 0, "action": 0, "next": [[0, 1]]}]})");
  const auto start = std::chrono::steady_clock::now();
  const std::string message = input_error_message([&] { (void)pegasus::load_mdp(huge); });
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  expect_names(message, huge + ": num_states: expected at most 1", "got 2147483647");
  const std::string actions =
      write("actions.json", R"({"format": "pegasus-mdp", "version": 1, "num_states": 1,
    "num_actions": 2147483647, "gamma": 0.5, "transitions": [{"state": 0, "action": 0, "next": [[0, 1]]}]})");
  expect_names(input_error_message([&] { (void)pegasus::load_mdp(actions); }), actions + ": num_actions",
               "got 2147483647");
  // The bound is what the file describes, so a complete MDP still loads.
  const std::string fine = write("fine.json", R"({"format": "pegasus-mdp", "version": 1, "num_states": 2,
    "num_actions": 1, "gamma": 0.5, "absorbing": [1], "transitions": [{"state": 0, "action": 0, "next": [[1, 1]]}]})");
  EXPECT_EQ(pegasus::load_mdp(fine).num_states, 2);
}

// A valid model.json (16 inputs, 8 outputs, 3 rows) to spoil one field at a time.
json valid_model() {
  json x = json::array(), y = json::array();
  for (int i = 0; i < 3; ++i) {
    json xr = json::array(), yr = json::array();
    for (int k = 0; k < 16; ++k) xr.push_back(0.01 * (i + 1) * (k + 1));
    for (int k = 0; k < 8; ++k) yr.push_back(0.001 * (i + k));
    x.push_back(xr);
    y.push_back(yr);
  }
  return {{"format", "pegasus-heli-model"},
          {"version", 1},
          {"structure",
           {{"rate_hz", 10},
            {"extra_states", true},
            {"intercept", true},
            {"templates", true},
            {"gravity", 9.81},
            {"tau_flap", 0.1},
            {"flap_per_a1", 0.21},
            {"flap_per_a2", 0.21},
            {"gyro_tau", 0.05}}},
          {"dt", 0.1},
          {"inv_bandwidth", json(std::vector<double>(16, 0.5))},
          {"sigma2", json(std::vector<double>(8, 0.01))},
          {"x", x},
          {"y", y},
          {"time", {0.0, 0.1, 0.2}}};
}

TEST_F(InputFiles, ModelJsonIsCheckedForMeaningNamingEachField) {
  const json good = valid_model();
  ASSERT_EQ(input_error_message([&] { (void)pegasus::sysid::IdentifiedModel::from_json(good); }),
            "(no error)");
  struct Case {
    std::string pointer;
    json value;
    std::string expected;  // the start of the message after "m.json: "
  };
  const std::vector<Case> cases = {
      {"/dt", 0, "dt: expected a number in (0, 100], got 0"},
      {"/dt", -0.1, "dt: expected a number in (0, 100], got -0.1"},
      {"/structure/rate_hz", 0, "structure.rate_hz: expected a number in (0, 1000], got 0"},
      {"/structure/gravity", 1e308, "structure.gravity: expected a number in [0, 100], got 1e+308"},
      {"/structure/tau_flap", -1, "structure.tau_flap: expected a number in (0, 100], got -1"},
      {"/structure/templates", "yes", "structure.templates: expected true or false, got \"yes\""},
      {"/version", 4294967297LL, "version: expected 1, got 4294967297"},
      {"/version", "1", "version: expected 1, got \"1\""},
      {"/sigma2/3", -0.5, "sigma2[3]: expected a number >= 0, got -0.5"},
      {"/inv_bandwidth/0", -2, "inv_bandwidth[0]: expected a number >= 0, got -2"},
      {"/inv_bandwidth", json::array({1, 2}), "inv_bandwidth: expected an array of 16 numbers, got [1,2]"},
      {"/x/1", json::array({1, 2, 3}), "x[1]: expected an array of 16 numbers, got [1,2,3]"},
      {"/y/2/7", "a", "y[2][7]: expected a number, got \"a\""},
      {"/time", json::array({0, 0.1}), "time: expected an array of 3 numbers, got [0,0.1]"},
      {"/time/2", 0.05, "time[2]: expected a time >= time[1], got 0.05"},
      {"/format", "other", "format: expected \"pegasus-heli-model\", got \"other\""},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.pointer);
    json j = good;
    j[json::json_pointer(c.pointer)] = c.value;
    const std::string message =
        input_error_message([&] { (void)pegasus::sysid::IdentifiedModel::from_json(j); });
    EXPECT_EQ(message.rfind("model.json: " + c.expected, 0), 0u) << message;
  }
  json missing = good;
  missing["structure"].erase("gyro_tau");
  EXPECT_EQ(input_error_message([&] { (void)pegasus::sysid::IdentifiedModel::from_json(missing); }),
            "model.json: structure.gyro_tau: missing");
}

TEST_F(InputFiles, FlightLogsAcceptAByteOrderMarkAndShowRawBytesEscaped) {
  const std::string header =
      "time,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate,a1,a2,a3,a4\r\n";
  std::string rows;
  for (int i = 0; i < 3; ++i) rows += std::to_string(0.02 * i) + ",0,0,-10,0,0,0,0,0,0,0,0,0,0,0,0.3,0\r\n";
  pegasus::sysid::LogReadOptions options;
  options.min_rows = 3;
  const auto log = pegasus::sysid::parse_flight_log("\xEF\xBB\xBF" + header + rows, "bom.csv", options);
  EXPECT_EQ(log.rows(), 3u);
  const std::string message = input_error_message([&] {
    (void)pegasus::sysid::parse_flight_log(header + rows + "0.06,0\r1,0,-10,0,0,0,0,0,0,0,0,0,0,0,0.3,0\n",
                                           "cr.csv", options);
  });
  EXPECT_EQ(message, "cr.csv:5:x: expected a number, found '0\\x0D1'");
}

TEST(UntrustedText, InvalidBytesAndControlsAreEscapedAndValidUtf8IsKept) {
  EXPECT_EQ(pegasus::printable("run\xff"), "run\\xFF");
  EXPECT_EQ(pegasus::printable(std::string("a\0b\r", 4)), "a\\x00b\\x0D");
  EXPECT_EQ(pegasus::printable("gr\xC3\xBC\xC3\x9F \xE2\x89\xA5 1\tok"),
            "gr\xC3\xBC\xC3\x9F \xE2\x89\xA5 1\tok");
  EXPECT_EQ(pegasus::printable("\xC0\xAF"), "\\xC0\\xAF");           // an overlong '/'
  EXPECT_EQ(pegasus::printable("\xED\xA0\x80"), "\\xED\\xA0\\x80");  // a surrogate
  EXPECT_EQ(pegasus::printable("\xE2\x89"), "\\xE2\\x89");           // cut short
  EXPECT_FALSE(pegasus::is_valid_utf8("\xF4\x90\x80\x80"));          // above U+10FFFF
  // What the CLI prints of every error: one printable line, whatever it quotes.
  EXPECT_EQ(pegasus::one_line_message(std::string("f\xff: x\ny\0", 8)), "f\\xFF: x y\\x00");
  // However much it quotes: a 10 MB unknown key keeps the message's start and end, each character whole.
  std::string key;
  for (int i = 0; i < 2000000; ++i) key += "\xC3\xBC";  // u-umlaut, two bytes each
  const std::string line =
      pegasus::one_line_message("c.toml:1: unknown key '" + key + "' (did you mean 'gamma'?)");
  EXPECT_LE(line.size(), pegasus::kMaxMessageBytes + 64);
  EXPECT_TRUE(line.starts_with("c.toml:1: unknown key '\xC3\xBC")) << line.substr(0, 40);
  EXPECT_TRUE(line.ends_with("\xC3\xBC' (did you mean 'gamma'?)"));
  EXPECT_NE(line.find(" bytes left out) ... "), std::string::npos);
  EXPECT_TRUE(pegasus::is_valid_utf8(line));
  const std::string short_line(pegasus::kMaxMessageBytes, 'a');
  EXPECT_EQ(pegasus::one_line_message(short_line), short_line);
}

TEST(UntrustedText, JsonWithInvalidStringsIsWrittenEscapedInsteadOfThrowing) {
  const json value = {{"argv", {"pegasus", "--out", "run\xff"}}, {"k\xfe", 1}};
  const json safe = pegasus::with_valid_utf8(value);
  EXPECT_EQ(safe.dump(), R"({"argv":["pegasus","--out","run\\xFF"],"k\\xFE":1})");
  EXPECT_THROW((void)value.dump(), json::type_error);  // what the run directory's JSON writer met before
}

// config.toml is written for every run and read back by --resume and --config: a string that is not UTF-8
// (a path) is stored escaped, loads again, and compares equal to the value it came from.
TEST(UntrustedText, ConfigTomlWithANonUtf8PathLoadsAgainAndEqualsItsSource) {
  pegasus::ConfigSchema schema;
  schema.add_string("policy", "", "a path");
  schema.add_double("gamma", 0.5, "discount").range(0, 1);
  schema.set("policy", std::string("runs/p\xff.json"));
  const std::string stored = schema.to_toml();
  pegasus::ConfigSchema again = schema.with_defaults();
  ASSERT_NO_THROW(again.load_toml_string(stored, "config.toml")) << stored;
  EXPECT_EQ(again.get_string("policy"), "runs/p\\xFF.json");
  EXPECT_EQ(schema.first_difference(again), std::nullopt);
  // Bytes that are not UTF-8 never reach toml++ (whose 3.3.0 misreads some); the line is named.
  EXPECT_EQ(
      input_error_message([&] { again.load_toml_string("gamma = 0.1\npolicy = \"\xff\"\n", "c.toml"); }),
      "c.toml:2: expected UTF-8 text, got the byte 0xFF");
}

}  // namespace
