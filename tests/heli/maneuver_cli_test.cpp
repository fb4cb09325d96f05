// End-to-end tests of `pegasus heli maneuver` on a small identified model and a shrunken manoeuvre: training
// improves U-hat, the documented files, --threads never changes a result, bad input is refused.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using pegasus::test_support::read_text;
using pegasus::test_support::run_pegasus;

class ManeuverCli : public pegasus::test_support::TempDirTest {
 protected:
  // One small identified model for the whole suite.
  static void SetUpTestSuite() {
    shared_ = fs::temp_directory_path() / ("pegasus-maneuver-model-" + std::to_string(::getpid()));
    fs::remove_all(shared_);
    auto r = run_pegasus("heli pilot --seconds 60 --hover-seconds 4 --seed 3 --quiet --out " +
                         (shared_ / "train").string());
    ASSERT_EQ(r.code, 0) << r.output;
    r = run_pegasus("heli pilot --seconds 20 --hover-seconds 4 --seed 4 --quiet --out " +
                    (shared_ / "test").string());
    ASSERT_EQ(r.code, 0) << r.output;
    r = run_pegasus("heli identify --train " + (shared_ / "train" / "log.csv").string() + " --test " +
                    (shared_ / "test" / "log.csv").string() +
                    " --cv-points 40 --scale-grid 2,4 --coordinate-passes 0 --horizon-s 5 --start-spacing-s "
                    "5 --variants=false"
                    " --quiet --out " +
                    (shared_ / "id").string());
    ASSERT_EQ(r.code, 0) << r.output;
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }

  // A 2 m nose-in circle flown slowly: about 20 s of flight per scenario.
  static std::string small(const std::string& out) {
    return "heli maneuver --name III.2 --model " + (shared_ / "id" / "model.json").string() +
           " --circle-radius 2 --pause-s 0.5 --hold-end-s 0.5 --speed 1 --scenarios 2 --optimizer.method "
           "hill-climb"
           " --optimizer.hill-climbing.max-iterations 3 --optimizer.hill-climbing.proposals-per-iteration 4 "
           "--flights 2 --quiet --out " +
           out;
  }
  static inline fs::path shared_;
};

nlohmann::json json_of(const fs::path& p) { return nlohmann::json::parse(read_text(p)); }

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

