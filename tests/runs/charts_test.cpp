// Chart specifications (runs/charts.hpp): charts.json reads back to what was written,
// RunDirectory::add_charts merges sections by id, and render_svg draws exactly the plot one would build from
// the same columns.
#include "pegasus/runs/charts.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "pegasus/heli/runs/flight_charts.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/run_directory.hpp"
#include "support/input_error.hpp"
#include "support/scratch_dir.hpp"

namespace pegasus {
namespace {

namespace fs = std::filesystem;
using test_support::input_error_message;

std::vector<ChartSection> sample_sections() {
  ChartSection progress =
      optimizer_progress_section({{"a", "progress.csv"}, {"b", "progress_b.csv"}}, "intro");
  ChartSection flights =
      flight_traces_section({{.file = "flights.csv", .label = "policy", .body_velocities = true},
                             {.file = "log.csv", .label = "log", .time = "time", .grouped = false}},
                            "hover", "Flights", "");
  flights.charts.push_back(
      flight_replay_chart({{.file = "flights.csv", .label = "policy"}}, "ideal_path.csv", 3));
  flights.charts.push_back({.kind = ChartKind::kBar,
                            .title = "bars",
                            .x = {"setting"},
                            .y = {"error", AxisScale::kLog2},
                            .traces = {{.file = "cv.csv", .x = "setting", .y = "e", .where = {{"k", "v"}}}},
                            .references = {{.y = -1.5, .name = "line", .dash = "dot"}},
                            .categorical = true});
  flights.data = {"raw.csv"};
  return {progress, flights};
}

TEST(Charts, ChartsJsonReadsBackToTheSameSections) {
  const auto sections = sample_sections();
  const nlohmann::json doc = to_json(sections);
  EXPECT_EQ(doc["format"], "pegasus.charts");
  const auto back = charts_from_json(nlohmann::json::parse(doc.dump()), "charts.json");
  EXPECT_EQ(to_json(back), doc);
  ASSERT_EQ(back.size(), 2u);
  const Chart& bars = back[1].charts.back();
  EXPECT_EQ(bars.kind, ChartKind::kBar);
  EXPECT_EQ(bars.y.scale, AxisScale::kLog2);
  EXPECT_EQ(bars.traces[0].where.at("k"), "v");
  EXPECT_EQ(bars.references[0].y, -1.5);
  EXPECT_TRUE(bars.categorical);
  const Chart& altitude = back[1].charts[5];
  EXPECT_EQ(altitude.traces[1].y_factor, -1.0);
  EXPECT_EQ(altitude.traces[1].x, "time");
  EXPECT_EQ(back[1].charts[6].traces[0].max_groups, 3u);
  EXPECT_EQ(chart_files(back), (std::vector<std::string>{"progress.csv", "progress_b.csv", "flights.csv",
                                                         "log.csv", "ideal_path.csv", "cv.csv", "raw.csv"}));
}

TEST(Charts, BadDocumentsNameTheField) {
  auto error = [](const std::string& text) {
    return input_error_message([&] { charts_from_json(nlohmann::json::parse(text), "c.json"); });
  };
  EXPECT_EQ(error(R"({"format": "pegasus.charts", "version": 2})"), "c.json: version: expected 1, got 2");
  EXPECT_EQ(error(R"({"format": "pegasus.charts", "version": 1, "sections": [{"title": "x"}]})"),
            "c.json: sections[0].id: missing");
  EXPECT_EQ(
      error(R"({"format": "pegasus.charts", "version": 1, "sections": [{"id": "s", "charts": [{"kind": "xy",
                  "x": {"scale": "log3"}}]}]})"),
      "c.json: sections[0].charts[0].x.scale: expected linear, log2 or log10, got \"log3\"");
  EXPECT_EQ(
      error(R"({"format": "pegasus.charts", "version": 1, "sections": [{"id": "s", "charts": [{"kind": "xy",
                  "traces": [{"file": "a.csv", "max_groups": 1.5}]}]}]})"),
      "c.json: sections[0].charts[0].traces[0].max_groups: expected a whole number from 0, got 1.5");
  EXPECT_EQ(
      error(R"({"format": "pegasus.charts", "version": 1, "sections": [{"id": "s", "charts": [{"kind": "xy",
                  "traces": [{"file": "/etc/passwd"}]}]}]})"),
      "c.json: sections[0].charts[0].traces[0].file: expected a file name inside the run directory, got "
      "\"/etc/passwd\"");
}

