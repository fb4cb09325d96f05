#include "pegasus/report/report.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/frames.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/config.hpp"

namespace pegasus::report {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

// One CSV series of the run directory, read whole; cells are checked when a column is asked for.
class Series {
 public:
  // nullopt when the file is absent.
  static std::optional<Series> load(const fs::path& dir, const std::string& name) {
    const fs::path file = dir / name;
    std::error_code ec;
    if (!fs::is_regular_file(file, ec)) return std::nullopt;
    Series s;
    s.file_ = file;
    std::string text;
    try {
      text = read_file(file);
    } catch (const std::exception& e) {
      throw InputError(e.what());
    }
    auto rows = parse_csv(text);
    if (rows.empty())
      throw InputError(fmt::format("{}: empty file, expected a CSV header line", file.string()));
    s.header_ = std::move(rows.front());
    for (std::size_t i = 1; i < rows.size(); ++i) {
      if (rows[i].size() == 1 && rows[i][0].empty()) continue;  // a blank line
      if (rows[i].size() != s.header_.size()) {
        throw InputError(fmt::format("{}:{}: expected {} fields (as in the header), got {}", file.string(),
                                     i + 1, s.header_.size(), rows[i].size()));
      }
      s.lines_.push_back(i + 1);
      s.rows_.push_back(std::move(rows[i]));
    }
    return s;
  }

  std::string name() const { return file_.filename().string(); }
  const std::vector<std::string>& header() const { return header_; }
  std::size_t rows() const { return rows_.size(); }
  bool has(std::string_view column) const { return index(column).has_value(); }

  // The column as numbers (empty cells, "nan" -> NaN); InputError naming file:line and column otherwise.
  // Parsed once per column (flight tables are read by several charts).
  const std::vector<double>& numbers(std::string_view column) const {
    const std::size_t c = require(column);
    if (auto it = parsed_.find(c); it != parsed_.end()) return it->second;
    std::vector<double> out;
    out.reserve(rows_.size());
    for (std::size_t i = 0; i < rows_.size(); ++i) {
      const std::string& cell = rows_[i][c];
      if (cell.empty()) {
        out.push_back(std::nan(""));
        continue;
      }
      const auto x = parse_double(cell);
      if (!x) {
        throw InputError(fmt::format("{}:{}: column '{}': expected a number, got '{}'", file_.string(),
                                     lines_[i], column, cell));
      }
      out.push_back(*x);
    }
    return parsed_.emplace(c, std::move(out)).first->second;
  }
  // True when every cell of the column is a number (or empty).
  bool numeric(std::string_view column) const {
    const auto c = index(column);
    if (!c) return false;
    return std::all_of(rows_.begin(), rows_.end(),
                       [&](const auto& row) { return row[*c].empty() || parse_double(row[*c]).has_value(); });
  }
  std::vector<std::string> texts(std::string_view column) const {
    const std::size_t c = require(column);
    std::vector<std::string> out;
    out.reserve(rows_.size());
    for (const auto& row : rows_) out.push_back(row[c]);
    return out;
  }
  const std::vector<std::vector<std::string>>& cells() const { return rows_; }

 private:
  std::optional<std::size_t> index(std::string_view column) const {
    for (std::size_t i = 0; i < header_.size(); ++i) {
      if (header_[i] == column) return i;
    }
    return std::nullopt;
  }
  std::size_t require(std::string_view column) const {
    if (auto i = index(column)) return *i;
    std::string columns;
    for (const auto& h : header_) columns += (columns.empty() ? "" : ",") + h;
    throw InputError(fmt::format("{}: expected a column '{}' (header: {})", file_.string(), column, columns));
  }

  fs::path file_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<std::size_t> lines_;  // the file line of each row
  mutable std::map<std::size_t, std::vector<double>> parsed_;
};

// Rows of `series` grouped by the values of `keys` (joined by " "), in order of first appearance.
std::vector<std::pair<std::string, std::vector<std::size_t>>> group_rows(
    const Series& series, const std::vector<std::string>& keys) {
  std::vector<std::vector<std::string>> columns;
  for (const auto& k : keys) {
    if (series.has(k)) columns.push_back(series.texts(k));
  }
  std::vector<std::pair<std::string, std::vector<std::size_t>>> groups;
  std::map<std::string, std::size_t> where;
  for (std::size_t r = 0; r < series.rows(); ++r) {
    std::string key;
    for (const auto& c : columns) key += (key.empty() ? "" : " ") + c[r];
    auto [it, fresh] = where.try_emplace(key, groups.size());
    if (fresh) groups.push_back({key, {}});
    groups[it->second].second.push_back(r);
  }
  return groups;
}

std::vector<std::size_t> all_rows(std::size_t n) {
  std::vector<std::size_t> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = i;
  return r;
}

// Every k-th of `rows` (and the last one) so that at most about `max_points` remain; k is returned.
std::size_t thin(std::vector<std::size_t>& rows, std::size_t max_points) {
  if (max_points == 0 || rows.size() <= max_points) return 1;
  const std::size_t k = (rows.size() + max_points - 1) / max_points;
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < rows.size(); i += k) kept.push_back(rows[i]);
  if (kept.back() != rows.back()) kept.push_back(rows.back());
  rows = std::move(kept);
  return k;
}

json pick(const std::vector<double>& values, const std::vector<std::size_t>& rows) {
  json out = json::array();
  for (std::size_t r : rows) {
    const double v = values[r];
    if (std::isfinite(v)) {
      out.push_back(v);
    } else {
      out.push_back(nullptr);
    }
  }
  return out;
}

std::string format_number(double x) {
  if (std::isnan(x)) return "nan";
  return fmt::format("{:.6g}", x);
}

// The page under construction: HTML sections and the chart specifications the page code draws.
class Page {
 public:
  // Registers a chart and returns its placeholder.
  std::string chart(json spec, const std::string& extra_class = "") {
    const std::string id = fmt::format("chart-{}", charts.size());
    spec["id"] = id;
    const std::string kind = spec["kind"];
    charts.push_back(std::move(spec));
    return fmt::format("<div class=\"chart{}{}\" id=\"{}\" data-kind=\"{}\"></div>\n",
                       extra_class.empty() ? "" : " ", extra_class, id, kind);
  }
  void section(const std::string& id, const std::string& title, const std::string& intro_html,
               const std::string& content_html) {
    body += fmt::format("<section id=\"{}\">\n<h2>{}</h2>\n", id, escape_markup(title));
    if (!intro_html.empty()) body += "<p class=\"intro\">" + intro_html + "</p>\n";
    body += content_html + "</section>\n";
    sections.push_back({{"id", id}, {"title", title}});
  }
  void consumed(const std::string& file) { used.insert(file); }

  json charts = json::array();
  json sections = json::array();
  std::string body;
  std::set<std::string> used;
};

json xy_chart(std::string title, std::string x_title, std::string y_title, std::string source) {
  return {{"kind", "xy"},
          {"title", std::move(title)},
          {"x_title", std::move(x_title)},
          {"y_title", std::move(y_title)},
          {"source", std::move(source)},
          {"traces", json::array()}};
}

