// End-to-end tests of `pegasus heli pilot` and `pegasus heli identify` through the built CLI.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>

#include "pegasus/io/csv_table.hpp"
#include "support/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using pegasus::test_support::read_text;
using HeliCli = pegasus::test_support::TempDirTest;

pegasus::test_support::CliResult run(const std::string& args) {
  return pegasus::test_support::run_pegasus(args);
}

// The locally weighted class and the least-squares gains set: these tests read the local model's bandwidths
// and variants, and compare models identified against different test logs, from which the defaults would
// choose (the choices from the data are tests/logs/vehicle_cli_test.cpp's and
// tests/sysid/model_choice_test.cpp's).
const char* kIdentifySmall =
    " --local --whitened-gains=false --cv-points 40 --scale-grid 2,4 --coordinate-passes 0 --horizon-s 10 "
    "--start-spacing-s 5 --quiet";

class HeliCliWithLogs : public HeliCli {
 protected:
  void SetUp() override {
    HeliCli::SetUp();
    auto r =
        run("heli pilot --seconds 60 --hover-seconds 4 --seed 3 --quiet --out " + (dir_ / "train").string());
    ASSERT_EQ(r.code, 0) << r.output;
    r = run("heli pilot --seconds 25 --hover-seconds 4 --seed 4 --quiet --out " + (dir_ / "test").string());
    ASSERT_EQ(r.code, 0) << r.output;
  }
  std::string logs() const {
    return " --train " + (dir_ / "train" / "log.csv").string() + " --test " +
           (dir_ / "test" / "log.csv").string();
  }
};

TEST_F(HeliCliWithLogs, PilotWritesTheDocumentedLog) {
  const std::string text = read_text(dir_ / "train" / "log.csv");
  EXPECT_EQ(text.substr(0, text.find('\n')),
            "time,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate,a1,a2,a3,a4");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 3001);
  const auto summary = nlohmann::json::parse(read_text(dir_ / "train" / "summary.json"));
  EXPECT_EQ(summary.at("crashed"), false);
  EXPECT_EQ(summary.at("rows"), 3000);
  EXPECT_GT(summary.at("trim").at("roll").get<double>(), 0.0);
}

