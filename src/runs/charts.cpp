#include "pegasus/runs/charts.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>

#include "pegasus/core/error.hpp"
#include "pegasus/io/csv_table.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/io/json_input.hpp"

namespace pegasus {

using json = nlohmann::json;

namespace {

constexpr const char* kFormat = "pegasus.charts";
constexpr int kVersion = 1;

struct KindName {
  ChartKind kind;
  const char* name;
};
constexpr KindName kKinds[] = {{ChartKind::kXY, "xy"},         {ChartKind::kBox, "box"},
                               {ChartKind::kBar, "bar"},       {ChartKind::kTable, "table"},
                               {ChartKind::kReplay, "replay"}, {ChartKind::kMujocoReplay, "mujoco_replay"},
                               {ChartKind::kImage, "image"}};

struct ScaleName {
  AxisScale scale;
  const char* name;
};
constexpr ScaleName kScales[] = {
    {AxisScale::kLinear, "linear"}, {AxisScale::kLog2, "log2"}, {AxisScale::kLog10, "log10"}};

const char* name_of(ChartKind kind) {
  for (const auto& k : kKinds) {
    if (k.kind == kind) return k.name;
  }
  return "xy";
}

const char* name_of(AxisScale scale) {
  for (const auto& s : kScales) {
    if (s.scale == scale) return s.name;
  }
  return "linear";
}

void put(json& out, const char* key, const std::string& value) {
  if (!value.empty()) out[key] = value;
}

json axis_json(const ChartAxis& a) {
  json out = json::object();
  put(out, "title", a.title);
  if (a.scale != AxisScale::kLinear) out["scale"] = name_of(a.scale);
  return out;
}

json trace_json(const ChartTrace& t) {
  json out = {{"file", t.file}};
  put(out, "x", t.x);
  put(out, "y", t.y);
  if (!t.group_by.empty()) out["group_by"] = t.group_by;
  if (!t.where.empty()) out["where"] = t.where;
  put(out, "name", t.name);
  if (t.y_factor != 1.0) out["y_factor"] = t.y_factor;
  put(out, "band", t.band);
  if (t.band_factor != 1.0) out["band_factor"] = t.band_factor;
  put(out, "band_name", t.band_name);
  put(out, "error", t.error);
  if (t.max_groups != 0) out["max_groups"] = t.max_groups;
  if (t.one_trace) out["one_trace"] = true;
  put(out, "mode", t.mode);
  put(out, "dash", t.dash);
  put(out, "color", t.color);
  if (t.width != 0) out["width"] = t.width;
  return out;
}

json chart_json(const Chart& c) {
  json out = {{"kind", name_of(c.kind)}};
  put(out, "title", c.title);
  if (!c.x.title.empty() || c.x.scale != AxisScale::kLinear) out["x"] = axis_json(c.x);
  if (!c.y.title.empty() || c.y.scale != AxisScale::kLinear) out["y"] = axis_json(c.y);
  out["traces"] = json::array();
  for (const auto& t : c.traces) out["traces"].push_back(trace_json(t));
  if (!c.references.empty()) {
    out["references"] = json::array();
    for (const auto& r : c.references) {
      json ref = {{"y", r.y}};
      put(ref, "name", r.name);
      put(ref, "dash", r.dash);
      out["references"].push_back(std::move(ref));
    }
  }
  if (c.equal_aspect) out["equal_aspect"] = true;
  if (c.categorical) out["categorical"] = true;
  put(out, "size", c.size);
  put(out, "path", c.path);
  return out;
}

// Reads fields of one JSON object, naming `where` (file and path) in every error.
// The members of one object of charts.json, named in errors by their path from the file's top
// ("sections[0].charts[1].x.scale"); every check goes through io/json_input's readers.
class Fields {
 public:
  Fields(const json& object, std::string file, std::string where)
      : object_(object), file_(std::move(file)), where_(std::move(where)) {
    if (!object_.is_object())
      json_field_error(file_, where_.empty() ? "(top level)" : where_, "an object", object_);
  }
  [[noreturn]] void fail(const std::string& key, const std::string& expected, const json& value) const {
    json_field_error(file_, at(key), expected, value);
  }
  const json* find(const char* key) const {
    auto it = object_.find(key);
    return it == object_.end() ? nullptr : &*it;
  }
  std::string text(const char* key, bool required = false) const {
    const json* v = required ? &json_member(object_, key, file_, at(key)) : find(key);
    if (!v) return {};
    if (!v->is_string()) fail(key, "a string", *v);
    return v->get<std::string>();
  }
  double number(const char* key, double fallback) const {
    return json_number_or(object_, key, fallback, file_, at(key));
  }
  bool flag(const char* key) const { return json_flag_or(object_, key, false, file_, at(key)); }
  const json& array(const char* key) const {
    static const json empty = json::array();
    const json* v = find(key);
    if (!v) return empty;
    if (!v->is_array()) fail(key, "an array", *v);
    return *v;
  }
  // The path of a member, or of a nested object's member, from the file's top.
  std::string at(const std::string& key) const { return where_.empty() ? key : where_ + "." + key; }
  const std::string& file() const { return file_; }

