#pragma once
// What the report's pieces share (internal to src/report): the page under construction and the helpers that
// turn CSV series into chart specifications and HTML.
#include <fmt/format.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "pegasus/io/json_csv.hpp"
#include "pegasus/report/report.hpp"

namespace pegasus::report::detail {

using json = nlohmann::json;

bool ends_with(std::string_view s, std::string_view tail);
// 0, 1, ..., n - 1.
std::vector<std::size_t> all_rows(std::size_t n);
// Every k-th of `rows` (and the last one) so that at most about `max_points` remain; k is returned.
// Gaps (kGapRow) are always kept, so that thinning never joins two groups of a one_trace line.
std::size_t thin(std::vector<std::size_t>& rows, std::size_t max_points);
// A number as the page carries it: rounded to six significant digits (what a chart can show).
double chart_number(double x);
// values at `rows` as a JSON array of chart numbers, null for a gap or a value that is not finite.
json pick(const std::vector<double>& values, const std::vector<std::size_t>& rows);
std::string format_number(double x);

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

json xy_chart(std::string title, std::string x_title, std::string y_title, std::string source);
json trace(const std::string& name, json x, json y);
std::string grid(const std::string& content);
std::string table_html(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows, const std::string& css_class = "");
// RFC 4648 base64 of `bytes`.
std::string base64(std::string_view bytes);
// `text` compressed in the gzip format (zlib at its best compression). std::runtime_error if zlib fails.
std::string gzip(std::string_view text);
// An SVG file inlined as an <img> (base64 data URL).
std::string svg_image(const std::filesystem::path& file);

// The sections charts.json describes (nothing when the run directory has none).
void add_chart_sections(Page& page, const std::filesystem::path& dir, const ReportOptions& options);
// Any other CSV series with a numeric first column: its numeric columns against the first; small tables.
void add_other_series(Page& page, const std::filesystem::path& dir, const ReportOptions& options);

}  // namespace pegasus::report::detail