json trace(const std::string& name, json x, json y) {
  return {{"name", name}, {"x", std::move(x)}, {"y", std::move(y)}};
}

std::string grid(const std::string& content) { return "<div class=\"grid\">\n" + content + "</div>\n"; }

// --- headline, configuration, provenance ------------------------------------------------------------------

void flatten(const json& value, const std::string& prefix, int depth,
             std::vector<std::pair<std::string, std::string>>& out) {
  if (out.size() >= 60) return;
  if (value.is_object()) {
    if (depth >= 2) return;
    for (const auto& [k, v] : value.items())
      flatten(v, prefix.empty() ? k : prefix + "." + k, depth + 1, out);
  } else if (value.is_array()) {
    if (value.size() > 6 ||
        std::any_of(value.begin(), value.end(), [](const json& v) { return v.is_structured(); }))
      return;
    std::string text;
    for (const auto& v : value) {
      text += (text.empty() ? "" : ", ") + (v.is_number_float() ? format_number(v.get<double>())
                                            : v.is_string()     ? v.get<std::string>()
                                                                : v.dump());
    }
    out.push_back({prefix, "[" + text + "]"});
  } else if (value.is_number_float()) {
    out.push_back({prefix, format_number(value.get<double>())});
  } else if (value.is_string()) {
    out.push_back({prefix, value.get<std::string>()});
  } else {
    out.push_back({prefix, value.dump()});
  }
}

std::string table_html(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows, const std::string& css_class = "") {
  std::string out =
      css_class.empty() ? "<table>\n<thead><tr>" : "<table class=\"" + css_class + "\">\n<thead><tr>";
  for (const auto& h : header) out += "<th>" + escape_markup(h) + "</th>";
  out += "</tr></thead>\n<tbody>\n";
  for (const auto& row : rows) {
    out += "<tr>";
    for (const auto& cell : row) {
      const bool number = parse_double(cell).has_value();
      std::string shown = cell;
      if (number && cell.size() > 10) shown = format_number(*parse_double(cell));
      out += (number ? "<td class=\"num\">" : "<td>") + escape_markup(shown) + "</td>";
    }
    out += "</tr>\n";
  }
  return out + "</tbody>\n</table>\n";
}

// --- sections by file
// ---------------------------------------------------------------------------------------

// Objective (U-hat) against iterations, evaluations and time, one trace per run/trial/method if such a
// column is there.
void add_progress(Page& page, const std::vector<std::pair<std::string, Series>>& series,
                  const std::string& y_column, const std::string& caption, const ReportOptions& options) {
  std::string charts;
  const Series& s = series.front().second;
  const std::vector<std::pair<std::string, std::string>> xs = {
      {"iteration", "iterations"},
      {"evaluations", "evaluations of U-hat (policies x scenario sets)"},
      {"seconds", "time (s)"}};
  for (const auto& [column, label] : xs) {
    if (!s.has(column)) continue;
    json spec = xy_chart("U-hat against " + column, label, "U-hat", s.name());
    for (const auto& [label_of_file, file] : series) {
      if (!file.has(column)) continue;
      const auto x = file.numbers(column);
      const auto y = file.numbers(y_column);
      for (const auto& [name, rows] : group_rows(file, {"method", "run", "trial"})) {
        auto kept = rows;
        const std::size_t stride = thin(kept, options.max_points);
        std::string trace_name = label_of_file;
        if (!name.empty()) trace_name += (trace_name.empty() ? "" : " ") + name;
        json t = trace(trace_name.empty() ? "U-hat" : trace_name, pick(x, kept), pick(y, kept));
        t["mode"] = "lines+markers";
        if (stride > 1) t["stride"] = stride;
        spec["traces"].push_back(std::move(t));
      }
    }
    charts += page.chart(std::move(spec));
  }
  page.section("progress", "Optimizer progress", caption, grid(charts));
  for (const auto& [label_of_file, file] : series) page.consumed(file.name());
}

void add_learning_curves(Page& page, const Series& s, const ReportOptions& options) {
  if (s.has("method") && s.has("trial") && s.has("iteration") && s.has("uhat")) {
    const auto x = s.numbers("iteration");
    const auto y = s.numbers("uhat");
    json spec = xy_chart("U-hat during training", "iteration", "U-hat (training scenarios)", s.name());
    for (const auto& [name, rows] : group_rows(s, {"method", "trial"})) {
      spec["traces"].push_back(trace(name, pick(x, rows), pick(y, rows)));
    }
    page.section(
        "learning-curves", "Learning curves",
        "U-hat of each training on its own scenario set, by optimizer iteration (learning_curves.csv).",
        page.chart(std::move(spec)));
  } else if (s.has("episode")) {
    const auto x = s.numbers("episode");
    json spec = xy_chart("Steps per episode", "episode", "steps to the goal", s.name());
    spec["y_log"] = true;
    auto rows = all_rows(s.rows());
    const std::size_t stride = thin(rows, options.max_points);
    for (const auto& column : s.header()) {
      if (column == "episode") continue;
      json t = trace(column, pick(x, rows), pick(s.numbers(column), rows));
      t["width"] = 1;
      if (stride > 1) t["stride"] = stride;
      spec["traces"].push_back(std::move(t));
    }
    page.section("learning-curves", "Learning curves",
                 "Steps per episode of each learner (learning_curves.csv).", page.chart(std::move(spec)));
  } else {
    return;
  }
  page.consumed(s.name());
}

// Shaping experiments (thesis §3.4, Figs 3.2-3.3): mean steps per trial with +-1 standard error bands.
void add_shaping_curves(Page& page, const Series& s, const json& summary, const ReportOptions& options) {
  const auto x = s.numbers("trial");
  auto rows = all_rows(s.rows());
  const std::size_t stride = thin(rows, options.max_points);
  json linear =
      xy_chart("Steps to the goal against trial", "trial", "steps to the goal (mean over runs)", s.name());
  for (const auto& column : s.header()) {
    if (!ends_with(column, "_mean")) continue;
    const std::string name = column.substr(0, column.size() - 5);
    const auto mean = s.numbers(column);
    json t = trace(name, pick(x, rows), pick(mean, rows));
    if (s.has(name + "_stderr")) {
      const auto se = s.numbers(name + "_stderr");
      std::vector<double> lo(mean.size()), hi(mean.size());
      for (std::size_t i = 0; i < mean.size(); ++i) {
        lo[i] = mean[i] - se[i];
        hi[i] = mean[i] + se[i];
      }
      t["lower"] = pick(lo, rows);
      t["upper"] = pick(hi, rows);
      t["band_name"] = name + " +-1 s.e.";
    }
    if (stride > 1) t["stride"] = stride;
    linear["traces"].push_back(std::move(t));
  }
  if (summary.contains("optimal_expected_steps") && summary["optimal_expected_steps"].is_number()) {
    linear["hlines"] =
        json::array({{{"y", summary["optimal_expected_steps"]}, {"name", "optimal policy (expected)"}}});
  }
  json loglog = linear;
  loglog["title"] = "The same on log-log axes";
  loglog["x_log"] = true;
  loglog["y_log"] = true;
  const std::string figure =
      summary.value("experiment", std::string()) == "shaping-flags" ? "Fig 3.3" : "Fig 3.2";
  const std::string runs = summary.contains("runs") ? summary["runs"].dump() : std::string("the");
  page.section(
      "shaping", "Shaping curves (" + figure + ")",
      fmt::format("Sarsa's steps to the goal per trial, mean over {} runs, for each potential; the shaded "
                  "band is +-1 standard error (curves.csv).",
                  escape_markup(runs)),
      grid(page.chart(std::move(linear)) + page.chart(std::move(loglog))));
  page.consumed(s.name());
}

