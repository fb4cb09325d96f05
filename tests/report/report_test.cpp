// The HTML report generator (include/pegasus/report/report.hpp): the page is one self-contained file and the
// data it embeds is the run's CSV data (report_command_test.cpp: bad run directories, the bundle, and
// `pegasus report`). The browser test (tests/browser) checks that the pages draw.
#include "pegasus/report/report.hpp"

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

TEST_F(Report, PageIsSelfContainedWithTheBundleInlinedOnce) {
  write(run_ / "curves.csv", "trial,none_mean,none_stderr\n1,100,10\n2,50,5\n");
  describe(
      run_,
      {one_chart({.title = "Steps", .traces = {{.file = "curves.csv", .x = "trial", .y = "none_mean"}}})});
  const std::string html = render();
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);
  EXPECT_EQ(html.find("@import"), std::string::npos);
  const auto at = html.find(kFakeBundle);
  ASSERT_NE(at, std::string::npos);
  EXPECT_EQ(html.find(kFakeBundle, at + 1), std::string::npos);
  // Headline figures and the configuration are plain HTML.
  EXPECT_NE(html.find("optimal_expected_steps"), std::string::npos);
  EXPECT_NE(html.find("nested.a"), std::string::npos);
  EXPECT_NE(html.find("size = 10"), std::string::npos);
  // Every chart has its placeholder.
  const json data = embedded_data(html);
  ASSERT_FALSE(data["charts"].empty());
  for (const auto& c : data["charts"]) {
    EXPECT_NE(html.find("id=\"" + c["id"].get<std::string>() + "\""), std::string::npos) << c["id"];
  }
}

TEST_F(Report, TextFromTheRunCannotEndTheScriptElements) {
  write(run_ / "trials.csv", "method,trial,x\n\"</script><script>alert(1)//\",0,1\n");
  write(run_ / "rides.csv", "method,trial,ride,distance_km,reached,fell\n</SCRIPT>,0,0,1.0,1,0\n");
  describe(
      run_,
      {{.id = "rides",
        .title = "</script>",
        .intro = "<!-- </script>",
        .charts = {{.kind = pegasus::ChartKind::kBox,
                    .title = "Distance",
                    .traces = {{.file = "rides.csv", .y = "distance_km", .group_by = {"method", "trial"}}}},
                   {.kind = pegasus::ChartKind::kTable, .traces = {{.file = "trials.csv"}}}}}});
  const std::string bundle = "var s = \"</script>\"; /<!--x/.test(s);";
  const std::string html = pegasus::report::render_report(run_, bundle);
  std::size_t closes = 0;
  std::string lower = html;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
  for (auto p = lower.find("</script"); p != std::string::npos; p = lower.find("</script", p + 1)) ++closes;
  EXPECT_EQ(closes, 2u);  // the end of the data block and of the bundle
  EXPECT_EQ(lower.find("<!--"), std::string::npos);
  EXPECT_NE(html.find("var s = \"<\\/script>\""), std::string::npos);
  // The JSON still reads back to the original text.
  const json data = embedded_data(html);
  EXPECT_EQ(data["charts"][0]["groups"][0]["name"], "</SCRIPT> 0");
}

