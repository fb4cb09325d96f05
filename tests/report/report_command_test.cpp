// The HTML report generator (include/pegasus/report/report.hpp) and `pegasus report`: a bad run directory or
// a missing bundle is refused before anything is written, a long page thins its series, and every run ends
// with its report (report_test.cpp: the page and its data).
#include <gtest/gtest.h>
#include <stdlib.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/runs/flight_charts.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/report/report.hpp"
#include "pegasus/runs/charts.hpp"
#include "report_fixture.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using pegasus::test_support::input_error_message;
using pegasus::test_support::read_text;
using pegasus::test_support::run_pegasus;
using namespace report_test;

TEST_F(Report, BadRunDirectoriesAreInputErrorsNamingTheFile) {
  using pegasus::report::report_data;
  EXPECT_NE(input_error_message([&] { report_data(dir_ / "nope"); }).find("no such directory"),
            std::string::npos);
  write(dir_ / "file", "x");
  EXPECT_NE(input_error_message([&] { report_data(dir_ / "file"); }).find("expected a run directory"),
            std::string::npos);
  fs::create_directories(dir_ / "empty");
  EXPECT_NE(input_error_message([&] { report_data(dir_ / "empty"); }).find("summary.json: not found"),
            std::string::npos);
  write(dir_ / "badjson" / "summary.json", "{\"a\": ");
  EXPECT_NE(input_error_message([&] { report_data(dir_ / "badjson"); }).find("invalid JSON"),
            std::string::npos);
  // A series a chart draws: bad cells, rows and columns are named with file and line.
  describe(
      run_,
      {one_chart({.title = "Steps", .traces = {{.file = "curves.csv", .x = "trial", .y = "none_mean"}}})});
  write(run_ / "curves.csv", "trial,none_mean,none_stderr\n1,2,3\n2,x7,3\n");
  EXPECT_NE(input_error_message([&] {
              report_data(run_);
            }).find("curves.csv:3: column 'none_mean': expected a number, got 'x7'"),
            std::string::npos);
  write(run_ / "curves.csv", "trial,none_mean,none_stderr\n1,2\n");
  EXPECT_NE(input_error_message([&] { report_data(run_); }).find("curves.csv:2: expected 3 fields"),
            std::string::npos);
  write(run_ / "curves.csv", "trial,other\n1,2\n");
  EXPECT_NE(input_error_message([&] { report_data(run_); }).find("curves.csv: expected a column 'none_mean'"),
            std::string::npos);
  fs::remove(run_ / "curves.csv");
  EXPECT_NE(input_error_message([&] { report_data(run_); }).find("curves.csv: not found (chart 'Steps'"),
            std::string::npos);
  // A MuJoCo replay whose frames do not hold 7 numbers per geom would pose the wrong geoms: named, with the
  // frame.
  describe(run_, {one_chart({.kind = pegasus::ChartKind::kMujocoReplay,
                             .title = "3-D replay",
                             .traces = {{.file = "replay.json"}}})});
  json replay = {{"format", "pegasus.mujoco.replay"},
                 {"version", 1},
                 {"geoms", json::array({json::object(), json::object()})},
                 {"t", {0.0, 0.01}},
                 {"frames", {std::vector<double>(14, 0.5), std::vector<double>(13, 0.5)}}};
  write(run_ / "replay.json", replay.dump());
  EXPECT_NE(input_error_message([&] {
              report_data(run_);
            }).find("replay.json: frames[1]: expected 14 numbers (7 for each of the 2 geoms)"),
            std::string::npos);
  replay["frames"][1] = std::vector<double>(14, 0.5);
  replay["t"] = {0.0};
  write(run_ / "replay.json", replay.dump());
  EXPECT_NE(input_error_message([&] {
              report_data(run_);
            }).find("replay.json: t, frames: expected two arrays of one length"),
            std::string::npos);
  replay["t"] = {0.0, 0.01};
  write(run_ / "replay.json", replay.dump());
  EXPECT_EQ(input_error_message([&] { report_data(run_); }), "(no error)");
  // A replay of a version this build does not know: one line naming the file and the field.
  replay["version"] = 2;
  write(run_ / "replay.json", replay.dump());
  EXPECT_EQ(
      input_error_message([&] { report_data(run_); }),
      (run_ / "replay.json").string() + ": version: expected 1 (the replay layout this build reads), got 2");
  fs::remove(run_ / "replay.json");
  // charts.json itself: the field is named.
  write(
      run_ / "charts.json",
      R"({"format": "pegasus.charts", "version": 1, "sections": [{"id": "s", "charts": [{"kind": "pie"}]}]})");
  EXPECT_NE(
      input_error_message([&] { report_data(run_); }).find("sections[0].charts[0].kind: expected xy, box"),
      std::string::npos);
  write(run_ / "charts.json",
        R"({"format": "pegasus.charts", "version": 1, "sections": [{"id": "s", "charts": [{"kind": "xy",
            "traces": [{"file": "../../etc/passwd", "x": "a", "y": "b"}]}]}]})");
  EXPECT_NE(
      input_error_message([&] { report_data(run_); }).find("traces[0].file: expected a file name inside"),
      std::string::npos);
  write(run_ / "charts.json", R"({"format": "other"})");
  EXPECT_NE(input_error_message([&] {
              report_data(run_);
            }).find("charts.json: format: expected \"pegasus.charts\", got \"other\""),
            std::string::npos);
}