// POMDP gridworld (thesis §4.6, Fig 4.5b): value of the chosen policy against m, best-in-class line.
void add_value_vs_m(Page& page, const Series& s, const json& summary) {
  const auto m = s.numbers("m");
  const auto value = s.numbers("mean_true_value");
  json chart = xy_chart("Value of the chosen policy against m", "scenarios m",
                        "true value of the chosen policy", s.name());
  chart["x_log"] = true;
  chart["x_log_base"] = 2;
  std::optional<std::vector<double>> se;
  if (s.has("stderr_true_value")) se = s.numbers("stderr_true_value");
  for (const auto& [name, rows] : group_rows(s, {"model", "estimator"})) {
    json t = trace(name, pick(m, rows), pick(value, rows));
    t["mode"] = "lines+markers";
    if (se) t["error"] = pick(*se, rows);
    if (name.find("hashed") != std::string::npos) t["dash"] = "dash";
    chart["traces"].push_back(std::move(t));
  }
  if (summary.contains("best_in_class_value") && summary["best_in_class_value"].is_number()) {
    chart["hlines"] = json::array({{{"y", summary["best_in_class_value"]},
                                    {"name", "best policy in the class (exact)"},
                                    {"dash", "solid"}}});
  }
  std::string charts = page.chart(std::move(chart));
  if (s.has("mean_sup_deviation")) {
    const auto dev = s.numbers("mean_sup_deviation");
    json chart2 = xy_chart("Uniform deviation sup |U-hat - U| against m", "scenarios m",
                           "mean sup |U-hat - U|", s.name());
    chart2["x_log"] = true;
    chart2["x_log_base"] = 2;
    for (const auto& [name, rows] : group_rows(s, {"model", "estimator"})) {
      json t = trace(name, pick(m, rows), pick(dev, rows));
      t["mode"] = "lines+markers";
      chart2["traces"].push_back(std::move(t));
    }
    charts += page.chart(std::move(chart2));
  }
  page.section("value-vs-m", "PEGASUS value against m (Fig 4.5b)",
               "Mean true value of the policy each estimator chose, with 1 s.e. bars, against the number of "
               "scenarios; the line is the best policy in the class (results.csv).",
               grid(charts));
  page.consumed(s.name());
}

void add_small_table(Page& page, const Series& s, const std::string& id, const std::string& title,
                     std::size_t max_rows = 60) {
  if (s.rows() == 0 || s.rows() > max_rows) return;
  page.section(id, title, "(" + escape_markup(s.name()) + ")", table_html(s.header(), s.cells()));
  page.consumed(s.name());
}

std::string svg_image(const fs::path& file) {
  static constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const std::string text = read_file(file);
  std::string out;
  out.reserve(text.size() * 4 / 3 + 4);
  std::size_t i = 0;
  for (; i + 2 < text.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(text[i]) << 16) |
                       (static_cast<unsigned char>(text[i + 1]) << 8) |
                       static_cast<unsigned char>(text[i + 2]);
    out += {kBase64[(v >> 18) & 63], kBase64[(v >> 12) & 63], kBase64[(v >> 6) & 63], kBase64[v & 63]};
  }
  if (i < text.size()) {
    unsigned v = static_cast<unsigned char>(text[i]) << 16;
    if (i + 1 < text.size()) v |= static_cast<unsigned char>(text[i + 1]) << 8;
    out += {kBase64[(v >> 18) & 63], kBase64[(v >> 12) & 63],
            i + 1 < text.size() ? kBase64[(v >> 6) & 63] : '=', '='};
  }
  return fmt::format("<img class=\"svg\" alt=\"{}\" src=\"data:image/svg+xml;base64,{}\">\n",
                     escape_markup(file.filename().string()), out);
}

// Bicycle (thesis §4.6): distances ridden, and the rides seen from above.
void add_rides(Page& page, const fs::path& dir, const Series& rides, const ReportOptions& options) {
  std::string content;
  if (rides.has("distance_km")) {
    const auto d = rides.numbers("distance_km");
    json box = {{"kind", "box"},
                {"title", "Distance ridden to the goal"},
                {"y_title", "distance ridden (km)"},
                {"source", rides.name()},
                {"groups", json::array()}};
    for (const auto& [name, rows] : group_rows(rides, {"method", "trial"})) {
      box["groups"].push_back({{"name", name}, {"values", pick(d, rows)}});
    }
    content += page.chart(std::move(box));
  }
  if (auto paths = Series::load(dir, "ride_paths.csv")) {
    const auto x = paths->numbers("x");
    const auto y = paths->numbers("y");
    json chart = xy_chart("Rides seen from above", "x (m)", "y (m)", paths->name());
    chart["equal_aspect"] = true;
    for (const auto& [name, rows] : group_rows(*paths, {"method", "trial", "ride"})) {
      auto kept = rows;
      const std::size_t stride = thin(kept, options.max_points);
      json t = trace("ride " + name, pick(x, kept), pick(y, kept));
      t["width"] = 1;
      if (stride > 1) t["stride"] = stride;
      chart["traces"].push_back(std::move(t));
    }
    content += page.chart(std::move(chart));
    page.consumed(paths->name());
  } else {
    // The commands draw the rides from above as SVG; shown as they are until the paths come as CSV.
    std::vector<fs::path> svgs;
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string();
      if (name.starts_with("rides") && ends_with(name, ".svg")) svgs.push_back(e.path());
    }
    std::sort(svgs.begin(), svgs.end());
    for (const auto& svg : svgs) content += svg_image(svg);
  }
  page.section("rides", "Rides",
               "Each policy ridden from the initial-state distribution with fresh noise (rides.csv).",
               grid(content));
  page.consumed(rides.name());
}

void add_variance(Page& page, const Series& s) {
  const auto u = s.numbers("uhat");
  json box = {{"kind", "box"},
              {"title", "U-hat of one policy over independent scenario sets"},
              {"y_title", "U-hat"},
              {"source", s.name()},
              {"groups", json::array()}};
  for (const auto& [name, rows] : group_rows(s, {"variant"})) {
    box["groups"].push_back({{"name", name}, {"values", pick(u, rows)}});
  }
  page.section("variance", "U-hat by scenario variant",
               "The spread of U-hat across scenario sets is the noise the optimizer sees (uhat.csv).",
               page.chart(std::move(box)));
  page.consumed(s.name());
}