TEST_F(ManeuverCli, TrainingImprovesUhatAndWritesTheDocumentedFiles) {
  const auto r = run_pegasus(small((dir_ / "run").string()) + " --ablations=false");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = json_of(dir_ / "run" / "summary.json");
  EXPECT_EQ(s.at("maneuver"), "III.2");
  EXPECT_GT(s.at("final_uhat").get<double>(), s.at("initial_uhat").get<double>());
  EXPECT_EQ(s.at("flights"), 2);
  for (const char* key :
       {"crashes", "rms_path_deviation_m", "max_path_deviation_m", "z_delay_s", "completed"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_FALSE(s.contains("rms_path_deviation_no_delay_m"));  // no ablations asked for
  EXPECT_EQ(first_line(read_text(dir_ / "run" / "progress.csv")), "iteration,evaluations,seconds,objective");
  EXPECT_EQ(first_line(read_text(dir_ / "run" / "ideal_path.csv")), "t,x,y,z,yaw");
  EXPECT_EQ(first_line(read_text(dir_ / "run" / "flights.csv"))
                .rfind("flight,t,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate,a1,a2,a3,"
                       "a4,target_x,target_y,"
                       "target_z,target_yaw",
                       0),
            0u);
  EXPECT_EQ(first_line(read_text(dir_ / "run" / "path_deviation.csv")),
            "flight,t,path_deviation_m,progress_m");
  const auto policy = json_of(dir_ / "run" / "policy.json");
  EXPECT_EQ(policy.at("class"), "maneuver");
  EXPECT_EQ(policy.at("options").at("name"), "III.2");
  EXPECT_EQ(policy.at("options").at("circle_radius"), 2.0);
  EXPECT_TRUE(fs::exists(dir_ / "run" / "paths_top.svg"));
  // This small model is a global linear one (identify's choice on 60 s of logs), and there is no hover
  // policy: the manoeuvre keeps the limits hover training would give the model (issue 48), in its file too.
  ASSERT_EQ(json_of(shared_ / "id" / "summary.json").at("choices").at("model_class").at("class"),
            "global linear");
  EXPECT_EQ(s.at("choices").at("command_limits").at("by"), "the global linear model's logged controls");
  EXPECT_EQ(s.at("choices").at("command_limits").at("margin"), 0.5);
  EXPECT_EQ(policy.at("options").at("command_limits").at("lower"),
            s.at("choices").at("command_limits").at("lower"));
  EXPECT_EQ(policy.at("options").at("command_limits").at("upper"),
            s.at("choices").at("command_limits").at("upper"));
}

// On a global linear model the manoeuvre's commands stay within the logs' range widened by --command-margin
// (issue 48), as hover's do: in training, in its flights, and in its policy file (so in `control` and the C
// export); said in one line and in the summary. A margin of 100 sets none.
TEST_F(ManeuverCli, OnAGlobalLinearModelCommandsStayWithinTheLogsRangeWidenedByTheMargin) {
  const auto r =
      run_pegasus(small((dir_ / "run").string()) + " --ablations=false --trace-flights 2 --command-margin 0");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("command limits (the global linear model extrapolates beyond its logs): the logs' "
                          "controls widened by 0% of their range per side, a1 ["),
            std::string::npos)
      << r.output;
  const auto limits = json_of(dir_ / "run" / "policy.json").at("options").at("command_limits");
  const auto lower = limits.at("lower").get<std::vector<double>>(),
             upper = limits.at("upper").get<std::vector<double>>();
  const auto s = json_of(dir_ / "run" / "summary.json");
  EXPECT_EQ(s.at("choices").at("command_limits").at("upper"), limits.at("upper"));
  EXPECT_EQ(s.at("choices").at("command_limits").at("margin"), 0.0);
  // Every command flown is within the limits, and the limits bind: the clip is what held some of them.
  std::istringstream flights(read_text(dir_ / "run" / "flights.csv"));
  std::string line;
  std::getline(flights, line);
  int rows = 0, at_limit = 0;
  while (std::getline(flights, line)) {
    std::vector<double> v;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) v.push_back(std::stod(cell));
    for (std::size_t c = 0; c < 4; ++c) {
      const double a = v[14 + c];
      ASSERT_TRUE(a >= lower[c] && a <= upper[c]) << "a" << c + 1 << ": " << line;
      at_limit += a == lower[c] || a == upper[c];
    }
    ++rows;
  }
  EXPECT_GT(rows, 100);
  EXPECT_GE(at_limit, 10) << rows;  // 23 of 2330 steps with a command at its limit

  const auto wide = run_pegasus(small((dir_ / "wide").string()) + " --ablations=false --command-margin 100");
  ASSERT_EQ(wide.code, 0) << wide.output;
  EXPECT_EQ(wide.output.find("command limits"), std::string::npos) << wide.output;
  EXPECT_FALSE(json_of(dir_ / "wide" / "policy.json").at("options").contains("command_limits"));
  EXPECT_FALSE(json_of(dir_ / "wide" / "summary.json").contains("choices"));
}

TEST_F(ManeuverCli, ThreadCountNeverChangesTheResult) {
  const std::string small_ablations =
      " --optimizer.gradient.max-iterations 1 --optimizer.hill-climbing.max-iterations 1"
      " --optimizer.hill-climbing.proposals-per-iteration 2";
  auto a = run_pegasus(small((dir_ / "one").string()) + small_ablations + " --threads 1");
  ASSERT_EQ(a.code, 0) << a.output;
  auto b = run_pegasus(small((dir_ / "two").string()) + small_ablations + " --threads 2");
  ASSERT_EQ(b.code, 0) << b.output;
  const auto sa = json_of(dir_ / "one" / "summary.json"), sb = json_of(dir_ / "two" / "summary.json");
  for (const char* key : {"final_uhat", "initial_uhat", "rms_path_deviation_m",
                          "rms_path_deviation_no_delay_m", "rms_path_deviation_no_shaping_m", "crashes"})
    EXPECT_EQ(sa.at(key), sb.at(key)) << key;
  EXPECT_EQ(json_of(dir_ / "one" / "policy.json").at("parameters"),
            json_of(dir_ / "two" / "policy.json").at("parameters"));
  EXPECT_EQ(read_text(dir_ / "one" / "flights.csv"), read_text(dir_ / "two" / "flights.csv"));
}

TEST_F(ManeuverCli, RefusesBadInputWithOneClearLine) {
  auto r = run_pegasus("heli maneuver --name III.9 --model x.json --quiet --out " + (dir_ / "bad").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("III.9"), std::string::npos) << r.output;
  r = run_pegasus("heli maneuver --name III.1 --quiet --out " + (dir_ / "bad").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--model"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

}  // namespace
