#include "pegasus/runs/svg_plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pegasus/io/json_csv.hpp"

namespace pegasus {

namespace {

constexpr const char* kPalette[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                    "#9467bd", "#8c564b", "#e377c2", "#7f7f7f"};

double nice_number(double x, bool round) {
  const double exponent = std::floor(std::log10(x));
  const double fraction = x / std::pow(10.0, exponent);
  double nice;
  if (round) {
    nice = fraction < 1.5 ? 1 : fraction < 3 ? 2 : fraction < 7 ? 5 : 10;
  } else {
    nice = fraction <= 1 ? 1 : fraction <= 2 ? 2 : fraction <= 5 ? 5 : 10;
  }
  return nice * std::pow(10.0, exponent);
}

// One axis: data values -> transformed t (log for log axes) -> pixels.
struct Axis {
  explicit Axis(AxisScale s) : scale(s) {}
  AxisScale scale;
  double lo = 0, hi = 1;      // domain in t
  std::vector<double> ticks;  // in t
  bool log() const { return scale != AxisScale::kLinear; }
  double base() const { return scale == AxisScale::kLog2 ? 2.0 : 10.0; }
  bool usable(double v) const { return std::isfinite(v) && (!log() || v > 0); }
  double t(double v) const { return log() ? std::log(v) / std::log(base()) : v; }
  // 0 to 1 across the frame; data far outside (1e308 on an axis clamped to 1e300, whose distance to the
  // axis overflows) is held at a finite distance past the edge, where the clip path hides it.
  double unit(double v) const { return std::clamp((t(v) - lo) / (hi - lo), -1e6, 1e6); }

  void fit(double vmin, double vmax) {  // vmin, vmax in t
    if (!(vmin <= vmax)) vmin = 0, vmax = 1;
    if (log()) {
      lo = std::floor(vmin);
      hi = std::ceil(vmax);
      if (hi == lo) hi = lo + 1;
      const int stride = std::max(1, static_cast<int>(std::ceil((hi - lo) / 10)));
      ticks.clear();
      for (double k = lo; k <= hi; k += stride) ticks.push_back(k);
      return;
    }
    // The ticks' arithmetic (the range, the steps past each end) must stay finite: data beyond kMaxLinear
    // (a goal radius of 1e308, issue 16) is drawn past the frame's edge instead of stretching the axis.
    constexpr double kMaxLinear = 1e300, kMinPad = 1e-300;
    vmin = std::clamp(vmin, -kMaxLinear, kMaxLinear);
    vmax = std::clamp(vmax, -kMaxLinear, kMaxLinear);
    if (vmax == vmin) {
      const double pad = vmin == 0 ? 1 : std::max(std::abs(vmin) * 0.1, kMinPad);
      vmin -= pad;
      vmax += pad;
    }
    ticks = nice_ticks(vmin, vmax);
    if (ticks.size() < 2) ticks = {vmin, vmax};
    lo = ticks.front();
    hi = ticks.back();
  }

  std::string label(double tick) const {
    if (scale == AxisScale::kLog2) {
      if (tick >= 0 && tick <= 20) return fmt::format("{}", static_cast<long long>(std::exp2(tick)));
      return fmt::format("2^{}", static_cast<long long>(tick));
    }
    if (scale == AxisScale::kLog10) {
      if (std::abs(tick) <= 4) return fmt::format("{}", std::pow(10.0, tick));
      return fmt::format("1e{}", static_cast<long long>(tick));
    }
    const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1;
    if (std::abs(tick) < step * 1e-9) tick = 0;  // no "-0" or "1e-17"
    const double magnitude = std::max(std::abs(lo), std::abs(hi));
    if (magnitude >= 1e6 || step < 1e-4) return fmt::format("{:.3g}", tick);
    const int digits = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
    return fmt::format("{:.{}f}", tick, digits);
  }
};

// The data's range in axis coordinates; error bands and reference lines count for y.
struct DataRange {
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  void take_y(const Axis& ay, double v) {
    if (ay.usable(v)) y0 = std::min(y0, ay.t(v)), y1 = std::max(y1, ay.t(v));
  }
};

DataRange series_range(const std::vector<PlotSeries>& series, const Axis& ax, const Axis& ay) {
  DataRange r;
  for (const auto& s : series) {
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!ax.usable(s.x[i]) || !ay.usable(s.y[i])) continue;
      r.x0 = std::min(r.x0, ax.t(s.x[i]));
      r.x1 = std::max(r.x1, ax.t(s.x[i]));
      r.take_y(ay, s.y[i]);
      if (!s.error.empty() && std::isfinite(s.error[i]))
        r.take_y(ay, s.y[i] - s.error[i]), r.take_y(ay, s.y[i] + s.error[i]);
    }
  }
  return r;
}