void add_potential(Page& page, const Series& s) {
  json bar = {{"kind", "bar"},
              {"title", "Potential Phi by state"},
              {"x_title", "state"},
              {"y_title", "Phi"},
              {"source", s.name()},
              {"x", pick(s.numbers("state"), all_rows(s.rows()))},
              {"y", pick(s.numbers("phi"), all_rows(s.rows()))}};
  page.section("potential", "Recovered potential",
               "Phi found by least squares over the transitions, 0 at absorbing states (potential.csv).",
               page.chart(std::move(bar)));
  page.consumed(s.name());
}

// System identification (thesis §5.2, Fig 5.2): mean-squared error of open-loop predictions against horizon.
void add_mse_vs_horizon(Page& page, const Series& s) {
  const auto seconds = s.numbers("seconds");
  const auto mse = s.numbers("mse");
  const auto models = s.texts("model");
  std::string charts;
  for (const auto& [variable, rows] : group_rows(s, {"variable"})) {
    json chart = xy_chart(variable, "prediction horizon (s)", "mean-squared error", s.name());
    std::vector<std::string> order;
    std::map<std::string, std::vector<std::size_t>> by_model;
    for (std::size_t r : rows) {
      if (!by_model.count(models[r])) order.push_back(models[r]);
      by_model[models[r]].push_back(r);
    }
    for (const auto& model : order) {
      json t = trace(model, pick(seconds, by_model[model]), pick(mse, by_model[model]));
      if (model.find("global") == std::string::npos) t["dash"] = "dashdot";
      chart["traces"].push_back(std::move(t));
    }
    charts += page.chart(std::move(chart), "small");
  }
  page.section(
      "identification", "Identification error against horizon (Fig 5.2)",
      "Mean-squared error on the hold-out flight between each state variable and the model's open-loop "
      "prediction from a perfect initial state, against the prediction horizon (mse_vs_horizon.csv).",
      grid(charts));
  page.consumed(s.name());
}

void add_cross_validation(Page& page, const Series& s) {
  json bar = {{"kind", "bar"},
              {"title", "Cross-validation error by setting"},
              {"x_title", "setting"},
              {"y_title", "cross-validation error"},
              {"source", s.name()},
              {"categorical", true},
              {"y_log", true},
              {"x", s.texts("setting")},
              {"y", pick(s.numbers("cv_error"), all_rows(s.rows()))}};
  page.section("cross-validation", "Bandwidth cross-validation", "(cross_validation.csv)",
               page.chart(std::move(bar)));
  page.consumed(s.name());
}

// Noise check (thesis §5.2, Fig 5.3): true state, prediction and its 2-sigma band, reset every few seconds.
void add_noise_check(Page& page, const Series& s) {
  const std::string time = s.has("time") ? "time" : "t";
  const auto t = s.numbers(time);
  const auto rows = all_rows(s.rows());
  std::string charts;
  for (const auto& column : s.header()) {
    if (!ends_with(column, "_true")) continue;
    const std::string v = column.substr(0, column.size() - 5);
    if (!s.has(v + "_predicted")) continue;
    const std::string sd_column = s.has(v + "_sd") ? v + "_sd" : "sd";
    json chart = xy_chart(v + ": truth and prediction", "time (s)", v, s.name());
    json truth = trace("true " + v, pick(t, rows), pick(s.numbers(column), rows));
    const auto pred = s.numbers(v + "_predicted");
    json predicted = trace("predicted", pick(t, rows), pick(pred, rows));
    predicted["dash"] = "dashdot";
    if (s.has(sd_column)) {
      const auto sd = s.numbers(sd_column);
      std::vector<double> lo(pred.size()), hi(pred.size());
      for (std::size_t i = 0; i < pred.size(); ++i) {
        lo[i] = pred[i] - 2 * sd[i];
        hi[i] = pred[i] + 2 * sd[i];
      }
      predicted["lower"] = pick(lo, rows);
      predicted["upper"] = pick(hi, rows);
      predicted["band_name"] = "+-2 standard deviations";
    }
    chart["traces"].push_back(std::move(truth));
    chart["traces"].push_back(std::move(predicted));
    charts += page.chart(std::move(chart));
  }
  page.section(
      "noise-check", "Prediction with 2-sigma bands (Fig 5.3)",
      "The model's prediction from the true state, reset to the truth every few seconds; the band is 2 "
      "standard deviations of the predicted state (noise_check.csv).",
      charts);
  page.consumed(s.name());
}

// A helicopter flight: rows of one flight of a flights.csv-like table (NED, radians, seconds).
struct Flight {
  std::string name;
  std::vector<std::size_t> rows;
};

struct FlightTable {
  const Series* series = nullptr;
  std::string time_column;
  std::vector<Flight> flights;
};

FlightTable flight_table(const Series& s, const std::string& label, std::size_t max_flights) {
  FlightTable table{&s, s.has("t") ? "t" : "time", {}};
  for (const auto& [key, rows] : group_rows(s, {"flight"})) {
    if (table.flights.size() >= max_flights) break;
    table.flights.push_back({key.empty() ? label : label + " " + key, rows});
  }
  return table;
}

json replay_flight(const FlightTable& table, const Flight& f, std::size_t max_points) {
  // The replay needs fewer samples than a chart: 25 Hz is smooth on screen.
  const Series& s = *table.series;
  auto rows = f.rows;
  const std::size_t stride = thin(rows, max_points);
  json out = {{"name", f.name}, {"t", pick(s.numbers(table.time_column), rows)}};
  for (const char* c : {"x", "y", "z", "roll", "pitch", "yaw"}) out[c] = pick(s.numbers(c), rows);
  if (stride > 1) out["stride"] = stride;
  return out;
}