TEST(Charts, AddChartsReplacesASectionOfTheSameIdAndKeepsTheOthers) {
  const fs::path root = test_support::fresh_test_dir("pegasus_charts_");
  ConfigSchema schema;
  schema.add_int("n", 1, "n");
  RunDirectory dir = RunDirectory::open(root / "run", schema);
  const auto sections = sample_sections();
  dir.add_charts(sections[0]);
  dir.add_charts(sections[1]);
  ChartSection replaced = sections[0];
  replaced.title = "Progress, again";
  dir.add_charts(replaced);
  const auto back = charts_from_json(read_json_file(dir.path() / "charts.json"), "charts.json");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].title, "Progress, again");
  EXPECT_EQ(back[1].id, "hover");
  dir.abandon();
  fs::remove_all(root);
}

TEST(Charts, SvgIsThePlotOfTheSameColumns) {
  const fs::path root = test_support::fresh_test_dir("pegasus_charts_");
  write_file_atomic(root / "s.csv", "run,x,y,e\na,1,2,0.5\na,2,4,0.25\nb,1,-1,0\nb,3,nan,1\n");
  const Chart chart{.title = "T",
                    .x = {"x axis", AxisScale::kLog2},
                    .y = {"y axis"},
                    .traces = {{.file = "s.csv",
                                .x = "x",
                                .y = "y",
                                .group_by = {"run"},
                                .name = "run",
                                .y_factor = -1,
                                .band = "e",
                                .band_factor = 2,
                                .mode = "lines+markers",
                                .color = "#123456"}},
                    .references = {{.y = 1.5, .name = "ref"}}};
  SvgPlot expected;
  expected.title("T").x_label("x axis").y_label("y axis").x_scale(AxisScale::kLog2);
  expected.add_series({.name = "run a", .x = {1, 2}, .y = {-2, -4}, .error = {1, 0.5}, .color = "#123456"});
  expected.add_series(
      {.name = "run b", .x = {1, 3}, .y = {1, std::nan("")}, .error = {0, 2}, .color = "#123456"});
  expected.add_reference_line(1.5, "ref");
  EXPECT_EQ(render_svg(chart, root), expected.render());

  // One trace: the groups joined with a break between them, one legend entry.
  Chart joined = chart;
  joined.traces[0].one_trace = true;
  joined.traces[0].band.clear();
  joined.traces[0].mode = "lines";
  joined.traces[0].max_groups = 0;
  SvgPlot one;
  one.title("T").x_label("x axis").y_label("y axis").x_scale(AxisScale::kLog2);
  one.add_series({.name = "run",
                  .x = {1, 2, std::nan(""), 1, 3},
                  .y = {-2, -4, std::nan(""), 1, std::nan("")},
                  .markers = false,
                  .color = "#123456"});
  one.add_reference_line(1.5, "ref");
  EXPECT_EQ(render_svg(joined, root), one.render());

  Chart missing = chart;
  missing.traces[0].file = "none.csv";
  EXPECT_NE(input_error_message([&] { render_svg(missing, root); }).find("none.csv: not found"),
            std::string::npos);
  Chart filtered = chart;
  filtered.traces[0].where = {{"nope", "1"}};
  EXPECT_NE(input_error_message([&] { render_svg(filtered, root); }).find("expected a column 'nope'"),
            std::string::npos);
  EXPECT_THROW(render_svg({.kind = ChartKind::kBox}, root), std::invalid_argument);
  fs::remove_all(root);
}

}  // namespace
}  // namespace pegasus
