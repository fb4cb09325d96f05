#include "report_page.hpp"

#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus::report::detail {

namespace fs = std::filesystem;

bool ends_with(std::string_view s, std::string_view tail) {
  return s.size() >= tail.size() && s.substr(s.size() - tail.size()) == tail;
}

std::vector<std::size_t> all_rows(std::size_t n) {
  std::vector<std::size_t> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = i;
  return r;
}

std::size_t thin(std::vector<std::size_t>& rows, std::size_t max_points) {
  if (max_points == 0 || rows.size() <= max_points) return 1;
  const std::size_t k = (rows.size() + max_points - 1) / max_points;
  std::vector<std::size_t> kept;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i] == kGapRow || i % k == 0) kept.push_back(rows[i]);
  }
  if (kept.back() != rows.back()) kept.push_back(rows.back());
  rows = std::move(kept);
  return k;
}

json pick(const std::vector<double>& values, const std::vector<std::size_t>& rows) {
  json out = json::array();
  for (std::size_t r : rows) {
    const double v = r == kGapRow ? std::nan("") : values[r];
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

std::string table_html(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows, const std::string& css_class) {
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

}  // namespace pegasus::report::detail