// Hover traces against the pilot (thesis §5.3, Figs 5.6-5.7): body-frame velocities and world positions.
void add_flight_traces(Page& page, const std::vector<FlightTable>& tables, const std::string& id,
                       const std::string& title, const std::string& intro, const ReportOptions& options) {
  struct Quantity {
    std::string title, y_title;
    std::function<std::vector<double>(const Series&)> values;
  };
  auto body = [](int axis) {
    return [axis](const Series& s) {
      const auto roll = s.numbers("roll"), pitch = s.numbers("pitch"), yaw = s.numbers("yaw");
      const auto xd = s.numbers("xdot"), yd = s.numbers("ydot"), zd = s.numbers("zdot");
      std::vector<double> out(roll.size());
      for (std::size_t i = 0; i < out.size(); ++i) {
        const heli::Vec3 v_B =
            heli::body_from_world({roll[i], pitch[i], yaw[i]}, heli::Vec3(xd[i], yd[i], zd[i]));
        out[i] = v_B[axis];
      }
      return out;
    };
  };
  const bool velocities = std::all_of(tables.begin(), tables.end(), [](const FlightTable& t) {
    return t.series->has("xdot") && t.series->has("ydot") && t.series->has("zdot");
  });
  std::vector<Quantity> quantities;
  if (velocities) {
    quantities.push_back({"Body velocity xdot_b (forward)", "xdot_b (m/s)", body(0)});
    quantities.push_back({"Body velocity ydot_b (right)", "ydot_b (m/s)", body(1)});
    quantities.push_back({"Body velocity zdot_b (down)", "zdot_b (m/s)", body(2)});
  }
  quantities.push_back({"Position x (north)", "x (m)", [](const Series& s) { return s.numbers("x"); }});
  quantities.push_back({"Position y (east)", "y (m)", [](const Series& s) { return s.numbers("y"); }});
  quantities.push_back({"Altitude -z", "altitude -z (m)", [](const Series& s) {
                          auto z = s.numbers("z");
                          for (double& v : z) v = -v;
                          return z;
                        }});
  std::string charts;
  for (const auto& q : quantities) {
    json chart = xy_chart(q.title, "time (s)", q.y_title, tables.front().series->name());
    for (std::size_t k = 0; k < tables.size(); ++k) {
      const FlightTable& table = tables[k];
      const auto values = q.values(*table.series);
      const auto t = table.series->numbers(table.time_column);
      // One flight of each controller, as in the thesis's figures; every flight is in the 3-D replay.
      for (std::size_t f = 0; f < std::min<std::size_t>(table.flights.size(), 1); ++f) {
        auto rows = table.flights[f].rows;
        const std::size_t stride = thin(rows, options.max_points);
        json tr = trace(table.flights[f].name, pick(t, rows), pick(values, rows));
        tr["color"] = k == 0 ? "#1f77b4" : "#d62728";
        if (k > 0) tr["dash"] = "dash";
        if (f > 0) tr["hidden"] = true;
        if (stride > 1) tr["stride"] = stride;
        chart["traces"].push_back(std::move(tr));
      }
    }
    charts += page.chart(std::move(chart), "small");
  }
  page.section(id, title, intro, grid(charts));
}

void add_flights(Page& page, const fs::path& dir, const ReportOptions& options) {
  const auto flights = Series::load(dir, "flights.csv");
  if (!flights) return;
  const auto pilot = Series::load(dir, "pilot_flights.csv");
  const auto ideal = Series::load(dir, "ideal_path.csv");
  std::vector<FlightTable> tables = {flight_table(*flights, "policy flight", options.max_flights)};
  if (pilot) tables.push_back(flight_table(*pilot, "pilot flight", options.max_flights));
  add_flight_traces(
      page, tables, "hover", pilot ? "Flights against the pilot (Figs 5.6-5.7)" : "Flight traces",
      pilot
          ? "Blue, solid: the learned controller; red, dashed: the scripted pilot; the first flight of each "
            "(all of them are in the 3-D replay). Body-frame velocities (Fig 5.6) and world positions "
            "(Fig 5.7) (flights.csv, pilot_flights.csv)."
          : "Body-frame velocities and world positions of the first flight; all of them are in the 3-D "
            "replay "
            "(flights.csv).",
      options);

  json replay = {{"kind", "replay"},
                 {"title", "3-D replay"},
                 {"source", "flights.csv"},
                 {"flights", json::array()},
                 {"ideal", nullptr}};
  for (const auto& table : tables) {
    for (const auto& f : table.flights)
      replay["flights"].push_back(replay_flight(table, f, options.max_replay_points));
  }
  std::string extra;
  if (ideal) {
    auto rows = all_rows(ideal->rows());
    const std::size_t stride = thin(rows, options.max_points);
    replay["ideal"] = {{"t", pick(ideal->numbers("t"), rows)},
                       {"x", pick(ideal->numbers("x"), rows)},
                       {"y", pick(ideal->numbers("y"), rows)},
                       {"z", pick(ideal->numbers("z"), rows)}};
    if (stride > 1) replay["ideal"]["stride"] = stride;
    json top = xy_chart("Seen from above", "y, east (m)", "x, north (m)", "flights.csv");
    top["equal_aspect"] = true;
    json side = xy_chart("Altitude against time", "time (s)", "altitude -z (m)", "flights.csv");
    const auto ix = ideal->numbers("x"), iy = ideal->numbers("y"), iz = ideal->numbers("z");
    std::vector<double> ialt(iz.size());
    for (std::size_t i = 0; i < iz.size(); ++i) ialt[i] = -iz[i];
    json ideal_top = trace("ideal path", pick(iy, rows), pick(ix, rows));
    ideal_top["dash"] = "dash";
    ideal_top["color"] = "#000000";
    top["traces"].push_back(std::move(ideal_top));
    json ideal_side = trace("ideal path", pick(ideal->numbers("t"), rows), pick(ialt, rows));
    ideal_side["dash"] = "dash";
    ideal_side["color"] = "#000000";
    side["traces"].push_back(std::move(ideal_side));
    for (const auto& f : replay["flights"]) {
      top["traces"].push_back(trace(f["name"], f["y"], f["x"]));
      json alt = json::array();
      for (const auto& z : f["z"]) alt.push_back(z.is_number() ? json(-z.get<double>()) : json(nullptr));
      side["traces"].push_back(trace(f["name"], f["t"], alt));
    }
    extra = grid(page.chart(std::move(top)) + page.chart(std::move(side)));
    page.consumed(ideal->name());
  }
  if (const auto deviation = Series::load(dir, "path_deviation.csv");
      deviation && deviation->has("flight") && deviation->has("t") && deviation->has("path_deviation_m")) {
    json chart =
        xy_chart("Distance to the ideal path", "time (s)", "distance to the path (m)", deviation->name());
    const auto t = deviation->numbers("t");
    const auto d = deviation->numbers("path_deviation_m");
    for (const auto& [name, rows] : group_rows(*deviation, {"flight"})) {
      auto kept = rows;
      const std::size_t stride = thin(kept, options.max_points);
      json tr = trace("flight " + name, pick(t, kept), pick(d, kept));
      tr["width"] = 1.2;
      if (stride > 1) tr["stride"] = stride;
      chart["traces"].push_back(std::move(tr));
    }
    extra += page.chart(std::move(chart), "wide");
    page.consumed(deviation->name());
  }
  page.section(
      "replay", ideal ? "3-D replay against the ideal path (Fig 5.10)" : "3-D replay",
      "Drag to turn the view, scroll to zoom; Play runs the flight in real time (speed adjustable), the "
      "slider moves through it. Coloured lines: the flights; black dashed: the ideal path.",
      page.chart(std::move(replay), "wide") + extra);
  page.consumed(flights->name());
  if (pilot) page.consumed(pilot->name());
}

