// Controllers out (codegen/c_policy.hpp), the files and the command: bad and old policy files, and `pegasus
// export c` writing a header, source and summary that compile and answer as `heli control` does, or refusing
// bad input in one line.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <new>
#include <numbers>
#include <random>

#include "c_policy_fixture.hpp"
#include "logs/outside_aircraft.hpp"
#include "pegasus/codegen/c_loader.hpp"
#include "pegasus/codegen/c_policy.hpp"
#include "pegasus/envs/bicycle_policy.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/experiments/pendulum_experiment.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/mujoco/mujoco_policy.hpp"
#include "pegasus/policies/policy_json.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace pegasus::codegen {
namespace {

using heli::Controls;
using heli::LoggedState;
using namespace c_policy_test;

TEST_F(CPolicyExport, BadPolicyFilesAreOneLineNamingTheFieldOrByte) {
  using test_support::input_error_message;
  EXPECT_EQ(
      input_error_message([] {
        export_c_policy({{"policy", "mystery"}}, "p.json");
      }),
      "p.json: policy: expected a policy file of class hover or maneuver (\"format\": "
      "\"pegasus-heli-policy\"), bicycle-sigmoid-15 or pendulum-swing-up (\"policy\": ...), got \"mystery\"");
  nlohmann::json unknown = heli::policy_file_json(hover_file(1, 0, {0, 0, -10, 0}));
  unknown["class"] = "spline";
  EXPECT_EQ(input_error_message([&] { export_c_policy(unknown, "p.json"); }),
            "p.json: class: expected \"hover\" or \"maneuver\" (the helicopter classes export knows), got "
            "\"spline\"");
  // A class of heli's registry (it flies) without C text is told so; a MuJoCo policy.json names what exports.
  heli::register_policy_class("glide", heli::make_hover_controller);
  unknown["class"] = "glide";
  EXPECT_EQ(input_error_message([&] { export_c_policy(unknown, "p.json"); }),
            "p.json: class: expected \"hover\" or \"maneuver\" (the helicopter classes export knows; this "
            "registered class has no C text), got \"glide\"");
  EXPECT_EQ(input_error_message([] {
              export_c_policy({{"format", kMujocoPolicyFormat}, {"version", 1}, {"class", "linear"}},
                              "policy.json");
            }),
            "policy.json: format: a MuJoCo policy (\"pegasus.mujoco.policy\") has no C export; export knows "
            "hover, maneuver, bicycle-sigmoid-15 or pendulum-swing-up");
  nlohmann::json short_file = heli::policy_file_json(hover_file(1, 0, {0, 0, -10, 0}));
  short_file["parameters"].erase(33);
  EXPECT_EQ(input_error_message([&] { export_c_policy(short_file, "p.json"); }),
            "p.json: parameters: expected 34 parameters for class hover, got 33");
  EXPECT_EQ(input_error_message([&] {
              export_c_policy(pendulum_policy_json({1, 2, 3, 4, 5}), "p.json", {.prefix = "9lives"});
            }),
            "prefix: expected a C identifier (letters, digits, _), got \"9lives\"");
  nlohmann::json four = pendulum_policy_json({1, 2, 3, 4, 5});
  four["parameters"].erase("stabilise.rate");
  EXPECT_EQ(input_error_message([&] { export_c_policy(four, "p.json"); }),
            "p.json: parameters.stabilise.rate: missing");
  std::ofstream(dir_ / "broken.json") << "{\"policy\": ";
  EXPECT_TRUE(
      input_error_message([&] {
        export_c_policy_file(dir_ / "broken.json");
      }).starts_with((dir_ / "broken.json").string() + ": byte 12: expected a JSON policy file, got "));
}

// Parameter policy files carry their format and version; a file from before (neither) is version 0 and
// exports to the same code, and a version this build does not know is one line naming the field.
TEST_F(CPolicyExport, ParameterPolicyFilesAreVersionedAndOldOnesStillLoad) {
  using test_support::input_error_message;
  const nlohmann::json current = pendulum_policy_json({1, 2, 3, 4, 5});
  EXPECT_EQ(current.at("format"), kParameterPolicyFormat);
  EXPECT_EQ(current.at("version"), kParameterPolicyVersion);
  nlohmann::json old = current;
  old.erase("format");
  old.erase("version");
  EXPECT_EQ(export_c_policy(old, "p.json").source, export_c_policy(current, "p.json").source);
  EXPECT_EQ(pendulum_policy_from_json(old, "p.json"), pendulum_policy_from_json(current, "p.json"));
  nlohmann::json later = current;
  later["version"] = kParameterPolicyVersion + 1;
  EXPECT_EQ(input_error_message([&] { export_c_policy(later, "p.json"); }),
            fmt::format("p.json: version: expected an integer in [1, {0}] (the versions this build reads), "
                        "got {1}",
                        kParameterPolicyVersion, kParameterPolicyVersion + 1));
  nlohmann::json other = current;
  other["format"] = "pegasus-mujoco-policy";
  EXPECT_EQ(input_error_message([&] { (void)pendulum_policy_from_json(other, "p.json"); }),
            "p.json: format: expected \"pegasus-parameter-policy\", got \"pegasus-mujoco-policy\"");
  // Every class export knows is in the registry's list, once.
  EXPECT_EQ(c_policy_class_names(),
            (std::vector<std::string>{"hover", "maneuver", "bicycle-sigmoid-15", "pendulum-swing-up"}));
}

// A class registers its controller and its C text once, in heli's registry, and the export finds it there:
// "glide" (the hover networks under another name) exports the hover's code, named for its own class, and
// c_policy_class_names lists it. Registered without a C text again, it flies but no longer exports.
TEST_F(CPolicyExport, AClassRegisteredWithItsCTextExportsFromTheRegistry) {
  using test_support::input_error_message;
  heli::register_policy_class("glide", heli::make_hover_controller, heli::hover_c_text);
  nlohmann::json file = heli::policy_file_json(hover_file(1, 0.5, {0, 0, -10, 0}));
  const CPolicyCode hover = export_c_policy(file, "p.json");
  file["class"] = "glide";
  const CPolicyCode glide = export_c_policy(file, "p.json");
  EXPECT_EQ(glide.class_name, "glide");
  const auto as_hover = [](std::string text) {
    const std::string from = "policy class \"glide\"", to = "policy class \"hover\"";
    for (std::size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
      text.replace(at, from.size(), to);
    return text;
  };
  EXPECT_NE(glide.header.find("policy class \"glide\""), std::string::npos);
  EXPECT_EQ(as_hover(glide.header), hover.header);
  EXPECT_EQ(as_hover(glide.source), hover.source);
  EXPECT_EQ(c_policy_class_names(), (std::vector<std::string>{"glide", "hover", "maneuver",
                                                              "bicycle-sigmoid-15", "pendulum-swing-up"}));
  heli::register_policy_class("glide", heli::make_hover_controller);
  EXPECT_EQ(input_error_message([&] { export_c_policy(file, "p.json"); }),
            "p.json: class: expected \"hover\" or \"maneuver\" (the helicopter classes export knows; this "
            "registered class has no C text), got \"glide\"");
  EXPECT_EQ(c_policy_class_names(),
            (std::vector<std::string>{"hover", "maneuver", "bicycle-sigmoid-15", "pendulum-swing-up"}));
}

// ---- The command, end to end ----------------------------------------------------------------------------

TEST_F(CPolicyExport, CommandWritesHeaderSourceAndSummaryThatCompileAndAct) {
  const Theta theta = {0.3, 1.5, 20.0, 4.0, 0.6, 1.5, 0.05};
  std::ofstream(dir_ / "policy.json") << pendulum_policy_json(theta).dump();
  const auto out = dir_ / "out";
  const auto r =
      test_support::run_pegasus(fmt::format("export --policy {} --lang c --prefix swing --out {} --quiet",
                                            (dir_ / "policy.json").string(), out.string()));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("class pendulum-swing-up: 3 observations -> 1 actions"), std::string::npos)
      << r.output;
  const auto summary = nlohmann::json::parse(test_support::read_text(out / "summary.json"));
  EXPECT_EQ(summary["class"], "pendulum-swing-up");
  EXPECT_EQ(summary["act_function"], "swing_act");
  EXPECT_EQ(summary["observation_names"], nlohmann::json({"cos_theta", "sin_theta", "theta_dot"}));
  EXPECT_TRUE(std::filesystem::exists(out / "config.toml"));
  // A flight computer's build: the header and source as written, compiled on their own, no -lm missing.
  const std::string main_c = R"(#include "swing.h"
#include <stdio.h>
int main(void) {
  const double o[SWING_OBSERVATION_SIZE] = {-1.0, 0.0, 0.5};
  double a[SWING_ACTION_SIZE];
  const int rc = swing_act(o, a);
  printf("%d %a\n", rc, a[0]);
  return 0;
}
)";
  std::ofstream(out / "main.c") << main_c;
  const auto built = test_support::run_shell(
      fmt::format("cd {} && gcc {} main.c swing.c -o main -lm && ./main", out.string(), kCFlags));
  ASSERT_EQ(built.code, 0) << built.output;
  int rc = -1;
  char hex[64] = {};
  ASSERT_EQ(std::sscanf(built.output.c_str(), "%d %63s", &rc, hex), 2) << built.output;
  EXPECT_EQ(rc, 0);
  EXPECT_TRUE(same_bits(std::strtod(hex, nullptr),
                        PendulumSwingUpPolicy().act(theta, PendulumObservation{-1.0, 0.0, 0.5})))
      << built.output;
}