// The plot area in pixels, and the maps from data (px, py) and axis coordinates (tx, ty) into it.
struct Frame {
  const Axis& ax;
  const Axis& ay;
  double left, top, pw, ph;
  double px(double x) const { return left + ax.unit(x) * pw; }
  double py(double y) const { return top + ph - ay.unit(y) * ph; }
  double tx(double t) const { return left + (t - ax.lo) / (ax.hi - ax.lo) * pw; }
  double ty(double t) const { return top + ph - (t - ay.lo) / (ay.hi - ay.lo) * ph; }
};

// The document's head, the title, the grid with its tick labels, the frame and the axis labels.
std::string frame_svg(const Frame& f, int width, int height, const std::string& title,
                      const std::string& x_label, const std::string& y_label) {
  const double left = f.left, top = f.top, pw = f.pw, ph = f.ph;
  std::string svg = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"sans-serif\" font-size=\"12\">\n"
      "<rect width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n"
      "<defs><clipPath id=\"plot-clip\"><rect x=\"{2:.2f}\" y=\"{3:.2f}\" width=\"{4:.2f}\" "
      "height=\"{5:.2f}\"/>"
      "</clipPath></defs>\n",
      width, height, left, top, pw, ph);
  if (!title.empty()) {
    svg += fmt::format("<text x=\"{:.2f}\" y=\"25\" text-anchor=\"middle\" font-size=\"15\">{}</text>\n",
                       left + pw / 2, escape_markup(title));
  }
  // Grid and tick labels.
  for (double t : f.ax.ticks) {
    svg += fmt::format(
        "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{0:.2f}\" y2=\"{2:.2f}\" stroke=\"#e0e0e0\"/>\n"
        "<text x=\"{0:.2f}\" y=\"{3:.2f}\" text-anchor=\"middle\">{4}</text>\n",
        f.tx(t), top, top + ph, top + ph + 16, escape_markup(f.ax.label(t)));
  }
  for (double t : f.ay.ticks) {
    svg += fmt::format(
        "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" stroke=\"#e0e0e0\"/>\n"
        "<text x=\"{3:.2f}\" y=\"{4:.2f}\" text-anchor=\"end\">{5}</text>\n",
        left, f.ty(t), left + pw, left - 6, f.ty(t) + 4, escape_markup(f.ay.label(t)));
  }
  svg += fmt::format(
      "<rect id=\"plot-area\" x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" "
      "fill=\"none\" stroke=\"#333\"/>\n",
      left, top, pw, ph);
  svg += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" text-anchor=\"middle\">{}</text>\n", left + pw / 2,
                     height - 15.0, escape_markup(x_label));
  svg +=
      fmt::format("<text transform=\"translate(18 {:.2f}) rotate(-90)\" text-anchor=\"middle\">{}</text>\n",
                  top + ph / 2, escape_markup(y_label));
  return svg;
}

// One series's band, line and markers: unusable points split it into runs, each drawn apart.
std::string series_svg(const Frame& f, const PlotSeries& s) {
  std::vector<std::vector<std::size_t>> runs(1);
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const bool ok = f.ax.usable(s.x[i]) && f.ay.usable(s.y[i]) &&
                    (s.error.empty() || (std::isfinite(s.error[i]) && f.ay.usable(s.y[i] - s.error[i])));
    if (ok) {
      runs.back().push_back(i);
    } else if (!runs.back().empty()) {
      runs.emplace_back();
    }
  }
  std::string svg;
  for (const auto& run : runs) {
    if (run.empty()) continue;
    if (!s.error.empty()) {
      std::string d;
      for (std::size_t i : run)
        d += fmt::format("{}{:.2f},{:.2f}", d.empty() ? "M" : " L", f.px(s.x[i]), f.py(s.y[i] + s.error[i]));
      for (auto it = run.rbegin(); it != run.rend(); ++it) {
        d += fmt::format(" L{:.2f},{:.2f}", f.px(s.x[*it]), f.py(s.y[*it] - s.error[*it]));
      }
      svg += fmt::format("<path d=\"{} Z\" fill=\"{}\" fill-opacity=\"0.2\" stroke=\"none\"/>\n", d, s.color);
    }
    if (s.line && run.size() > 1) {
      std::string points;
      for (std::size_t i : run)
        points += fmt::format("{}{:.2f},{:.2f}", points.empty() ? "" : " ", f.px(s.x[i]), f.py(s.y[i]));
      svg += fmt::format("<polyline points=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"2\"/>\n", points,
                         s.color);
    }
    if (s.markers) {
      for (std::size_t i : run) {
        svg += fmt::format("<circle class=\"marker\" cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"3\" fill=\"{}\"/>\n",
                           f.px(s.x[i]), f.py(s.y[i]), s.color);
      }
    }
  }
  return svg;
}