// heli pilot: the logged flight (state estimate) and the true state.
void add_pilot_log(Page& page, const fs::path& dir, const ReportOptions& options) {
  const auto log = Series::load(dir, "log.csv");
  if (!log || !log->has("x") || !log->has("roll")) return;
  const auto truth = Series::load(dir, "truth.csv");
  std::vector<FlightTable> tables;
  if (truth) tables.push_back(flight_table(*truth, "true state", 1));
  tables.push_back(flight_table(*log, "logged estimate", 1));
  add_flight_traces(
      page, tables, "flight", "Pilot flight",
      "The scripted pilot's flight: true state (blue) and the logged state estimate (red, dashed) "
      "(truth.csv, log.csv).",
      options);
  if (log->has("a1")) {
    json chart = xy_chart("Controls", "time (s)", "control in [-1, 1]", log->name());
    auto rows = all_rows(log->rows());
    const std::size_t stride = thin(rows, options.max_points);
    const auto t = log->numbers(tables.back().time_column);
    for (const char* a : {"a1", "a2", "a3", "a4"}) {
      if (!log->has(a)) continue;
      json tr = trace(a, pick(t, rows), pick(log->numbers(a), rows));
      tr["width"] = 1;
      if (stride > 1) tr["stride"] = stride;
      chart["traces"].push_back(std::move(tr));
    }
    page.section("controls", "Controls",
                 "a1, a2: cyclic pitch; a3: main rotor collective; a4: tail rotor (log.csv).",
                 page.chart(std::move(chart), "wide"));
  }
  json replay = {{"kind", "replay"},
                 {"title", "3-D replay"},
                 {"source", tables.front().series->name()},
                 {"flights", json::array()},
                 {"ideal", nullptr}};
  for (const auto& table : tables) {
    for (const auto& f : table.flights)
      replay["flights"].push_back(replay_flight(table, f, options.max_replay_points));
  }
  page.section("replay", "3-D replay",
               "Drag to turn the view, scroll to zoom; Play runs the flight in real time, the slider moves "
               "through it.",
               page.chart(std::move(replay), "wide"));
  page.consumed(log->name());
  if (truth) page.consumed(truth->name());
}

// Any other CSV series with a numeric first column: its numeric columns against the first.
void add_other_series(Page& page, const fs::path& dir, const ReportOptions& options) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (ends_with(name, ".csv") && !page.used.count(name) && e.is_regular_file()) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  std::string charts;
  for (const auto& name : names) {
    const auto s = Series::load(dir, name);
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
    const auto s = Series::load(dir, name);
    if (s && s->rows() > 0 && s->rows() <= 60 && s->header().size() <= 16) {
      page.section("table-" + name.substr(0, name.size() - 4), name, "", table_html(s->header(), s->cells()));
      page.consumed(name);
    }
  }
}

// mujoco train / rollout: the 3-D replay of one rollout's geoms (replay.json), drawn with three.js
// primitives.
void add_mujoco_replay(Page& page, const fs::path& dir) {
  const fs::path file = dir / "replay.json";
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return;
  json replay;
  try {
    replay = read_json_file(file);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (!replay.is_object() || replay.value("format", "") != "pegasus.mujoco.replay") return;
  json spec = {{"kind", "mujoco_replay"},
               {"title", "3-D replay"},
               {"source", "replay.json"},
               {"geoms", replay.value("geoms", json::array())},
               {"t", replay.value("t", json::array())},
               {"frames", replay.value("frames", json::array())}};
  page.section(
      "replay", "3-D replay",
      "Held-out episode 0 of the final policy (replay.json): every geom of the model drawn as a "
      "three.js primitive at its world position and orientation after each control step. Drag to "
      "turn the view, scroll to zoom; Play runs the episode in real time, the slider moves through it.",
      page.chart(std::move(spec), "wide"));
}

void add_policy(Page& page, const fs::path& dir) {
  const fs::path file = dir / "policy.json";
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return;
  json policy;
  try {
    policy = read_json_file(file);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (!policy.is_object() || !policy.contains("parameters")) return;
  const json& p = policy["parameters"];
  std::vector<std::vector<std::string>> rows;
  auto number = [](const json& v) { return v.is_number() ? format_double(v.get<double>()) : v.dump(); };
  if (p.is_object()) {
    for (const auto& [k, v] : p.items()) rows.push_back({k, number(v)});
  } else if (p.is_array()) {
    const json* names = policy.contains("names") && policy["names"].is_array() ? &policy["names"] : nullptr;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p[i].is_object() && p[i].contains("name") && p[i].contains("value")) {
        rows.push_back({p[i]["name"].is_string() ? p[i]["name"].get<std::string>() : p[i]["name"].dump(),
                        number(p[i]["value"])});
      } else {
        const std::string name = names && i < names->size() && (*names)[i].is_string()
                                     ? (*names)[i].get<std::string>()
                                     : std::to_string(i);
        rows.push_back({name, number(p[i])});
      }
    }
  }
  if (rows.empty() || rows.size() > 500) return;
  page.section("policy", "Policy parameters", "(policy.json)",
               "<details><summary>" + std::to_string(rows.size()) + " parameters</summary>\n" +
                   table_html({"parameter", "value"}, rows) + "</details>\n");
}

std::string read_text_or_empty(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return {};
  return read_file(file);
}

constexpr const char* kStyle = R"(
:root { --fg: #1d2330; --muted: #5b6475; --line: #d8dde6; --bg: #ffffff; --panel: #f6f8fb; --accent: #1f77b4; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: var(--fg); background: var(--bg); }
header { padding: 20px 32px 12px; border-bottom: 1px solid var(--line); background: var(--panel); }
header h1 { margin: 0 0 4px; font-size: 24px; }
header .meta { margin: 0; color: var(--muted); font-size: 13px; }
nav { padding: 8px 32px; border-bottom: 1px solid var(--line); font-size: 13px; }
nav a { margin-right: 14px; color: var(--accent); text-decoration: none; }
main { padding: 8px 32px 40px; max-width: 1500px; }
section { margin: 22px 0 30px; }
h2 { font-size: 19px; margin: 0 0 6px; border-bottom: 1px solid var(--line); padding-bottom: 4px; }
p.intro { margin: 4px 0 12px; color: var(--muted); max-width: 70em; }
table { border-collapse: collapse; font-size: 13px; margin: 6px 0; }
th, td { border: 1px solid var(--line); padding: 3px 9px; text-align: left; }
th { background: var(--panel); }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
pre { background: var(--panel); border: 1px solid var(--line); padding: 10px; overflow: auto; max-height: 420px; font-size: 12.5px; }
details summary { cursor: pointer; color: var(--accent); margin: 6px 0; }
.grid { display: grid; grid-template-columns: repeat(auto-fit, minmax(460px, 1fr)); gap: 14px; }
.chart { min-height: 380px; border: 1px solid var(--line); border-radius: 6px; padding: 4px; background: #fff; }
.chart.small { min-height: 300px; height: 300px; }
.chart.wide { grid-column: 1 / -1; }
.chart.replay { min-height: 0; }
.replay-controls { display: flex; flex-wrap: wrap; align-items: center; gap: 12px; padding: 8px 4px; font-size: 13px; }
.replay-slider { flex: 1 1 300px; }
.replay-time { font-variant-numeric: tabular-nums; min-width: 8em; }
.replay-view canvas { display: block; width: 100%; border-radius: 4px; }
img.svg { max-width: 100%; border: 1px solid var(--line); border-radius: 6px; }
footer { padding: 12px 32px; color: var(--muted); font-size: 12px; border-top: 1px solid var(--line); }
)";

}  // namespace