// What a flight computer sees: the same state lines through `pegasus heli control` and through a program
// built on the exported hover controller give the same controls, bit for bit. With the integral term the
// program keeps one memory over the lines, as `heli control` serves one flight.
TEST_F(CPolicyExport, ExportedHoverAnswersHeliControlLinesWithHeliControlsBits) {
  for (const bool with_memory : {false, true}) {
    SCOPED_TRACE(with_memory ? "with the integral term" : "without memory");
    const heli::PolicyFile file =
        hover_file(11, 1.0, {1.0, 2.0, -10.0, 0.3}, {.dt = with_memory ? 0.02 : 0.0, .limit_position = 3});
    const auto policy = dir_ / (with_memory ? "integral.json" : "hover.json");
    heli::write_policy_file(policy, file);
    const auto out = dir_ / (with_memory ? "c-memory" : "c");
    const auto exported =
        test_support::run_pegasus(fmt::format("export --policy {} --out {}", policy.string(), out.string()));
    ASSERT_EQ(exported.code, 0) << exported.output;
    const auto summary = nlohmann::json::parse(test_support::read_text(out / "summary.json"));
    EXPECT_EQ(summary.contains("memory_type"), with_memory);
    if (with_memory) {
      EXPECT_EQ(summary["reset_function"], "pegasus_policy_reset");
    }
    std::ofstream(out / "main.c") << fmt::format(
        R"(#include "pegasus_policy.h"
#include <stdio.h>
int main(void) {{
  double o[PEGASUS_POLICY_OBSERVATION_SIZE], a[PEGASUS_POLICY_ACTION_SIZE];
{}  for (;;) {{
    int i;
    for (i = 0; i < PEGASUS_POLICY_OBSERVATION_SIZE; ++i)
      if (scanf(i ? " ,%lf" : "%lf", &o[i]) != 1) return 0;
    pegasus_policy_act({}o, a);
    printf("%a,%a,%a,%a\n", a[0], a[1], a[2], a[3]);
  }}
}}
)",
        with_memory ? "  pegasus_policy_memory m;\n  pegasus_policy_reset(&m);\n" : "",
        with_memory ? "&m, " : "");
    std::mt19937_64 rng(12);
    std::string lines;
    for (int i = 0; i < 500; ++i) {
      const LoggedState s = random_state(rng, file.target);
      lines += fmt::format("{}", 0.02 * i);
      for (const double x : s) lines += fmt::format(",{}", x);
      lines += "\n";
    }
    std::ofstream(dir_ / "states.csv") << lines;
    const auto flight_computer = test_support::run_shell(
        fmt::format("cd {} && gcc {} main.c pegasus_policy.c -o main -lm && ./main < {}", out.string(),
                    kCFlags, (dir_ / "states.csv").string()));
    ASSERT_EQ(flight_computer.code, 0) << flight_computer.output;
    const auto served = test_support::run_pegasus(
        fmt::format("heli control --policy {} < {}", policy.string(), (dir_ / "states.csv").string()));
    ASSERT_EQ(served.code, 0) << served.output;
    auto numbers = [](const std::string& text) {
      std::vector<double> v;
      std::string field;
      for (const char ch : text + "\n")
        if (ch == ',' || ch == '\n') {
          if (!field.empty()) v.push_back(std::strtod(field.c_str(), nullptr));
          field.clear();
        } else {
          field += ch;
        }
      return v;
    };
    const std::vector<double> c = numbers(flight_computer.output), cpp = numbers(served.output);
    ASSERT_EQ(c.size(), 2000u);
    ASSERT_EQ(cpp.size(), 2000u);
    for (std::size_t i = 0; i < c.size(); ++i) ASSERT_TRUE(same_bits(c[i], cpp[i])) << "line " << i / 4 + 1;
  }
}