std::string reference_svg(const Frame& f, double y, const std::string& label) {
  if (!f.ay.usable(y)) return {};
  return fmt::format(
      "<line class=\"reference\" x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" "
      "stroke=\"#555\" "
      "stroke-dasharray=\"6 4\"/>\n<text x=\"{3:.2f}\" y=\"{4:.2f}\" text-anchor=\"end\" "
      "fill=\"#555\">{5}</text>\n",
      f.left, f.py(y), f.left + f.pw, f.left + f.pw - 4, f.py(y) - 4, escape_markup(label));
}

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi)) return {lo, hi};
  const double range = nice_number(hi - lo, false);
  const double step = nice_number(range / std::max(1, target - 1), true);
  const double first = std::floor(lo / step) * step, last = std::ceil(hi / step) * step;
  std::vector<double> ticks;
  for (int i = 0; first + i * step <= last + step * 0.5; ++i) ticks.push_back(first + i * step);
  return ticks;
}

SvgPlot& SvgPlot::title(std::string text) {
  title_ = std::move(text);
  return *this;
}
SvgPlot& SvgPlot::x_label(std::string text) {
  x_label_ = std::move(text);
  return *this;
}
SvgPlot& SvgPlot::y_label(std::string text) {
  y_label_ = std::move(text);
  return *this;
}
SvgPlot& SvgPlot::x_scale(AxisScale scale) {
  x_scale_ = scale;
  return *this;
}
SvgPlot& SvgPlot::y_scale(AxisScale scale) {
  y_scale_ = scale;
  return *this;
}
SvgPlot& SvgPlot::size(int width, int height) {
  if (width < 200 || height < 150) throw std::logic_error("SvgPlot: size must be at least 200 x 150");
  width_ = width;
  height_ = height;
  return *this;
}

SvgPlot& SvgPlot::add_series(PlotSeries series) {
  if (series.x.size() != series.y.size() ||
      (!series.error.empty() && series.error.size() != series.y.size())) {
    throw std::logic_error("SvgPlot: series '" + series.name + "' has x, y and error of different lengths");
  }
  if (series.color.empty()) series.color = kPalette[series_.size() % std::size(kPalette)];
  series_.push_back(std::move(series));
  return *this;
}

SvgPlot& SvgPlot::add_reference_line(double y, std::string label) {
  references_.push_back({y, std::move(label)});
  return *this;
}

std::string SvgPlot::render() const {
  Axis ax(x_scale_), ay(y_scale_);
  DataRange range = series_range(series_, ax, ay);
  for (const auto& r : references_) range.take_y(ay, r.y);
  ax.fit(range.x0, range.x1);
  ay.fit(range.y0, range.y1);

  const double left = 75, top = title_.empty() ? 20 : 45, bottom = 55;
  // The legend is as wide as its longest entry (about 7 px per character at the legend's font size).
  std::size_t longest = 0;
  for (const auto& series : series_) longest = std::max(longest, series.name.size());
  for (const auto& reference : references_) longest = std::max(longest, reference.label.size());
  const double legend_width =
      series_.empty() && references_.empty() ? 20 : 50 + 7.0 * static_cast<double>(longest);
  const Frame frame{.ax = ax,
                    .ay = ay,
                    .left = left,
                    .top = top,
                    .pw = width_ - left - legend_width,
                    .ph = height_ - top - bottom};
  std::string svg = frame_svg(frame, width_, height_, title_, x_label_, y_label_);

  // Series: bands first, so lines and markers stay on top.
  svg += "<g clip-path=\"url(#plot-clip)\">\n";
  for (const auto& s : series_) svg += series_svg(frame, s);
  for (const auto& r : references_) svg += reference_svg(frame, r.y, r.label);
  svg += "</g>\n";

  // Legend, to the right of the plot area.
  double ly = top + 10;
  const double lx = left + frame.pw + 15;
  for (const auto& s : series_) {
    svg += fmt::format(
        "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" stroke=\"{3}\" "
        "stroke-width=\"2\"/>\n<text x=\"{4:.2f}\" y=\"{5:.2f}\">{6}</text>\n",
        lx, ly, lx + 22, s.color, lx + 28, ly + 4, escape_markup(s.name));
    ly += 18;
  }
  for (const auto& r : references_) {
    svg += fmt::format(
        "<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{2:.2f}\" y2=\"{1:.2f}\" stroke=\"#555\" "
        "stroke-dasharray=\"6 4\"/>\n<text x=\"{3:.2f}\" y=\"{4:.2f}\">{5}</text>\n",
        lx, ly, lx + 22, lx + 28, ly + 4, escape_markup(r.label));
    ly += 18;
  }
  return svg + "</svg>\n";
}

}  // namespace pegasus