fs::path find_bundle() {
  std::vector<fs::path> tried;
  if (const char* env = std::getenv(kBundleEnv); env != nullptr && *env != '\0') {
    const fs::path p(env);
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) return p;
    throw std::runtime_error(fmt::format(
        "report JavaScript bundle not found: ${} is '{}', which is not a file", kBundleEnv, p.string()));
  }
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    for (const fs::path& p : {exe.parent_path() / kBundleName,
                              exe.parent_path().parent_path() / "share" / "pegasus" / kBundleName}) {
      std::error_code e2;
      if (fs::is_regular_file(p, e2)) return p;
      tried.push_back(p);
    }
  }
  std::string places;
  for (const auto& p : tried) places += (places.empty() ? "" : ", ") + p.string();
  throw std::runtime_error(fmt::format(
      "report JavaScript bundle {} not found (looked in {}): build the `report_bundle` target (it runs npm "
      "ci in "
      "web/) or set ${} to the file",
      kBundleName, places.empty() ? std::string("no place: the executable's path is unknown") : places,
      kBundleEnv));
}

json report_data(const fs::path& run_dir, const ReportOptions& options) {
  std::error_code ec;
  if (!fs::exists(run_dir, ec)) {
    throw InputError(fmt::format("RUN_DIR '{}': no such directory", run_dir.string()));
  }
  if (!fs::is_directory(run_dir, ec)) {
    throw InputError(fmt::format("RUN_DIR '{}': expected a run directory, got a file", run_dir.string()));
  }
  const fs::path summary_file = run_dir / "summary.json";
  if (!fs::is_regular_file(summary_file, ec)) {
    throw InputError(fmt::format("{}: not found (expected a run directory written by a pegasus command)",
                                 summary_file.string()));
  }
  json summary;
  try {
    summary = read_json_file(summary_file);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  json run = json::object();
  if (fs::is_regular_file(run_dir / "run.json", ec)) {
    try {
      run = read_json_file(run_dir / "run.json");
    } catch (const std::exception& e) {
      throw InputError(e.what());
    }
  }
  fs::path name = run_dir.lexically_normal();
  if (!name.has_filename()) name = name.parent_path();
  std::string title = name.filename().string();
  if (run.is_object() && run.contains("command") && run["command"].is_string()) {
    title = "pegasus " + run["command"].get<std::string>();
  } else if (summary.is_object() && summary.contains("experiment") && summary["experiment"].is_string()) {
    title = summary["experiment"].get<std::string>();
  }

  Page page;
  page.consumed("report.html");
  // Headline figures and configuration.
  std::vector<std::pair<std::string, std::string>> headline;
  flatten(summary, "", 0, headline);
  std::vector<std::vector<std::string>> rows;
  for (auto& [k, v] : headline) rows.push_back({k, v});
  std::string head = rows.empty() ? std::string("<p>(no scalar figures)</p>\n")
                                  : table_html({"figure", "value"}, rows, "headline");
  head += "<details><summary>summary.json</summary>\n<pre>" + escape_markup(summary.dump(2)) +
          "</pre></details>\n";
  page.section("headline", "Headline figures", "From summary.json.", head);
  const std::string config = read_text_or_empty(run_dir / "config.toml");
  std::string config_html =
      "<details open><summary>config.toml</summary>\n<pre>" + escape_markup(config) + "</pre></details>\n";
  if (run.is_object() && !run.empty()) {
    config_html += "<details><summary>run.json (provenance)</summary>\n<pre>" + escape_markup(run.dump(2)) +
                   "</pre></details>\n";
  }
  page.section("config", "Configuration",
               config.empty()
                   ? "No config.toml in the run directory."
                   : "The resolved configuration (defaults, then the config file, then the command line).",
               config_html);

  // Series, by file.
  if (auto s = Series::load(run_dir, "progress.csv")) {
    // progress.csv, and progress_<variant>.csv of the runs that train several variants, as one trace each.
    std::vector<std::pair<std::string, Series>> files;
    std::vector<std::string> variants;
    for (const auto& e : fs::directory_iterator(run_dir)) {
      const std::string n = e.path().filename().string();
      if (n.starts_with("progress_") && ends_with(n, ".csv")) variants.push_back(n);
    }
    std::sort(variants.begin(), variants.end());
    files.emplace_back(variants.empty() ? "" : "progress", std::move(*s));
    for (const auto& n : variants) {
      auto v = Series::load(run_dir, n);
      if (v && v->has("objective")) files.emplace_back(n.substr(9, n.size() - 13), std::move(*v));
    }
    add_progress(
        page, files, "objective",
        "U-hat of the best policy so far against optimizer iterations, evaluations and time (progress.csv).",
        options);
  } else if (auto lc = Series::load(run_dir, "learning_curve.csv");
             lc && lc->has("uhat") && lc->has("iteration")) {
    std::vector<std::pair<std::string, Series>> files;
    files.emplace_back("", std::move(*lc));
    add_progress(page, files, "uhat",
                 "U-hat of the current policy on the training scenarios, by iteration and by evaluations "
                 "(learning_curve.csv).",
                 options);
  }
  if (auto s = Series::load(run_dir, "learning_curves.csv")) add_learning_curves(page, *s, options);
  if (auto s = Series::load(run_dir, "curves.csv"); s && s->has("trial"))
    add_shaping_curves(page, *s, summary, options);
  if (auto s = Series::load(run_dir, "results.csv"); s && s->has("m") && s->has("mean_true_value")) {
    add_value_vs_m(page, *s, summary);
  }
  if (auto s = Series::load(run_dir, "trials.csv"); s && s->has("method"))
    add_small_table(page, *s, "trials", "Trainings");
  if (auto s = Series::load(run_dir, "rides.csv")) add_rides(page, run_dir, *s, options);
  if (auto s = Series::load(run_dir, "uhat.csv"); s && s->has("variant") && s->has("uhat"))
    add_variance(page, *s);
  if (auto s = Series::load(run_dir, "potential.csv"); s && s->has("state") && s->has("phi"))
    add_potential(page, *s);
  if (auto s = Series::load(run_dir, "mse_vs_horizon.csv"); s && s->has("variable"))
    add_mse_vs_horizon(page, *s);
  if (auto s = Series::load(run_dir, "noise_check.csv")) add_noise_check(page, *s);
  if (auto s = Series::load(run_dir, "cross_validation.csv"); s && s->has("setting"))
    add_cross_validation(page, *s);
  add_flights(page, run_dir, options);
  add_mujoco_replay(page, run_dir);
  add_pilot_log(page, run_dir, options);
  add_policy(page, run_dir);
  add_other_series(page, run_dir, options);

  // Runs inside this one (the stages of a pipeline): links to their own reports.
  std::vector<fs::path> parts;
  for (const auto& e : fs::directory_iterator(run_dir)) {
    std::error_code e2;
    if (e.is_directory(e2) && fs::is_regular_file(e.path() / "summary.json", e2)) parts.push_back(e.path());
  }
  std::sort(parts.begin(), parts.end());
  if (!parts.empty()) {
    std::string list = "<ul class=\"parts\">\n";
    for (const auto& part : parts) {
      const std::string n = part.filename().string();
      std::string command;
      try {
        const json r = read_json_file(part / "run.json");
        if (r.contains("command") && r["command"].is_string())
          command = "pegasus " + r["command"].get<std::string>();
      } catch (const std::exception&) {
      }
      std::error_code e2;
      list += fs::is_regular_file(part / "report.html", e2)
                  ? fmt::format("<li><a href=\"{0}/report.html\">{0}</a> {1}</li>\n", escape_markup(n),
                                escape_markup(command))
                  : fmt::format("<li>{} {} (no report.html yet: pegasus report {})</li>\n", escape_markup(n),
                                escape_markup(command), escape_markup(part.string()));
    }
    page.section("parts", "Parts of this run",
                 "Each stage is a run directory of its own, with its own report.", list + "</ul>\n");
  }

  // The files of the run directory.
  std::vector<std::vector<std::string>> files;
  std::vector<fs::directory_entry> entries;
  for (const auto& e : fs::directory_iterator(run_dir)) entries.push_back(e);
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.path() < b.path(); });
  for (const auto& e : entries) {
    const std::string n = e.path().filename().string();
    if (n == "report.html" || n.starts_with(".")) continue;
    std::error_code e2;
    const bool dir = e.is_directory(e2);
    files.push_back({n + (dir ? "/" : ""), dir ? std::string("") : std::to_string(e.file_size(e2))});
  }
  page.section("files", "Files", "The run directory this report was made from.",
               table_html({"file", "bytes"}, files));

  return {{"title", title},    {"run_dir", name.filename().string()}, {"summary", summary},   {"run", run},
          {"body", page.body}, {"sections", page.sections},           {"charts", page.charts}};
}

