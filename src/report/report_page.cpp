#include "report_page.hpp"

#include <zlib.h>

#include <cmath>
#include <stdexcept>

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

double chart_number(double x) {
  if (!std::isfinite(x) || x == 0) return x;
  // Six significant digits, as their shortest decimal text: the chart draws the same to the pixel, and the
  // page carries "0.123457" where the CSV's double printed 17 digits.
  return std::stod(fmt::format("{:.6g}", x));
}

json pick(const std::vector<double>& values, const std::vector<std::size_t>& rows) {
  json out = json::array();
  for (std::size_t r : rows) {
    const double v = r == kGapRow ? std::nan("") : values[r];
    if (std::isfinite(v)) {
      out.push_back(chart_number(v));
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

std::string base64(std::string_view bytes) {
  static constexpr char kBase64[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve(bytes.size() * 4 / 3 + 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += {kBase64[(v >> 18) & 63], kBase64[(v >> 12) & 63], kBase64[(v >> 6) & 63], kBase64[v & 63]};
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += {kBase64[(v >> 18) & 63], kBase64[(v >> 12) & 63],
            i + 1 < bytes.size() ? kBase64[(v >> 6) & 63] : '=', '='};
  }
  return out;
}

std::string gzip(std::string_view text) {
  z_stream z{};
  // windowBits 15 + 16: the gzip format (header and CRC), which the browser's DecompressionStream("gzip")
  // reads.
  if (deflateInit2(&z, Z_BEST_COMPRESSION, Z_DEFLATED, 15 + 16, 9, Z_DEFAULT_STRATEGY) != Z_OK)
    throw std::runtime_error("zlib: deflateInit2 failed");
  std::string out(deflateBound(&z, static_cast<uLong>(text.size())) + 32, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(text.data()));
  z.avail_in = static_cast<uInt>(text.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  const int status = deflate(&z, Z_FINISH);
  const std::size_t written = z.total_out;
  deflateEnd(&z);
  if (status != Z_STREAM_END) throw std::runtime_error("zlib: deflate did not finish");
  out.resize(written);
  return out;
}

std::string svg_image(const fs::path& file) {
  return fmt::format("<img class=\"svg\" alt=\"{}\" src=\"data:image/svg+xml;base64,{}\">\n",
                     escape_markup(file.filename().string()), base64(read_file(file)));
}

}  // namespace pegasus::report::detail
