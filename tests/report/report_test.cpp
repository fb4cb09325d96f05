// The HTML report generator (include/pegasus/report/report.hpp) and `pegasus
// report`: the page is one self-contained file, the data it embeds is the run's
// CSV data, and a bad run directory is refused before anything is written. The
// browser test (tests/browser) checks that the pages draw.
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
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/flight_charts.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;
using pegasus::test_support::input_error_message;
using pegasus::test_support::read_text;
using pegasus::test_support::run_pegasus;

constexpr const char* kFakeBundle = "window.pegasusFakeBundle = 1; /* bundle */";

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

// The bytes of base64 text.
std::string from_base64(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned bits = 0;
  int count = 0;
  for (char c : text) {
    const auto v = alphabet.find(c);
    if (v == std::string::npos) continue;  // '=' padding
    bits = (bits << 6) | static_cast<unsigned>(v);
    if ((count += 6) >= 8) {
      count -= 8;
      out += static_cast<char>((bits >> count) & 0xff);
    }
  }
  return out;
}

// The text of gzip-compressed bytes.
std::string gunzip(const std::string& bytes) {
  z_stream z{};
  EXPECT_EQ(inflateInit2(&z, 15 + 16), Z_OK);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  std::string out;
  char buffer[65536];
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof buffer;
    status = inflate(&z, Z_NO_FLUSH);
    out.append(buffer, sizeof buffer - z.avail_out);
  }
  inflateEnd(&z);
  EXPECT_EQ(status, Z_STREAM_END);
  return out;
}

// The JSON block of a report page (gzip-compressed, base64-encoded).
json embedded_data(const std::string& html) {
  const std::string open =
      "<script type=\"application/gzip\" id=\"pegasus-data\" data-encoding=\"gzip+base64\">";
  const auto begin = html.find(open);
  EXPECT_NE(begin, std::string::npos);
  const auto start = begin + open.size();
  const auto end = html.find("</script>", start);
  return json::parse(gunzip(from_base64(html.substr(start, end - start))));
}

const json& chart_from(const json& data, const std::string& source, const std::string& title_part = "") {
  for (const auto& c : data["charts"]) {
    if (c.value("source", "") == source && c.value("title", "").find(title_part) != std::string::npos)
      return c;
  }
  static const json none;
  ADD_FAILURE() << "no chart from " << source << " titled *" << title_part << "*";
  return none;
}

std::vector<double> doubles(const json& a) {
  std::vector<double> out;
  for (const auto& v : a) out.push_back(v.is_null() ? std::nan("") : v.get<double>());
  return out;
}

std::vector<double> column(const fs::path& csv, std::size_t c) {
  const auto rows = pegasus::parse_csv(read_text(csv));
  std::vector<double> out;
  for (std::size_t r = 1; r < rows.size(); ++r) out.push_back(std::stod(rows[r][c]));
  return out;
}

class Report : public pegasus::test_support::TempDirTest {
 protected:
  fs::path run_ = dir_ / "run";
  void SetUp() override {
    TempDirTest::SetUp();
    run_ = dir_ / "run";
    write(run_ / "summary.json",
          R"({"experiment": "shaping-gridworld", "runs": 3, "optimal_expected_steps": 22.0,
                                     "nested": {"a": 0.1}})");
    write(run_ / "config.toml", "# the resolved configuration\nsize = 10\n");
  }
  std::string render() const { return pegasus::report::render_report(run_, kFakeBundle); }
};

// The run's charts.json, written as commands write it.
void describe(const fs::path& run, const std::vector<pegasus::ChartSection>& sections) {
  write(run / "charts.json", pegasus::to_json(sections).dump());
}

pegasus::ChartSection one_chart(pegasus::Chart chart, std::string id = "s") {
  return {.id = std::move(id), .title = "Section", .intro = "intro", .charts = {std::move(chart)}};
}

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