 private:
  const json& object_;
  std::string file_;
  std::string where_;
};

ChartAxis axis_from(const Fields& parent, const char* key) {
  ChartAxis a;
  const json* v = parent.find(key);
  if (!v) return a;
  Fields f(*v, parent.file(), parent.at(key));
  a.title = f.text("title");
  const std::string scale = f.text("scale");
  if (!scale.empty()) {
    auto it =
        std::find_if(std::begin(kScales), std::end(kScales), [&](const auto& s) { return scale == s.name; });
    if (it == std::end(kScales)) f.fail("scale", "linear, log2 or log10", scale);
    a.scale = it->scale;
  }
  return a;
}

ChartTrace trace_from(const json& value, const std::string& file, const std::string& where) {
  Fields f(value, file, where);
  ChartTrace t;
  t.file = f.text("file", true);
  if (t.file.empty() || t.file.find("..") != std::string::npos || t.file.front() == '/')
    f.fail("file", "a file name inside the run directory", t.file);
  t.x = f.text("x");
  t.y = f.text("y");
  const json& groups = f.array("group_by");
  for (std::size_t i = 0; i < groups.size(); ++i) {
    if (!groups[i].is_string()) f.fail(fmt::format("group_by[{}]", i), "a column name", groups[i]);
    t.group_by.push_back(groups[i].get<std::string>());
  }
  if (const json* filter = f.find("where")) {
    if (!filter->is_object()) f.fail("where", "an object of column: text", *filter);
    for (const auto& [column, text] : filter->items()) {
      if (!text.is_string()) f.fail("where." + column, "a string", text);
      t.where[column] = text.get<std::string>();
    }
  }
  t.name = f.text("name");
  t.y_factor = f.number("y_factor", 1.0);
  t.band = f.text("band");
  t.band_factor = f.number("band_factor", 1.0);
  t.band_name = f.text("band_name");
  t.error = f.text("error");
  const double max_groups = f.number("max_groups", 0);
  if (max_groups < 0 || max_groups > 1e6 ||
      max_groups != static_cast<double>(static_cast<std::size_t>(max_groups)))
    f.fail("max_groups", "a whole number from 0", max_groups);
  t.max_groups = static_cast<std::size_t>(max_groups);
  t.one_trace = f.flag("one_trace");
  t.mode = f.text("mode");
  if (!t.mode.empty() && t.mode != "lines" && t.mode != "markers" && t.mode != "lines+markers")
    f.fail("mode", "lines, markers or lines+markers", t.mode);
  t.dash = f.text("dash");
  t.color = f.text("color");
  t.width = f.number("width", 0);
  return t;
}

Chart chart_from(const json& value, const std::string& file, const std::string& where) {
  Fields f(value, file, where);
  Chart c;
  const std::string kind = f.text("kind", true);
  auto it = std::find_if(std::begin(kKinds), std::end(kKinds), [&](const auto& k) { return kind == k.name; });
  if (it == std::end(kKinds)) f.fail("kind", "xy, box, bar, table, replay, mujoco_replay or image", kind);
  c.kind = it->kind;
  c.title = f.text("title");
  c.x = axis_from(f, "x");
  c.y = axis_from(f, "y");
  const json& traces = f.array("traces");
  for (std::size_t i = 0; i < traces.size(); ++i)
    c.traces.push_back(trace_from(traces[i], file, fmt::format("{}.traces[{}]", where, i)));
  const json& references = f.array("references");
  for (std::size_t i = 0; i < references.size(); ++i) {
    Fields r(references[i], file, fmt::format("{}.references[{}]", where, i));
    json_member(references[i], "y", file, r.at("y"));
    c.references.push_back({r.number("y", 0), r.text("name"), r.text("dash")});
  }
  c.equal_aspect = f.flag("equal_aspect");
  c.categorical = f.flag("categorical");
  c.size = f.text("size");
  c.path = f.text("path");
  return c;
}

}  // namespace

json to_json(const ChartSection& section) {
  json out = {
      {"id", section.id}, {"title", section.title}, {"intro", section.intro}, {"charts", json::array()}};
  for (const auto& c : section.charts) out["charts"].push_back(chart_json(c));
  if (!section.data.empty()) out["data"] = section.data;
  return out;
}

json to_json(const std::vector<ChartSection>& sections) {
  json out = {{"format", kFormat}, {"version", kVersion}, {"sections", json::array()}};
  for (const auto& s : sections) out["sections"].push_back(to_json(s));
  return out;
}

std::vector<ChartSection> charts_from_json(const json& document, const std::string& source) {
  json_format_header(document, source, kFormat, kVersion);
  const Fields top(document, source, "");
  std::vector<ChartSection> out;
  const json& sections = top.array("sections");
  for (std::size_t i = 0; i < sections.size(); ++i) {
    const std::string where = fmt::format("sections[{}]", i);
    Fields f(sections[i], source, where);
    ChartSection s{.id = f.text("id", true), .title = f.text("title"), .intro = f.text("intro")};
    const json& charts = f.array("charts");
    for (std::size_t k = 0; k < charts.size(); ++k)
      s.charts.push_back(chart_from(charts[k], source, fmt::format("{}.charts[{}]", where, k)));
    const json& data = f.array("data");
    for (std::size_t k = 0; k < data.size(); ++k) {
      if (!data[k].is_string()) f.fail(fmt::format("data[{}]", k), "a file name", data[k]);
      s.data.push_back(data[k].get<std::string>());
    }
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<std::string> chart_files(const std::vector<ChartSection>& sections) {
  std::vector<std::string> out;
  auto add = [&](const std::string& file) {
    if (!file.empty() && std::find(out.begin(), out.end(), file) == out.end()) out.push_back(file);
  };
  for (const auto& s : sections) {
    for (const auto& c : s.charts) {
      for (const auto& t : c.traces) add(t.file);
      add(c.path);
    }
    for (const auto& d : s.data) add(d);
  }
  return out;
}

ChartFiles::ChartFiles(std::filesystem::path dir) : dir_(std::move(dir)) {}

const CsvTable& ChartFiles::get(const std::string& file, const std::string& chart) {
  auto it = tables_.find(file);
  if (it == tables_.end()) {
    auto table = CsvTable::load(dir_ / file);
    if (!table)
      throw InputError(fmt::format("{}: not found (chart '{}' draws it)", (dir_ / file).string(), chart));
    it = tables_.emplace(file, std::move(*table)).first;
  }
  return it->second;
}

std::vector<TraceRows> trace_rows(const ChartTrace& trace, const CsvTable& table, std::size_t default_max) {
  auto groups = table.groups(trace.group_by, trace.where);
  const std::size_t most = trace.max_groups != 0 ? trace.max_groups : default_max;
  if (most != 0 && groups.size() > most) groups.resize(most);
  std::vector<TraceRows> out;
  if (trace.one_trace) {
    TraceRows joined{.name = trace.name, .rows = {}};
    for (const auto& [key, rows] : groups) {
      if (!joined.rows.empty()) joined.rows.push_back(kGapRow);
      joined.rows.insert(joined.rows.end(), rows.begin(), rows.end());
    }
    if (!groups.empty()) out.push_back(std::move(joined));
    return out;
  }
  for (auto& [key, rows] : groups) {
    const std::string name = trace.name.empty() ? key : (key.empty() ? trace.name : trace.name + " " + key);
    out.push_back({.name = name, .rows = std::move(rows)});
  }
  return out;
}

std::string render_svg(const Chart& chart, const std::filesystem::path& dir) {
  if (chart.kind != ChartKind::kXY)
    throw std::invalid_argument(fmt::format("render_svg: chart '{}' is not an xy chart", chart.title));
  SvgPlot plot;
  plot.title(chart.title)
      .x_label(chart.x.title)
      .y_label(chart.y.title)
      .x_scale(chart.x.scale)
      .y_scale(chart.y.scale);
  ChartFiles files(dir);
  for (const auto& t : chart.traces) {
    const CsvTable& table = files.get(t.file, chart.title);
    const auto& xs = table.numbers(t.x);
    const auto& ys = table.numbers(t.y);
    // SvgPlot draws one symmetric band per series: the band column, else the error column.
    const std::vector<double>* spread =
        !t.band.empty() ? &table.numbers(t.band) : (!t.error.empty() ? &table.numbers(t.error) : nullptr);
    const double spread_factor = (t.band.empty() ? 1.0 : t.band_factor) * std::abs(t.y_factor);
    for (const auto& line : trace_rows(t, table)) {
      PlotSeries s{.name = line.name,
                   .line = t.mode != "markers",
                   .markers = t.mode == "markers" || t.mode == "lines+markers",
                   .color = t.color};
      for (std::size_t r : line.rows) {
        const bool gap = r == kGapRow;  // SvgPlot breaks the line at a point that is not finite
        s.x.push_back(gap ? std::nan("") : xs[r]);
        s.y.push_back(gap ? std::nan("") : ys[r] * t.y_factor);
        if (spread) s.error.push_back(gap ? 0.0 : (*spread)[r] * spread_factor);
      }
      plot.add_series(std::move(s));
    }
  }
  for (const auto& r : chart.references) plot.add_reference_line(r.y, r.name);
  return plot.render();
}

CsvWriter optimizer_progress_csv(const std::vector<IterationRecord>& history) {
  CsvWriter csv({"iteration", "evaluations", "seconds", "objective"});
  for (const auto& h : history) csv.add_row({h.iteration, h.evaluations, h.seconds, h.value});
  return csv;
}

ChartSection optimizer_progress_section(const std::vector<std::pair<std::string, std::string>>& files,
                                        const std::string& intro, const std::string& y,
                                        const std::vector<std::string>& x_columns) {
  ChartSection section{.id = "progress", .title = "Optimizer progress", .intro = intro};
  const std::map<std::string, std::string> labels = {
      {"iteration", "iterations"},
      {"evaluations", "evaluations of U-hat (policies x scenario sets)"},
      {"seconds", "time (s)"}};
  for (const auto& column : x_columns) {
    const auto label = labels.find(column);
    Chart chart{.title = "U-hat against " + column,
                .x = {label == labels.end() ? column : label->second},
                .y = {"U-hat"}};
    for (const auto& [name, file] : files) {
      chart.traces.push_back({.file = file,
                              .x = column,
                              .y = y,
                              .group_by = {"method", "run", "trial"},
                              .name = name.empty() && files.size() == 1 ? "U-hat" : name,
                              .mode = "lines+markers"});
    }
    section.charts.push_back(std::move(chart));
  }
  return section;
}

}  // namespace pegasus
