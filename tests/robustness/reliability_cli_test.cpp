// Issue 51, end to end: the hostile-user campaign's reproductions through the built `pegasus` CLI. Each gives
// exit 2 (or the documented code) with one line naming the file, field or option, and leaves no debris.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "pegasus/heli/hover_policy.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "support/cli_runner.hpp"

namespace {

namespace fs = std::filesystem;
using pegasus::test_support::read_text;
using pegasus::test_support::run_shell;
using ::testing::HasSubstr;

const fs::path kSource = PEGASUS_SOURCE_DIR;
const fs::path kCrazyflie = kSource / "experiments" / "vehicles" / "crazyflie2.toml";

class ReliabilityCli : public pegasus::test_support::TempDirTest {
 protected:
  struct Run {
    int code = -1;
    std::string out, err;
  };
  // `pegasus ARGS` inside dir_ (stdin from `input`, a shell redirection), stdout and stderr apart.
  Run run(const std::string& args, const std::string& input = "</dev/null") const {
    const auto r = run_shell("cd '" + dir_.string() + "' && timeout 60 '" PEGASUS_CLI_PATH "' " + args + " " +
                             input + " >out.txt 2>err.txt; echo $?");
    return {std::stoi(r.output), read_text(dir_ / "out.txt"), read_text(dir_ / "err.txt")};
  }
  // A hover policy file at its starting weights (what `control` and `export` read).
  fs::path policy(const std::string& name, double trim_thrust = 0.2) const {
    const pegasus::heli::HoverPolicyInit init{.trim = {0.0, 0.0, trim_thrust, 0.0}};
    const pegasus::heli::HoverPolicy hover(init);
    const fs::path file = dir_ / name;
    pegasus::heli::write_policy_file(
        file,
        pegasus::heli::hover_policy_file(hover, hover.parameters().initial(), {0, 0, -1, 0}, init.trim));
    return file;
  }
  // Exit 2, exactly one line on stderr holding `expected`, and no `name`, name.partial or name.lock.
  void expect_refused(const Run& r, const std::string& expected, const std::string& name = "") const {
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "not one line: " << r.err;
    EXPECT_THAT(r.err, HasSubstr(expected));
    if (name.empty()) return;
    for (const char* suffix : {"", ".partial", ".lock"}) EXPECT_FALSE(fs::exists(dir_ / (name + suffix)));
  }
};

// Item 1, the reproduction: a DIR.partial holding a copied config.toml (or a kill between config.toml
// and inputs.json) was resumed on a changed policy, finished with exit 0, and left no inputs.json.
TEST_F(ReliabilityCli, AResumeNeverSkipsTheInputCheck) {
  const fs::path a = policy("A.json"), b = policy("B.json", 0.3);
  ASSERT_EQ(run("export --policy A.json --lang c --out o --quiet").code, 0);
  EXPECT_TRUE(fs::exists(dir_ / "o" / "inputs.json"));
  fs::create_directory(dir_ / "o2.partial");
  fs::copy_file(dir_ / "o" / "config.toml", dir_ / "o2.partial" / "config.toml");
  fs::copy_file(b, a, fs::copy_options::overwrite_existing);
  const Run resumed = run("export --policy A.json --lang c --out o2 --resume --quiet");
  EXPECT_EQ(resumed.code, 2) << resumed.err;
  EXPECT_THAT(resumed.err, HasSubstr("no record of the input files"));
  EXPECT_THAT(resumed.err, HasSubstr("A.json"));
  EXPECT_FALSE(fs::exists(dir_ / "o2"));
  // --force starts over on the inputs as they are, and records them.
  ASSERT_EQ(run("export --policy A.json --lang c --out o2 --force --quiet").code, 0);
  EXPECT_TRUE(fs::exists(dir_ / "o2" / "inputs.json"));
}

// Item 2, the reproduction: `control --vehicle` took a header with a misspelt column and read y = 5
// as x. Now: an error line at once, the trim controls on every line, exit 2 at the end of the input.
TEST_F(ReliabilityCli, ControlNeverServesAStateReadUnderAHeaderThatDoesNotPlaceIt) {
  policy("P.json");
  std::ofstream(dir_ / "in.csv") << "time,y,x,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yawrate\n"
                                    "0,5,0,-2,0,0,0,0,0,0,0,0,0\n";
  const Run misspelt = run("control --vehicle " + kCrazyflie.string() + " --policy P.json", "<in.csv");
  EXPECT_EQ(misspelt.code, 2) << misspelt.err;
  EXPECT_THAT(misspelt.err, HasSubstr("stdin:1: header: no column for the state field(s) yaw_rate"));
  EXPECT_THAT(misspelt.err, HasSubstr("the trim controls"));
  // The answers: the header, then the trim controls (a1..a4 0, 0, 0.2, 0 in the Crazyflie's channel order).
  const std::string trim = misspelt.out.substr(misspelt.out.find('\n') + 1);
  EXPECT_EQ(trim, "0,0,0.2,0\n") << misspelt.out;

  std::ofstream(dir_ / "short.csv") << "time,x,y\n0,1,2\n";
  const Run short_header = run("control --vehicle " + kCrazyflie.string() + " --policy P.json", "<short.csv");
  EXPECT_EQ(short_header.code, 2);
  EXPECT_THAT(short_header.err, HasSubstr("no column for the state field(s) z, roll"));
}

// Item 3: endless input was read forever (memory growing by 100 MB/s) by every reader given /dev/zero, and
// runs left DIR.partial and DIR.lock behind. Now each refuses it at once: exit 2, one line, nothing left.
TEST_F(ReliabilityCli, EndlessInputIsRefusedAtOnceByEveryReader) {
  policy("P.json");
  const auto start = std::chrono::steady_clock::now();
  expect_refused(run("control --vehicle /dev/zero --policy P.json"), "/dev/zero");
  expect_refused(run("control --policy /dev/zero"), "/dev/zero");
  expect_refused(run("export --policy /dev/zero --out e --quiet"), "/dev/zero", "e");
  expect_refused(run("dev count --config /dev/zero --out c --quiet"), "/dev/zero", "c");
  expect_refused(
      run("identify --vehicle " + kCrazyflie.string() + " --train /dev/zero --test /dev/zero --out i"),
      "/dev/zero", "i");
  expect_refused(run("hover --vehicle " + kCrazyflie.string() + " --model /dev/zero --out h --quiet"),
                 "/dev/zero", "h");
  expect_refused(run("log import /dev/zero --vehicle " + kCrazyflie.string() + " --out l --quiet"),
                 "/dev/zero", "l");
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
}

// Item 7: --noise-check-logs counted a flight again when given the test log, the training log or copies.
TEST_F(ReliabilityCli, ANoiseCheckLogThatIsAnotherGivenFlightIsRefused) {
  ASSERT_EQ(run("pilot --vehicle " + kCrazyflie.string() + " --seconds 40 --seed 3 --quiet --out train").code,
            0);
  ASSERT_EQ(run("pilot --vehicle " + kCrazyflie.string() + " --seconds 20 --seed 4 --quiet --out test").code,
            0);
  fs::copy_file(dir_ / "test" / "log.csv", dir_ / "copy.csv");
  const std::string args =
      "identify --vehicle " + kCrazyflie.string() + " --train train/log.csv --test test/log.csv --quiet";
  expect_refused(run(args + " --noise-check-logs copy.csv --out n"),
                 "--noise-check-logs: copy.csv is the same flight as test/log.csv (--test)", "n");
  expect_refused(run(args + " --noise-check-logs train/log.csv --out n"),
                 "--noise-check-logs: train/log.csv is the same flight as train/log.csv (--train)", "n");
}

}  // namespace