TEST_F(CPolicyExport, CommandRejectsBadInputWithOneLineExit2AndNoOutputDirectory) {
  std::ofstream(dir_ / "malformed.json") << "{\"format\": \"pegasus-heli-policy\",";
  std::ofstream(dir_ / "unknown.json") << R"({"policy": "cart-pole-pid", "parameters": {}})";
  std::ofstream(dir_ / "overflow.json") << R"({"policy": "pendulum", "parameters": {"k": 1e999}})";
  std::ofstream(dir_ / "mujoco.json")
      << R"({"format": "pegasus.mujoco.policy", "version": 1, "class": "mlp"})";
  const std::pair<std::string, std::string> cases[] = {
      {"malformed.json", "malformed.json: byte 34: expected a JSON policy file"},
      {"overflow.json", "overflow.json: expected numbers within the range of a double"},
      {"unknown.json", "unknown.json: policy: expected a policy file of class hover"},
      {"mujoco.json", "mujoco.json: format: a MuJoCo policy (\"pegasus.mujoco.policy\") has no C export"},
  };
  for (const auto& [file, message] : cases) {
    const auto out = dir_ / ("out-" + file);
    const auto r = test_support::run_pegasus(
        fmt::format("export --policy {} --lang c --out {}", (dir_ / file).string(), out.string()));
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_FALSE(std::filesystem::exists(out.string() + ".partial"));
  }
  const auto r = test_support::run_pegasus(fmt::format(
      "export --policy {} --lang rust --out {}", (dir_ / "unknown.json").string(), (dir_ / "o").string()));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "o"));
}

}  // namespace
}  // namespace pegasus::codegen
