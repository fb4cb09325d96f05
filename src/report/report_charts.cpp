// The report's sections from the run's own chart specifications (charts.json) and from any other CSV series.
#include <algorithm>
#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/csv_table.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/runs/charts.hpp"
#include "report_page.hpp"

namespace pegasus::report::detail {

namespace fs = std::filesystem;

namespace {

// --- charts.json: the run's own chart specifications -----------------------------------------------------

void put_axes(json& spec, const Chart& c) {
  if (c.x.scale != AxisScale::kLinear) spec["x_log"] = true;
  if (c.x.scale == AxisScale::kLog2) spec["x_log_base"] = 2;
  if (c.y.scale != AxisScale::kLinear) spec["y_log"] = true;
  if (c.y.scale == AxisScale::kLog2) spec["y_log_base"] = 2;
}

json xy_spec(const Chart& c, ChartFiles& tables, const ReportOptions& options) {
  json spec = xy_chart(c.title, c.x.title, c.y.title, c.traces.empty() ? "" : c.traces.front().file);
  put_axes(spec, c);
  if (c.equal_aspect) spec["equal_aspect"] = true;
  for (const auto& t : c.traces) {
    const CsvTable& table = tables.get(t.file, c.title);
    const auto& xs = table.numbers(t.x);
    std::vector<double> ys = table.numbers(t.y);
    for (double& v : ys) v *= t.y_factor;
    std::vector<double> lower, upper;
    if (!t.band.empty()) {
      const auto& half = table.numbers(t.band);
      lower.resize(ys.size());
      upper.resize(ys.size());
      for (std::size_t i = 0; i < ys.size(); ++i) {
        lower[i] = ys[i] - t.band_factor * std::abs(t.y_factor) * half[i];
        upper[i] = ys[i] + t.band_factor * std::abs(t.y_factor) * half[i];
      }
    }
    for (const auto& line : trace_rows(t, table)) {
      auto kept = line.rows;
      const std::size_t stride = thin(kept, options.max_points);
      json tr = trace(line.name, pick(xs, kept), pick(ys, kept));
      if (!t.band.empty()) {
        tr["lower"] = pick(lower, kept);
        tr["upper"] = pick(upper, kept);
        if (!t.band_name.empty()) tr["band_name"] = t.band_name;
      }
      if (!t.error.empty()) tr["error"] = pick(table.numbers(t.error), kept);
      if (!t.mode.empty()) tr["mode"] = t.mode;
      if (!t.dash.empty()) tr["dash"] = t.dash;
      if (!t.color.empty()) tr["color"] = t.color;
      if (t.width != 0) tr["width"] = t.width;
      if (stride > 1) tr["stride"] = stride;
      spec["traces"].push_back(std::move(tr));
    }
  }
  if (!c.references.empty()) {
    spec["hlines"] = json::array();
    for (const auto& r : c.references) {
      json h = {{"y", r.y}, {"name", r.name}};
      if (!r.dash.empty()) h["dash"] = r.dash;
      spec["hlines"].push_back(std::move(h));
    }
  }
  return spec;
}

json box_spec(const Chart& c, ChartFiles& tables) {
  json spec = {{"kind", "box"},
               {"title", c.title},
               {"x_title", c.x.title},
               {"y_title", c.y.title},
               {"source", c.traces.empty() ? "" : c.traces.front().file},
               {"groups", json::array()}};
  put_axes(spec, c);
  for (const auto& t : c.traces) {
    const CsvTable& table = tables.get(t.file, c.title);
    const auto& values = table.numbers(t.y);
    for (const auto& line : trace_rows(t, table))
      spec["groups"].push_back({{"name", line.name}, {"values", pick(values, line.rows)}});
  }
  return spec;
}

json bar_spec(const Chart& c, ChartFiles& tables) {
  if (c.traces.size() != 1)
    throw InputError(fmt::format("charts.json: bar chart '{}': expected one trace", c.title));
  const ChartTrace& t = c.traces.front();
  const CsvTable& table = tables.get(t.file, c.title);
  const auto rows = all_rows(table.rows());
  json spec = {{"kind", "bar"},
               {"title", c.title},
               {"x_title", c.x.title},
               {"y_title", c.y.title},
               {"source", t.file},
               {"categorical", c.categorical},
               {"y", pick(table.numbers(t.y), rows)}};
  put_axes(spec, c);
  if (c.categorical) {
    spec["x"] = table.texts(t.x);
  } else {
    spec["x"] = pick(table.numbers(t.x), rows);
  }
  return spec;
}

// Flights for the 3-D replay: NED positions and Euler angles against time, every `stride`-th sample.
json replay_spec(const Chart& c, ChartFiles& tables, const ReportOptions& options) {
  json spec = {{"kind", "replay"},
               {"title", c.title},
               {"source", c.traces.empty() ? "" : c.traces.front().file},
               {"flights", json::array()},
               {"ideal", nullptr}};
  for (const auto& t : c.traces) {
    const CsvTable& table = tables.get(t.file, c.title);
    const std::string time = t.x.empty() ? "t" : t.x;
    for (const auto& line : trace_rows(t, table, options.max_flights)) {
      auto kept = line.rows;
      const std::size_t stride = thin(kept, options.max_replay_points);
      json f = {{"name", line.name}, {"t", pick(table.numbers(time), kept)}};
      for (const char* column : {"x", "y", "z", "roll", "pitch", "yaw"})
        f[column] = pick(table.numbers(column), kept);
      if (stride > 1) f["stride"] = stride;
      spec["flights"].push_back(std::move(f));
    }
  }
  if (!c.path.empty()) {
    const CsvTable& ideal = tables.get(c.path, c.title);
    auto rows = all_rows(ideal.rows());
    const std::size_t stride = thin(rows, options.max_points);
    spec["ideal"] = {{"t", pick(ideal.numbers("t"), rows)},
                     {"x", pick(ideal.numbers("x"), rows)},
                     {"y", pick(ideal.numbers("y"), rows)},
                     {"z", pick(ideal.numbers("z"), rows)}};
    if (stride > 1) spec["ideal"]["stride"] = stride;
  }
  return spec;
}

json mujoco_replay_spec(const Chart& c, const fs::path& dir, const ReportOptions& options) {
  if (c.traces.size() != 1)
    throw InputError(fmt::format("charts.json: replay '{}': expected one trace naming replay.json", c.title));
  const fs::path file = dir / c.traces.front().file;
  json replay;
  try {
    replay = read_json_file(file);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (!replay.is_object() || replay.value("format", "") != "pegasus.mujoco.replay")
    throw InputError(
        fmt::format("{}: expected a MuJoCo replay (format pegasus.mujoco.replay)", file.string()));
  // Written with version 1 since replays began (mujoco/runs/mujoco_runs.cpp): another is a layout this build
  // cannot pose.
  if (const json& version = replay.value("version", json()); version != 1)
    json_field_error(file.string(), "version", "1 (the replay layout this build reads)", version);
  // The viewer poses geom g of frame k from frames[k][7g .. 7g + 6] (position, quaternion) at time t[k]: a
  // frame of another size would pose the wrong geoms, or read past its end.
  const auto field_error = [&](const std::string& field, const std::string& expected) {
    return InputError(fmt::format("{}: {}: expected {}", printable(file.string()), field, expected));
  };
  const json& geoms = replay.value("geoms", json::array());
  const json& t = replay.value("t", json::array());
  const json& frames = replay.value("frames", json::array());
  if (!geoms.is_array()) throw field_error("geoms", "an array");
  if (!t.is_array() || !frames.is_array() || t.size() != frames.size())
    throw field_error("t, frames", "two arrays of one length");
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (!t[k].is_number()) throw field_error(fmt::format("t[{}]", k), "a number");
    const json& frame = frames[k];
    if (!frame.is_array() || frame.size() != 7 * geoms.size())
      throw field_error(fmt::format("frames[{}]", k), fmt::format("{} numbers (7 for each of the {} geoms)",
                                                                  7 * geoms.size(), geoms.size()));
    for (const json& x : frame)
      if (!x.is_number()) throw field_error(fmt::format("frames[{}]", k), "numbers only");
  }
  // Every k-th frame (and the last), as chart numbers, like a flight's replay.
  std::vector<std::size_t> rows = all_rows(frames.size());
  const std::size_t stride = rows.empty() ? 1 : thin(rows, options.max_replay_points);
  json kept_t = json::array(), kept_frames = json::array();
  for (std::size_t k : rows) {
    kept_t.push_back(chart_number(t[k].get<double>()));
    json frame = json::array();
    for (const json& x : frames[k]) frame.push_back(chart_number(x.get<double>()));
    kept_frames.push_back(std::move(frame));
  }
  json spec = {{"kind", "mujoco_replay"}, {"title", c.title}, {"source", c.traces.front().file},
               {"geoms", geoms},          {"t", kept_t},      {"frames", kept_frames}};
  if (stride > 1) spec["stride"] = stride;
  return spec;
}

}  // namespace

void add_chart_sections(Page& page, const fs::path& dir, const ReportOptions& options) {
  const fs::path file = dir / "charts.json";
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return;
  std::vector<ChartSection> sections;
  try {
    sections = charts_from_json(read_json_file(file), file.string());
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  ChartFiles tables(dir);
  for (const auto& s : sections) {
    std::string content;
    std::size_t plots = 0;
    for (const auto& c : s.charts) {
      switch (c.kind) {
        case ChartKind::kXY:
          content += page.chart(xy_spec(c, tables, options), c.size);
          ++plots;
          break;
        case ChartKind::kBox:
          content += page.chart(box_spec(c, tables), c.size);
          ++plots;
          break;
        case ChartKind::kBar:
          content += page.chart(bar_spec(c, tables), c.size);
          ++plots;
          break;
        case ChartKind::kReplay:
          content += page.chart(replay_spec(c, tables, options), "wide");
          break;
        case ChartKind::kMujocoReplay:
          content += page.chart(mujoco_replay_spec(c, dir, options), "wide");
          break;
        case ChartKind::kTable:
          for (const auto& t : c.traces) {
            const CsvTable& table = tables.get(t.file, c.title);
            content += table_html(table.header(), table.cells());
          }
          break;
        case ChartKind::kImage:
          for (const auto& t : c.traces) content += svg_image(dir / t.file);
          ++plots;
          break;
      }
    }
    if (!s.data.empty()) {
      std::string names;
      for (const auto& d : s.data) names += (names.empty() ? "" : ", ") + escape_markup(d);
      content += "<p class=\"intro\">Data: " + names + "</p>\n";
    }
    page.section(s.id, s.title, escape_markup(s.intro), plots > 1 ? grid(content) : content);
  }
  page.consumed("charts.json");
  for (const auto& f : chart_files(sections)) page.consumed(f);
}

void add_other_series(Page& page, const fs::path& dir, const ReportOptions& options) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (ends_with(name, ".csv") && !page.used.count(name) && e.is_regular_file()) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  std::string charts;
  for (const auto& name : names) {
    const auto s = CsvTable::load(dir / name);
    if (!s || s->rows() == 0 || s->header().size() < 2 || s->header().size() > 16 ||
        !s->numeric(s->header()[0]))
      continue;
    const auto x = s->numbers(s->header()[0]);
    // Only series along an increasing first column (step, time, iteration): a table of trials is not a curve.
    bool increasing = true;
    for (std::size_t i = 1; i < x.size(); ++i) increasing = increasing && x[i] > x[i - 1];
    if (!increasing) continue;
    auto rows = all_rows(s->rows());
    const std::size_t stride = thin(rows, options.max_points);
    json chart = xy_chart(name, s->header()[0], "", name);
    for (std::size_t c = 1; c < s->header().size(); ++c) {
      if (!s->numeric(s->header()[c])) continue;
      json tr = trace(s->header()[c], pick(x, rows), pick(s->numbers(s->header()[c]), rows));
      if (stride > 1) tr["stride"] = stride;
      chart["traces"].push_back(std::move(tr));
    }
    if (chart["traces"].empty()) continue;
    charts += page.chart(std::move(chart));
    page.consumed(name);
  }
  if (!charts.empty()) page.section("series", "Other series", "", grid(charts));
  // Small tables that are not series (one row per flight, per run, ...).
  for (const auto& name : names) {
    if (page.used.count(name)) continue;
    const auto s = CsvTable::load(dir / name);
    if (s && s->rows() > 0 && s->rows() <= 60 && s->header().size() <= 16) {
      page.section("table-" + name.substr(0, name.size() - 4), name, "", table_html(s->header(), s->cells()));
      page.consumed(name);
    }
  }
}

}  // namespace pegasus::report::detail