TEST_F(Report, XyTracesEmbedTheCsvValuesByGroupWithBandsAndReferenceLines) {
  write(run_ / "curves.csv",
        "potential,trial,mean,stderr\nnone,1,704.6,61.5\nnone,2,0.1,0.2\nnone,3,nan,1\n"
        "phi0,1,75.6,9.25\nphi0,2,1e-300,0\n");
  describe(run_, {one_chart({.title = "Steps to the goal against trial",
                             .x = {"trial", pegasus::AxisScale::kLog10},
                             .traces = {{.file = "curves.csv",
                                         .x = "trial",
                                         .y = "mean",
                                         .group_by = {"potential"},
                                         .band = "stderr",
                                         .band_factor = 2,
                                         .band_name = "+-2 s.e."}},
                             .references = {{.y = 22.0, .name = "optimal"}}})});
  const json data = embedded_data(render());
  const json& c = chart_from(data, "curves.csv", "against trial");
  ASSERT_EQ(c["traces"].size(), 2u);
  const json& none = c["traces"][0];
  EXPECT_EQ(none["name"], "none");
  EXPECT_EQ(doubles(none["x"]), (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(none["y"][0].get<double>(), 704.6);
  EXPECT_EQ(none["y"][1].get<double>(), 0.1);  // exact: shortest round-trip text both ways
  EXPECT_TRUE(none["y"][2].is_null());         // nan
  EXPECT_EQ(none["lower"][0].get<double>(), 704.6 - 2 * 61.5);
  EXPECT_EQ(none["upper"][1].get<double>(), 0.1 + 2 * 0.2);
  EXPECT_EQ(none["band_name"], "+-2 s.e.");
  EXPECT_EQ(c["traces"][1]["name"], "phi0");
  EXPECT_EQ(c["traces"][1]["y"][1].get<double>(), 1e-300);
  EXPECT_TRUE(c["x_log"].get<bool>());
  EXPECT_FALSE(c.contains("y_log"));
  ASSERT_EQ(c["hlines"].size(), 1u);
  EXPECT_EQ(c["hlines"][0]["y"].get<double>(), 22.0);
}

TEST_F(Report, ErrorBarsRowFiltersAndOneTraceWithGaps) {
  write(run_ / "results.csv",
        "curve,variable,m,value,stderr\nPEGASUS,v,1,-12.87,1.94\nPEGASUS,w,1,5,5\nPEGASUS,v,2,-10.12,0.56\n"
        "hashed,v,1,-17.44,2.06\nhashed,v,2,-13.41,1.80\n");
  describe(run_, {one_chart({.title = "Value",
                             .x = {"m", pegasus::AxisScale::kLog2},
                             .traces = {{.file = "results.csv",
                                         .x = "m",
                                         .y = "value",
                                         .group_by = {"curve"},
                                         .where = {{"variable", "v"}},
                                         .error = "stderr"}}}),
                  one_chart({.title = "Joined",
                             .traces = {{.file = "results.csv",
                                         .x = "m",
                                         .y = "value",
                                         .group_by = {"curve"},
                                         .name = "all",
                                         .one_trace = true}}},
                            "t")});
  const json data = embedded_data(render());
  const json& c = chart_from(data, "results.csv", "Value");
  ASSERT_EQ(c["traces"].size(), 2u);
  EXPECT_EQ(c["traces"][0]["name"], "PEGASUS");
  EXPECT_EQ(doubles(c["traces"][0]["x"]), (std::vector<double>{1, 2}));
  EXPECT_EQ(doubles(c["traces"][0]["y"]), (std::vector<double>{-12.87, -10.12}));
  EXPECT_EQ(doubles(c["traces"][0]["error"]), (std::vector<double>{1.94, 0.56}));
  EXPECT_EQ(doubles(c["traces"][1]["y"]), (std::vector<double>{-17.44, -13.41}));
  EXPECT_EQ(c["x_log_base"], 2);
  const json& joined = chart_from(data, "results.csv", "Joined");
  ASSERT_EQ(joined["traces"].size(), 1u);
  EXPECT_EQ(joined["traces"][0]["name"], "all");
  const auto y = doubles(joined["traces"][0]["y"]);
  ASSERT_EQ(y.size(), 6u);  // 3 rows, a gap, 2 rows
  EXPECT_TRUE(std::isnan(y[3]));
  EXPECT_EQ(y[4], -17.44);
  // Thinning keeps the gap: the groups never join.
  pegasus::report::ReportOptions few;
  few.max_points = 3;  // every 2nd row: without the rule the gap (the 4th) would be dropped
  const auto thinned =
      doubles(chart_from(pegasus::report::report_data(run_, few), "results.csv", "Joined")["traces"][0]["y"]);
  EXPECT_EQ(std::count_if(thinned.begin(), thinned.end(), [](double v) { return std::isnan(v); }), 1);
  EXPECT_LT(thinned.size(), y.size());
}

TEST_F(Report, FlightChartsGiveReplayBodyVelocitiesAndAltitude) {
  const std::string header = "flight,t,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,xdot_b,ydot_b,zdot_b\n";
  std::string rows;
  for (int f = 0; f < 2; ++f) {
    for (int k = 0; k < 5; ++k) {
      rows += fmt::format("{},{},{},{},{},0.1,-0.05,1.5,1,0,0.5,{},-1,0.25\n", f, 0.02 * k, 0.1 * k + f,
                          -0.2 * k, -10 - 0.01 * k, 0.5 * k + f);
    }
  }
  write(run_ / "flights.csv", header + rows);
  write(run_ / "pilot_flights.csv", header + rows);
  write(run_ / "ideal_path.csv", "t,x,y,z,yaw\n0,0,0,-10,0\n1,5,0,-10,0\n");
  const std::vector<pegasus::FlightSeries> files = {
      {.file = "flights.csv", .label = "policy flight", .body_velocities = true},
      {.file = "pilot_flights.csv", .label = "pilot flight", .body_velocities = true}};
  describe(run_, {pegasus::flight_traces_section(files, "hover", "Flights", "intro"),
                  one_chart(pegasus::flight_replay_chart(files, "ideal_path.csv"), "replay")});
  const json data = embedded_data(render());
  const json* replay = nullptr;
  for (const auto& c : data["charts"]) {
    if (c["kind"] == "replay") replay = &c;
  }
  ASSERT_NE(replay, nullptr);
  ASSERT_EQ((*replay)["flights"].size(), 4u);  // 2 policy flights, 2 pilot flights
  const json& f1 = (*replay)["flights"][1];
  EXPECT_EQ(f1["name"], "policy flight 1");
  EXPECT_EQ(doubles(f1["x"]), (std::vector<double>{1, 1.1, 1.2, 1.3 /* 0.1*3+1 */, 1.4}));
  EXPECT_EQ(f1["z"][4].get<double>(), -10 - 0.01 * 4);
  EXPECT_EQ(f1["yaw"][0].get<double>(), 1.5);
  EXPECT_EQ(doubles((*replay)["ideal"]["x"]), (std::vector<double>{0, 5}));
  // Fig 5.6 draws the body-frame velocity columns; the first flight of each file.
  const json& xdot_b = chart_from(data, "flights.csv", "xdot_b");
  ASSERT_EQ(xdot_b["traces"].size(), 2u);
  EXPECT_EQ(doubles(xdot_b["traces"][0]["y"]), (std::vector<double>{0, 0.5, 1, 1.5, 2}));
  EXPECT_EQ(xdot_b["traces"][1]["name"], "pilot flight 0");
  EXPECT_EQ(xdot_b["traces"][1]["dash"], "dash");
  const json& altitude = chart_from(data, "flights.csv", "Altitude -z");
  EXPECT_EQ(altitude["traces"][0]["y"][1].get<double>(), -(-10 - 0.01));
  // Without body-frame columns the world velocities are drawn.
  describe(run_, {pegasus::flight_traces_section({{.file = "flights.csv", .label = "f"}}, "hover", "F", "")});
  EXPECT_EQ(
      chart_from(embedded_data(render()), "flights.csv", "xdot (north)")["traces"][0]["y"][0].get<double>(),
      1);
}

TEST_F(Report, LongSeriesKeepEveryKthRowAndTheLast) {
  std::string text = "iteration,evaluations,seconds,objective\n";
  for (int i = 0; i < 1001; ++i) text += fmt::format("{},{},{},{}\n", i, 10 * i, 0.5 * i, std::sqrt(i));
  write(run_ / "progress.csv", text);
  describe(run_, {pegasus::optimizer_progress_section({{"", "progress.csv"}}, "intro")});
  pegasus::report::ReportOptions options;
  options.max_points = 100;
  const json data = pegasus::report::report_data(run_, options);
  const json& c = chart_from(data, "progress.csv", "iteration");
  const auto x = doubles(c["traces"][0]["x"]);
  EXPECT_EQ(c["traces"][0]["stride"], 11);  // ceil(1001 / 100)
  ASSERT_EQ(x.size(), 92u);                 // 0, 11, ..., 990 and 1000
  EXPECT_EQ(x[1], 11);
  EXPECT_EQ(x.back(), 1000);
  const auto y = doubles(c["traces"][0]["y"]);
  const auto objective = column(run_ / "progress.csv", 3);
  // Six significant digits: the page's numbers are rounded (chart_number).
  EXPECT_NEAR(y[5], objective[55], 1e-6 * objective[55]);
  EXPECT_NE(y[5], objective[55]);  // sqrt(55) has 17 digits in the CSV
  EXPECT_NEAR(y.back(), objective[1000], 1e-6 * objective[1000]);
  // Against evaluations and time as well.
  EXPECT_EQ(doubles(chart_from(data, "progress.csv", "evaluations")["traces"][0]["x"])[1], 110);
  EXPECT_EQ(doubles(chart_from(data, "progress.csv", "seconds")["traces"][0]["x"])[1], 5.5);
}

TEST_F(Report, VariantProgressFilesAreTracesAndOtherSmallCsvsAreTables) {
  write(run_ / "progress.csv", "iteration,evaluations,seconds,objective\n1,10,0.5,-4\n2,20,1,-3\n");
  write(run_ / "progress_nofeed.csv", "iteration,evaluations,seconds,objective\n1,10,0.5,-6\n");
  write(run_ / "per_flight.csv", "controller,flight,rms_position_m\nlearned,0,0.25\npilot,0,0.61\n");
  describe(run_, {pegasus::optimizer_progress_section(
                     {{"full", "progress.csv"}, {"nofeed", "progress_nofeed.csv"}}, "intro")});
  const std::string html = render();
  const json data = embedded_data(html);
  const json& c = chart_from(data, "progress.csv", "evaluations");
  ASSERT_EQ(c["traces"].size(), 2u);
  EXPECT_EQ(c["traces"][1]["name"], "nofeed");
  EXPECT_EQ(doubles(c["traces"][1]["y"]), (std::vector<double>{-6}));
  EXPECT_EQ(doubles(c["traces"][0]["x"]), (std::vector<double>{10, 20}));
  EXPECT_NE(html.find("<td>pilot</td><td class=\"num\">0</td><td class=\"num\">0.61</td>"),
            std::string::npos);
}

TEST_F(Report, WithoutChartsJsonOnlyTheGenericPartsAreShown) {
  // A run directory from before charts.json: its series are drawn against their first column, nothing more.
  write(run_ / "progress.csv", "iteration,evaluations,seconds,objective\n1,10,0.5,-4\n2,20,1,-3\n");
  const json data = embedded_data(render());
  ASSERT_EQ(data["charts"].size(), 1u);
  EXPECT_EQ(data["charts"][0]["title"], "progress.csv");
  EXPECT_EQ(data["charts"][0]["traces"].size(), 3u);  // evaluations, seconds, objective against iteration
}

TEST_F(Report, StagesOfAPipelineAreLinkedToTheirReports) {
  write(run_ / "hover" / "summary.json", "{}");
  write(run_ / "hover" / "run.json", R"({"command": "heli hover"})");
  write(run_ / "hover" / "report.html", "<html></html>");
  write(run_ / "fly" / "summary.json", "{}");
  fs::create_directories(run_ / "policies");  // not a run
  const std::string html = render();
  EXPECT_NE(html.find("<a href=\"hover/report.html\">hover</a> pegasus heli hover"), std::string::npos);
  EXPECT_NE(html.find("fly  (no report.html yet"), std::string::npos);
  EXPECT_EQ(html.find("policies/report.html"), std::string::npos);
}

}  // namespace