TEST_F(HeliCliWithLogs, IdentifyWritesSummaryKeysAndModel) {
  const auto r = run("heli identify" + logs() + kIdentifySmall + " --out " + (dir_ / "id").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(read_text(dir_ / "id" / "summary.json"));
  for (const char* key : {"train_seconds", "test_seconds", "bandwidth", "sigma2", "mse_at_seconds",
                          "outside_2sigma_fraction", "global_linear", "variants"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_NEAR(s.at("train_seconds").get<double>(), 60.0, 1e-9);
  EXPECT_NEAR(s.at("test_seconds").get<double>(), 25.0, 1e-9);
  EXPECT_EQ(s.at("variants").size(), 7u);  // chosen, global, extra states, intercept, 5, 25, 50 Hz
  EXPECT_FALSE(s.contains("variant_rates_skipped_hz"));
  EXPECT_EQ(s.at("bandwidth").size(), 15u);
  EXPECT_EQ(s.at("sigma2").size(), 8u);
  for (const char* h : {"1", "5", "10"}) {
    EXPECT_TRUE(s.at("mse_at_seconds").contains(h)) << h;
    EXPECT_TRUE(s.at("global_linear").at("mse_at_seconds").contains(h)) << h;
  }
  EXPECT_TRUE(s.at("mse_at_seconds").at("1").contains("xdot_b"));
  for (auto& [k, v] : s.at("outside_2sigma_fraction").items()) {
    EXPECT_GE(v.get<double>(), 0.0) << k;
    EXPECT_LE(v.get<double>(), 0.5) << k;
  }
  EXPECT_TRUE(fs::exists(dir_ / "id" / "model.json"));
  EXPECT_TRUE(fs::exists(dir_ / "id" / "mse_vs_horizon.csv"));
  EXPECT_TRUE(fs::exists(dir_ / "id" / "noise_check.svg"));
  // The closed-loop check runs with the default white noise too: the collective's gain on the vertical
  // velocity is among those it reports, each with its ratio.
  const auto& bias = s.at("closed_loop_bias");
  ASSERT_TRUE(bias.contains("zdot_b/a3")) << bias.dump();
  for (auto& [k, v] : bias.items())
    EXPECT_DOUBLE_EQ(v.at("relative").get<double>(),
                     v.at("least_squares").get<double>() / v.at("whitened").get<double>() - 1)
        << k;
  EXPECT_EQ(s.at("noise"), "white");
  EXPECT_FALSE(s.contains("noise_correlation"));

  // Every horizon's misses: one row per body variable and model step since a reset (10 Hz, reset every 2 s),
  // the summary's three horizons among them with the same values, and a line that counts the summary's
  // cells outside 3-7%.
  const auto by_horizon = pegasus::CsvTable::load(dir_ / "id" / "noise_check_by_horizon.csv");
  ASSERT_TRUE(by_horizon.has_value());
  ASSERT_EQ(by_horizon->rows(), 20u * 8u);
  const auto& seconds = by_horizon->numbers("seconds");
  const auto variables = by_horizon->texts("variable");
  const auto& outside = by_horizon->numbers("outside_2sigma");
  const auto& steps = by_horizon->numbers("steps");
  double counted = 0;
  int summary_cells = 0, summary_outside = 0;
  std::size_t every_within = 0;
  for (std::size_t i = 0; i < by_horizon->rows(); ++i) {
    if (variables[i] == "roll") counted += steps[i];
    every_within += outside[i] >= 0.03 && outside[i] <= 0.07 ? 1 : 0;
    for (const char* h : {"0.5", "1", "2"})
      if (std::abs(seconds[i] - std::stod(h)) < 1e-9) {
        EXPECT_EQ(outside[i], s.at("outside_2sigma_by_horizon").at(h).at(variables[i]).get<double>())
            << h << " " << variables[i];
        ++summary_cells;
        summary_outside += outside[i] < 0.03 || outside[i] > 0.07 ? 1 : 0;
      }
  }
  EXPECT_EQ(summary_cells, 24);
  EXPECT_EQ(counted, s.at("noise_check_steps").get<double>());
  // The answer first (the binomial test of each cell: summary.json's noise_check_passes), then the count.
  const bool passes = s.at("noise_check_passes").get<bool>();
  EXPECT_EQ(passes, s.at("noise_check_cells_beyond_chance").get<int>() == 0);
  EXPECT_NE(r.output.find(std::string("noise check on the hold-out log: the bands ") +
                          (passes ? "pass (none" : "fail (")),
            std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("; " + std::to_string(summary_outside) + " of the 24 cells are outside 3-7%"),
            std::string::npos)
      << r.output;
  // White noise, uncalibrated, with cells outside at some horizon: the line names the options that narrow
  // them (on these logs it misses: gusts correlate the errors).
  ASSERT_LT(every_within, by_horizon->rows());
  EXPECT_NE(
      r.output.find(
          std::to_string(every_within) + " of 160 within 3-7% (noise_check_by_horizon.csv); " +
          "for more honest bands: --noise ar1+measurement --calibrate-noise (README, Calibrated noise)\n"),
      std::string::npos)
      << r.output;
  EXPECT_TRUE(fs::exists(dir_ / "id" / "noise_check_by_horizon.svg"));
  // The report says the same under its chart.
  const auto from = r.output.find("noise check on the hold-out log: ");
  ASSERT_NE(from, std::string::npos);
  const std::string line = r.output.substr(from, r.output.find('\n', from) - from);
  const auto charts = nlohmann::json::parse(read_text(dir_ / "id" / "charts.json"));
  bool said = false;
  for (const auto& section : charts.is_array() ? charts : charts.at("sections"))
    if (section.at("id") == "noise-check")
      said = section.at("intro").get<std::string>().find(line) != std::string::npos;
  EXPECT_TRUE(said) << line;
}

// A reset window shorter than 0.5 s has none of the summary's horizons: the line counts every horizon alone.
TEST_F(HeliCliWithLogs, IdentifyWithAShortResetWindowCountsEveryHorizonOnly) {
  const auto r = run("heli identify" + logs() + kIdentifySmall + " --variants=false --reset-s 0.3 --out " +
                     (dir_ / "short").string());
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(read_text(dir_ / "short" / "summary.json"));
  EXPECT_TRUE(s.at("outside_2sigma_by_horizon").empty()) << s.at("outside_2sigma_by_horizon").dump();
  const auto by_horizon = pegasus::CsvTable::load(dir_ / "short" / "noise_check_by_horizon.csv");
  ASSERT_TRUE(by_horizon.has_value());
  ASSERT_EQ(by_horizon->rows(), 3u * 8u);  // 0.1, 0.2 and 0.3 s at 10 Hz
  int within = 0;
  for (double f : by_horizon->numbers("outside_2sigma")) within += f >= 0.03 && f <= 0.07 ? 1 : 0;
  EXPECT_NE(r.output.find("noise check on the hold-out log: at every horizon to 0.3 s, " +
                          std::to_string(within) + " of 24 within 3-7%"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(r.output.find("cells of outside_2sigma_by_horizon"), std::string::npos) << r.output;
}

// More hold-out flights for the noise check: their steps pooled with the test log's, each flight's cells in
// noise_check_by_log. The test log counted twice changes no fraction; a log that cannot be read stops the
// run before anything is written.
TEST_F(HeliCliWithLogs, IdentifyPoolsTheNoiseCheckOverMoreHoldOutLogs) {
  const std::string args = "heli identify" + logs() + kIdentifySmall + " --variants=false";
  const std::string test_log = (dir_ / "test" / "log.csv").string();
  // A second hold-out flight, and the same model checked on it alone.
  ASSERT_EQ(
      run("heli pilot --seconds 25 --hover-seconds 4 --seed 5 --quiet --out " + (dir_ / "test2").string())
          .code,
      0);
  const std::string other_log = (dir_ / "test2" / "log.csv").string();
  const auto one = run(args + " --out " + (dir_ / "one").string());
  ASSERT_EQ(one.code, 0) << one.output;
  const auto alone = run("heli identify --train " + (dir_ / "train" / "log.csv").string() + " --test " +
                         other_log + kIdentifySmall + " --variants=false --out " + (dir_ / "alone").string());
  ASSERT_EQ(alone.code, 0) << alone.output;
  const auto two = run(args + " --noise-check-logs " + other_log + " --out " + (dir_ / "two").string());
  ASSERT_EQ(two.code, 0) << two.output;
  EXPECT_NE(two.output.find("noise check on the 2 hold-out logs, pooled: "), std::string::npos) << two.output;
  const auto a = nlohmann::json::parse(read_text(dir_ / "one" / "summary.json"));
  const auto b = nlohmann::json::parse(read_text(dir_ / "two" / "summary.json"));
  const auto c = nlohmann::json::parse(read_text(dir_ / "alone" / "summary.json"));
  EXPECT_FALSE(a.contains("noise_check_by_log"));  // summaries without the option stay as they were
  EXPECT_EQ(b.at("noise_check_steps"),
            a.at("noise_check_steps").get<int>() + c.at("noise_check_steps").get<int>());
  const auto& by_log = b.at("noise_check_by_log");
  ASSERT_EQ(by_log.size(), 2u);
  // Each flight's own check is the check of that flight alone, the test log first.
  for (const auto& [flight, single, log] : {std::tuple{by_log[0], a, test_log}, {by_log[1], c, other_log}}) {
    EXPECT_EQ(flight.at("log"), log);
    EXPECT_EQ(flight.at("steps"), single.at("noise_check_steps"));
    EXPECT_EQ(flight.at("outside_2sigma_by_horizon"), single.at("outside_2sigma_by_horizon"));
    EXPECT_EQ(flight.at("cells"), 24);
    EXPECT_EQ(flight.at("every_step_cells"), 160);
  }
  // The pooled fractions weigh each flight by its steps, cell by cell.
  const auto cells_one = pegasus::CsvTable::load(dir_ / "one" / "noise_check_by_horizon.csv");
  const auto cells_alone = pegasus::CsvTable::load(dir_ / "alone" / "noise_check_by_horizon.csv");
  const auto cells_two = pegasus::CsvTable::load(dir_ / "two" / "noise_check_by_horizon.csv");
  ASSERT_TRUE(cells_one.has_value() && cells_alone.has_value() && cells_two.has_value());
  const auto n1 = cells_one->numbers("steps"), n2 = cells_alone->numbers("steps"),
             f1 = cells_one->numbers("outside_2sigma"), f2 = cells_alone->numbers("outside_2sigma");
  const auto pooled_steps = cells_two->numbers("steps"), pooled = cells_two->numbers("outside_2sigma");
  ASSERT_EQ(pooled.size(), f1.size());
  ASSERT_EQ(pooled.size(), f2.size());
  int differ = 0;
  for (std::size_t i = 0; i < pooled.size(); ++i) {
    EXPECT_EQ(pooled_steps[i], n1[i] + n2[i]) << i;
    EXPECT_NEAR(pooled[i], (f1[i] * n1[i] + f2[i] * n2[i]) / (n1[i] + n2[i]), 1e-12) << i;
    differ += f1[i] != f2[i];
  }
  EXPECT_GE(differ, 20) << "the two flights must differ for the weights to be tested";
  for (const char* f : {"model.json", "noise_check.csv"})
    EXPECT_EQ(read_text(dir_ / "one" / f), read_text(dir_ / "two" / f)) << f;
  EXPECT_NE(read_text(dir_ / "two" / "config.toml").find("noise_check_logs = [\"" + other_log + "\"]"),
            std::string::npos);

  // The same flight twice would count its steps twice: refused (issue 51).
  const auto twice = run(args + " --noise-check-logs " + test_log + " --out " + (dir_ / "twice").string());
  EXPECT_EQ(twice.code, 2) << twice.output;
  EXPECT_NE(twice.output.find("is the same flight as " + test_log + " (--test)"), std::string::npos)
      << twice.output;
  EXPECT_FALSE(fs::exists(dir_ / "twice.partial"));

  const std::string missing = (dir_ / "missing.csv").string();
  const auto bad =
      run(args + " --noise-check-logs " + other_log + "," + missing + " --out " + (dir_ / "bad").string());
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_NE(bad.output.find(missing), std::string::npos) << bad.output;
  EXPECT_EQ(std::count(bad.output.begin(), bad.output.end(), '\n'), 1) << bad.output;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
  EXPECT_FALSE(fs::exists(dir_ / "bad.partial"));
}

TEST_F(HeliCliWithLogs, IdentifyOutputsDoNotDependOnThreads) {
  const std::string args = "heli identify" + logs() + kIdentifySmall + " --variants=false";
  ASSERT_EQ(run(args + " --threads 1 --out " + (dir_ / "t1").string()).code, 0);
  ASSERT_EQ(run(args + " --threads 2 --out " + (dir_ / "t2").string()).code, 0);
  for (const char* f : {"model.json", "mse_vs_horizon.csv", "noise_check.csv", "noise_check_by_horizon.csv",
                        "cross_validation.csv"})
    EXPECT_EQ(read_text(dir_ / "t1" / f), read_text(dir_ / "t2" / f)) << f;
  auto a = nlohmann::json::parse(read_text(dir_ / "t1" / "summary.json"));
  auto b = nlohmann::json::parse(read_text(dir_ / "t2" / "summary.json"));
  a.erase("cv_seconds");
  b.erase("cv_seconds");
  EXPECT_EQ(a, b);
}

// Every fifth row of a 50 Hz log: the same flight logged at 10 Hz.
void write_every_fifth_row(const fs::path& from, const fs::path& to) {
  std::ifstream in(from);
  std::ofstream out(to);
  std::string line;
  for (int i = -1; std::getline(in, line); ++i)
    if (i < 0 || i % 5 == 0) out << line << "\n";
}

TEST_F(HeliCliWithLogs, IdentifiesA10HzLogWithTheVariantsItsRateAllows) {
  // An outside aircraft's 10 Hz logs stopped `heli identify` with exit 2: Fig 5.2's variants always tried
  // 25 and 50 Hz models, which need 2.5 and 5 log rows per step.
  write_every_fifth_row(dir_ / "train" / "log.csv", dir_ / "train10.csv");
  write_every_fifth_row(dir_ / "test" / "log.csv", dir_ / "test10.csv");
  const auto r = run("heli identify --train " + (dir_ / "train10.csv").string() + " --test " +
                     (dir_ / "test10.csv").string() + kIdentifySmall + " --out " + (dir_ / "id").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("variants not identified at 25, 50 Hz: the logs' rates (10 and 10 Hz) are not"),
            std::string::npos)
      << r.output;
  const auto s = nlohmann::json::parse(read_text(dir_ / "id" / "summary.json"));
  EXPECT_EQ(s.at("rate_hz"), 10.0);
  EXPECT_EQ(s.at("variant_rates_skipped_hz"), nlohmann::json::parse("[25.0, 50.0]"));
  std::vector<std::string> names;
  for (const auto& v : s.at("variants")) names.push_back(v.at("model").get<std::string>());
  EXPECT_EQ(names,
            (std::vector<std::string>{"locally weighted (chosen)", "global linear", "without a1s, b1s, gyro",
                                      "without intercept", "identified at 5 Hz"}));
  // The 5 Hz variant is a model of its own, predicting the hold-out log at every horizon.
  EXPECT_TRUE(s.at("variants").at(4).at("mse_at_seconds").at("1").contains("xdot_b"));
}

TEST_F(HeliCli, IdentifyRejectsBadLogNamingFileLineAndColumn) {
  const fs::path bad = dir_ / "bad.csv";
  {
    std::ofstream out(bad);
    out << "time,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate,a1,a2,a3,a4\n";
    for (int i = 0; i < 200; ++i)
      out << i * 0.02 << "," << (i == 57 ? "oops" : "0") << ",0,-10,0,0,0,0,0,0,0,0,0,0,0,0,0\n";
  }
  const auto r = run("heli identify --train " + bad.string() + " --test " + bad.string() + " --quiet --out " +
                     (dir_ / "id").string());
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(bad.string() + ":59:x: expected a number, found 'oops'"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "id"));
  const auto missing = run("heli identify --quiet --out " + (dir_ / "id").string());
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.output.find("--train"), std::string::npos) << missing.output;
}

}  // namespace
