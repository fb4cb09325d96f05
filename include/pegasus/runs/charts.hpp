#pragma once
// Chart specifications: what the CSV series of a run directory mean and how to draw them, written by the code
// that wrote the series (charts.json), so that the HTML report and the SVG plots draw from one description
// and know nothing of experiments.
//
// A chart names columns of CSV files in the run directory; it holds no data. Sections group charts under a
// heading. Series that several commands write (optimizer progress, flights) and their charts are defined
// once, here.
//
//   ChartSection s{.id = "progress", .title = "Optimizer progress", .intro = "..."};
//   s.charts.push_back({.title = "U-hat", .x = {"iteration"}, .y = {"U-hat"},
//                       .traces = {{.file = "progress.csv", .x = "iteration", .y = "objective"}}});
//   dir.add_charts(s);                              // charts.json, rewritten atomically
//   dir.write_text("progress.svg", render_svg(s.charts[0], dir.path()));
//
// charts.json: {"format": "pegasus.charts", "version": 1, "sections": [{"id", "title", "intro", "charts":
// [chart...]}]}; each chart and trace as to_json writes it (fields at their defaults are left out).
#include <cstddef>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pegasus/io/csv_table.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/runs/svg_plot.hpp"

namespace pegasus {

class CsvWriter;

// xy      lines or markers of `y` against `x` (the only kind render_svg draws)
// box     box plots of the `y` values of each group
// bar     bars of `y` at each `x` (categorical x when the chart says so)
// table   the file as a table (small files)
// replay  3-D replay of flights: each trace a file of flights (columns t, x, y, z, roll, pitch, yaw; NED
//         metres, radians), grouped by `group_by`; `path` an optional file (t, x, y, z) of the ideal path
// mujoco_replay  3-D replay of a MuJoCo rollout (the trace's file: replay.json)
// image   an SVG file of the run directory, shown as it is
enum class ChartKind { kXY, kBox, kBar, kTable, kReplay, kMujocoReplay, kImage };

struct ChartAxis {
  std::string title{};
  AxisScale scale = AxisScale::kLinear;
};

// Columns of one file; one trace per group of rows when `group_by` names columns.
struct ChartTrace {
  std::string file{};  // relative to the run directory
  std::string x{}, y{};
  std::vector<std::string> group_by{};
  std::map<std::string, std::string> where{};  // only the rows whose cells equal these (column -> text)
  std::string name{};                          // the trace's name; a group's key is appended
  double y_factor = 1.0;                       // drawn as y * y_factor (altitude: -z)
  std::string band{};  // column: a shaded band from y - band_factor * band to y + band_factor * band
  double band_factor = 1.0;
  std::string band_name{};
  std::string error{};         // column: error bars of half-width `error`
  std::size_t max_groups = 0;  // draw the first groups only (0: all)
  bool one_trace = false;      // the groups as one trace, broken between groups (one legend entry)
  std::string mode{};          // "lines" (default), "markers", "lines+markers"
  std::string dash{};          // "", "dash", "dot", "dashdot"
  std::string color{};         // "#rrggbb", or "" for the palette's next
  double width = 0;            // line width, 0: the default
};

struct ChartReference {
  double y = 0;
  std::string name{};
  std::string dash{};
};

struct Chart {
  ChartKind kind = ChartKind::kXY;
  std::string title{};
  ChartAxis x{}, y{};
  std::vector<ChartTrace> traces{};
  std::vector<ChartReference> references{};  // horizontal lines
  bool equal_aspect = false;
  bool categorical = false;  // bar: x is a label
  std::string size{};        // "", "small", "wide"
  std::string path{};        // replay: the ideal path's file
};

struct ChartSection {
  std::string id{}, title{}, intro{};
  std::vector<Chart> charts{};
  std::vector<std::string> data{};  // files of the section's data that no chart draws (named, not drawn)
};

nlohmann::json to_json(const ChartSection& section);
nlohmann::json to_json(const std::vector<ChartSection>& sections);  // the whole of charts.json
// The sections of a charts.json document; InputError naming `source` and the field otherwise.
std::vector<ChartSection> charts_from_json(const nlohmann::json& document, const std::string& source);
// The files the sections name, drawn or as data (each once, in order).
std::vector<std::string> chart_files(const std::vector<ChartSection>& sections);

// The CSV files of a run directory, each read once; InputError naming a missing file and the chart that
// draws it.
class ChartFiles {
 public:
  explicit ChartFiles(std::filesystem::path dir);
  const CsvTable& get(const std::string& file, const std::string& chart);

 private:
  std::filesystem::path dir_;
  std::map<std::string, CsvTable> tables_;
};

// A row index that stands for a break in a line.
inline constexpr std::size_t kGapRow = static_cast<std::size_t>(-1);
// One line a trace draws: its name and rows.
struct TraceRows {
  std::string name;
  std::vector<std::size_t> rows;
};
// The lines of a trace: one per group of rows (named `name key`; the first max_groups, or default_max when
// the trace sets none), or with one_trace a single line through every group, kGapRow between groups. What the
// report and render_svg both draw.
std::vector<TraceRows> trace_rows(const ChartTrace& trace, const CsvTable& table,
                                  std::size_t default_max = 0);

// An SVG of an xy chart, reading its files from `dir` (InputError naming a missing file or column);
// std::invalid_argument for another kind.
std::string render_svg(const Chart& chart, const std::filesystem::path& dir);

// --- series written by several commands, with their charts ---------------------------------------------

// Optimizer progress: iteration, evaluations, seconds, objective (best U-hat so far) per row.
CsvWriter optimizer_progress_csv(const std::vector<IterationRecord>& history);
// U-hat against iterations, evaluations and time, one trace per file (`files` pairs a trace name with a
// progress file; a single file may have an empty name). `y` names the objective column, `x_columns` the
// columns to draw it against (one chart each).
ChartSection optimizer_progress_section(const std::vector<std::pair<std::string, std::string>>& files,
                                        const std::string& intro, const std::string& y = "objective",
                                        const std::vector<std::string>& x_columns = {
                                            "iteration", "evaluations", "seconds"});

}  // namespace pegasus