namespace {

// The script text made safe to sit between <script> and </script>: "</script" would end the element early,
// "<!--" can start the parser's escaped-script state. In JavaScript strings and regular expressions (the
// only places these occur in a minified bundle) "<\/" and "<\!--" mean the same.
std::string script_safe(std::string_view js) {
  std::string out;
  out.reserve(js.size());
  for (std::size_t i = 0; i < js.size(); ++i) {
    if (js[i] == '<' && i + 1 < js.size() && js[i + 1] == '/' && i + 8 <= js.size()) {
      std::string word(js.substr(i + 2, 6));
      std::transform(word.begin(), word.end(), word.begin(), [](unsigned char c) { return std::tolower(c); });
      if (word == "script") {
        out += "<\\/";
        ++i;
        continue;
      }
    }
    if (js.substr(i, 4) == "<!--") {
      out += "<\\!--";
      i += 3;
      continue;
    }
    out += js[i];
  }
  return out;
}

std::string render_data(json data, std::string_view bundle_js) {
  const std::string title = data["title"];
  std::string meta = escape_markup(data["run_dir"].get<std::string>());
  const json& run = data["run"];
  if (run.contains("version"))
    meta +=
        " &middot; pegasus " +
        escape_markup(run["version"].is_string() ? run["version"].get<std::string>() : run["version"].dump());
  if (run.contains("wall_time_s") && run["wall_time_s"].is_number()) {
    meta += fmt::format(" &middot; {:.3g} s wall time", run["wall_time_s"].get<double>());
  }
  if (run.contains("resumed") && run["resumed"].is_boolean() && run["resumed"].get<bool>())
    meta += " &middot; resumed";
  std::string nav;
  for (const auto& s : data["sections"]) {
    nav += fmt::format("<a href=\"#{}\">{}</a>", s["id"].get<std::string>(),
                       escape_markup(s["title"].get<std::string>()));
  }
  const json embedded = {{"title", title}, {"charts", data["charts"]}};
  std::string data_text = embedded.dump();
  // Inside <script> no "</" may appear: in JSON "<" occurs only in strings, where \u003c means the same.
  std::string safe_data;
  safe_data.reserve(data_text.size());
  for (char c : data_text) {
    if (c == '<') {
      safe_data += "\\u003c";
    } else {
      safe_data += c;
    }
  }
  std::string html;
  html.reserve(bundle_js.size() + safe_data.size() + data["body"].get<std::string>().size() + 8192);
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<meta name=\"generator\" content=\"pegasus report\">\n";
  html += "<title>" + escape_markup(title) + " &middot; " +
          escape_markup(data["run_dir"].get<std::string>()) + "</title>\n";
  html += "<style>" + std::string(kStyle) + "</style>\n</head>\n<body>\n";
  html += "<header><h1>" + escape_markup(title) + "</h1><p class=\"meta\">" + meta + "</p></header>\n";
  html += "<nav>" + nav + "</nav>\n<main>\n" + data["body"].get<std::string>() + "</main>\n";
  html +=
      "<footer>Written by <code>pegasus report</code>. Charts drawn with plotly.js, the 3-D replay with "
      "three.js, "
      "both inlined: this file works offline.</footer>\n";
  html += "<script type=\"application/json\" id=\"pegasus-data\">" + safe_data + "</script>\n";
  html += "<script>\n";
  html += script_safe(bundle_js);
  html += "\n</script>\n</body>\n</html>\n";
  return html;
}

fs::path write_data(const fs::path& run_dir, json data, const fs::path& bundle) {
  std::string bundle_js;
  try {
    bundle_js = read_file(bundle);
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("report JavaScript bundle: {}", e.what()));
  }
  const fs::path out = run_dir / "report.html";
  write_file_atomic(out, render_data(std::move(data), bundle_js));
  return out;
}

}  // namespace

std::string render_report(const fs::path& run_dir, std::string_view bundle_js, const ReportOptions& options) {
  return render_data(report_data(run_dir, options), bundle_js);
}

fs::path write_report(const fs::path& run_dir, const fs::path& bundle, const ReportOptions& options) {
  return write_data(run_dir, report_data(run_dir, options), bundle);
}

fs::path write_report(const fs::path& run_dir, const ReportOptions& options) {
  json data = report_data(run_dir, options);  // bad input first: exit 2 even where the bundle is missing
  return write_data(run_dir, std::move(data), find_bundle());
}

bool write_report_or_note(const fs::path& run_dir, std::ostream& err, const ReportOptions& options) {
  try {
    write_report(run_dir, options);
    return true;
  } catch (const std::exception& e) {
    std::string line = e.what();
    std::replace(line.begin(), line.end(), '\n', ' ');
    err << "pegasus: note: no report.html: " << line << std::endl;
    return false;
  }
}

}  // namespace pegasus::report