TEST_F(Report, AMissingBundleIsNamedWithWhereToGetIt) {
  ::setenv(pegasus::report::kBundleEnv, (dir_ / "missing.js").c_str(), 1);
  try {
    pegasus::report::find_bundle();
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("PEGASUS_REPORT_BUNDLE"), std::string::npos) << e.what();
  }
  write(dir_ / "b.js", kFakeBundle);
  ::setenv(pegasus::report::kBundleEnv, (dir_ / "b.js").c_str(), 1);
  EXPECT_EQ(pegasus::report::find_bundle(), dir_ / "b.js");
  ::unsetenv(pegasus::report::kBundleEnv);
}

// --- the CLI
// --------------------------------------------------------------------------------------------------

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

TEST_F(Report, CliRefusesABadRunDirectoryWithExit2AndWritesNothing) {
  write(run_ / "curves.csv", "trial,none_mean\n1,2\n2,oops\n");
  describe(
      run_,
      {one_chart({.title = "Steps", .traces = {{.file = "curves.csv", .x = "trial", .y = "none_mean"}}})});
  const auto r = run_pegasus("report " + quoted(run_));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_EQ(r.output.rfind("pegasus: ", 0), 0u) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "one line: " << r.output;
  EXPECT_NE(r.output.find("curves.csv:3"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(run_ / "report.html"));
  EXPECT_FALSE(fs::exists(run_ / ".report.html.tmp"));

  const auto missing = run_pegasus("report " + quoted(dir_ / "nope"));
  EXPECT_EQ(missing.code, 2) << missing.output;
  EXPECT_NE(missing.output.find("no such directory"), std::string::npos) << missing.output;
  const auto none = run_pegasus("report");
  EXPECT_EQ(none.code, 2) << none.output;
  EXPECT_NE(none.output.find("RUN_DIR"), std::string::npos) << none.output;
}

TEST_F(Report, APipelineOpensWithItsVerdictAndItsStagesVerdictsInOrder) {
  const json fly = {
      {"flights", 4}, {"crashes", 0}, {"rms_position_m", 0.5}, {"pilot", {{"rms_position_m", 1.0}}}};
  json top = fly;
  top["stages"] = {"pilot-train", "fly"};
  write(run_ / "summary.json", top.dump());
  write(run_ / "run.json", R"({"command": "heli pipeline", "printed": [], "warnings": []})");
  write(run_ / "fly" / "summary.json", fly.dump());
  write(run_ / "fly" / "run.json", R"({"command": "heli fly"})");
  write(run_ / "pilot-train" / "summary.json", R"({"seconds": 200.0, "crashed": false})");
  write(run_ / "pilot-train" / "run.json", R"({"command": "heli pilot"})");
  const std::string html = render();
  const auto result = html.find("id=\"result\"");
  ASSERT_NE(result, std::string::npos);
  const auto own = html.find("<p class=\"verdict\">4 flights, no crash; 50% closer to the set point", result);
  const auto pilot = html.find("<li><b>pilot-train</b>: the pilot flew 200 s without a crash</li>", result);
  const auto flights = html.find("<li><b>fly</b>: 4 flights, no crash; 50% closer", result);
  EXPECT_NE(own, std::string::npos) << html.substr(result, 2000);
  EXPECT_LT(own, pilot);      // its own verdict first
  EXPECT_LT(pilot, flights);  // then the stages in the order the summary lists them
  EXPECT_LT(flights, html.find("id=\"headline\""));
}

TEST_F(Report, APageLongerThanItsLimitThinsItsSeriesUntilItFits) {
  // 60,000 rows of a noisy series: 4,000 of them (the default) compress to far more than the room left
  // beside a bundle of 1.48 MB.
  std::string text = "iteration,evaluations,seconds,objective\n";
  for (int i = 0; i < 60000; ++i)
    text += fmt::format("{},{},{},{}\n", i, 10 * i, 0.5 * i, std::sin(0.37 * i) * std::sqrt(i + 1.0));
  write(run_ / "progress.csv", text);
  describe(run_, {pegasus::optimizer_progress_section({{"", "progress.csv"}}, "intro")});
  const std::string bundle(1'480'000, ' ');
  pegasus::report::ReportOptions unlimited;
  unlimited.max_bytes = 0;
  const std::string full = pegasus::report::render_report(run_, bundle, unlimited);
  EXPECT_GT(full.size(), pegasus::report::kMaxReportBytes);
  EXPECT_EQ(chart_from(embedded_data(full), "progress.csv", "iteration")["traces"][0]["stride"], 15);

  const std::string html = pegasus::report::render_report(run_, bundle);
  EXPECT_LE(html.size(), pegasus::report::kMaxReportBytes);
  const json data = embedded_data(html);
  const json& c = chart_from(data, "progress.csv", "iteration");
  const std::size_t stride = c["traces"][0]["stride"];
  EXPECT_GT(stride, 15u);
  // Still every stride-th row, to six digits.
  const auto y = doubles(c["traces"][0]["y"]);
  const auto objective = column(run_ / "progress.csv", 3);
  ASSERT_GE(y.size(), 8u);
  EXPECT_NEAR(y[7], objective[7 * stride], 1e-6 * std::abs(objective[7 * stride]));
  // A bundle that leaves no room at all: the page is written anyway, as the options allow.
  EXPECT_GT(pegasus::report::render_report(run_, std::string(1'600'000, ' ')).size(),
            pegasus::report::kMaxReportBytes);
}

TEST_F(Report, CliNamesAMissingBundleInOneLine) {
  ::setenv(pegasus::report::kBundleEnv, (dir_ / "none.js").c_str(), 1);
  const auto r = run_pegasus("report " + quoted(run_));
  ::unsetenv(pegasus::report::kBundleEnv);
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(r.output.rfind("pegasus: error: report JavaScript bundle not found", 0), 0u) << r.output;
  EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << r.output;
  EXPECT_FALSE(fs::exists(run_ / "report.html"));
}

bool bundle_built() {
  return fs::exists(fs::path(PEGASUS_CLI_PATH).parent_path() / pegasus::report::kBundleName);
}

TEST_F(Report, EveryRunEndsWithItsReportAndTheCommandRemakesIt) {
  if (!bundle_built())
    GTEST_SKIP() << "no pegasus-report.js next to the CLI (node/npm missing at "
                    "configure time)";
  const auto r = run_pegasus("horizon --gamma 0.9 --epsilon 0.1 --out " + quoted(dir_ / "h") + " --quiet");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output, "{\"horizon\":51}\n");  // no note about the report
  const std::string html = read_text(dir_ / "h" / "report.html");
  EXPECT_NE(html.find("pegasus horizon"), std::string::npos);
  // Written in h.partial, it names the run by its final name (issue 50: the demo's said demo-heli.partial).
  EXPECT_NE(html.find("<title>pegasus horizon &middot; h</title>"), std::string::npos);
  EXPECT_EQ(html.substr(0, html.find("<script")).find(".partial"),
            std::string::npos);  // the bundle's own text aside
  // It opens with the answer: what the run printed, before the headline table.
  const auto result = html.find("<pre class=\"result\">{&quot;horizon&quot;:51}\n</pre>");
  ASSERT_NE(result, std::string::npos) << html.substr(0, 4000);
  EXPECT_LT(result, html.find("id=\"headline\""));
  // The raw keys below carry their unit and meaning from the key table (summary_keys.hpp).
  EXPECT_NE(html.find("<th>figure</th><th>value</th><th>unit</th><th>meaning</th>"), std::string::npos);
  EXPECT_NE(
      html.find("<tr><td>horizon</td><td class=\"num\">51</td><td>steps</td><td>H_eps: the rollout length "
                "that truncates discounted returns by at most epsilon/2</td></tr>"),
      std::string::npos);
  const json run = json::parse(read_text(dir_ / "h" / "run.json"));
  EXPECT_EQ(run.at("printed"), json::array({"{\"horizon\":51}"}));
  EXPECT_EQ(run.at("warnings"), json::array());
  EXPECT_NE(html.find("plotly.js-cartesian-dist-min"),
            std::string::npos);  // the real bundle
  EXPECT_NE(html.find("three"), std::string::npos);
  // Self-contained and at most 1.5 MB (issue 50; 5.4 MB with the whole of plotly.js).
  EXPECT_LE(html.size(), pegasus::report::kMaxReportBytes);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);

  write(run_ / "progress.csv", "iteration,evaluations,seconds,objective\n1,10,0.1,-3\n2,20,0.2,-2\n");
  describe(run_, {pegasus::optimizer_progress_section({{"", "progress.csv"}}, "intro")});
  const auto again = run_pegasus("report " + quoted(run_));
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_NE(again.output.find("report.html"), std::string::npos);
  const json data = embedded_data(read_text(run_ / "report.html"));
  EXPECT_EQ(doubles(chart_from(data, "progress.csv", "iteration")["traces"][0]["y"]),
            (std::vector<double>{-3, -2}));
}

}  // namespace
