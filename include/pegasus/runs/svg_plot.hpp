#pragma once
// A small SVG line chart for run directories: title, axis labels, linear or log2/log10 axes, named series
// with optional error bands (y +- e) and markers, labelled horizontal reference lines, a legend and nice
// tick values. Hand-written because no Debian-packaged C++ plotting library writes plain SVG without a
// runtime (gnuplot, matplotlib-cpp and sciplot all drive an external program).
//
//   SvgPlot plot;
//   plot.title("Estimate error vs m").x_label("scenarios m").y_label("|U-hat -
//   U|").x_scale(AxisScale::kLog2); plot.add_series({.name = "PEGASUS", .x = ms, .y = mean, .error =
//   stderr_}); plot.add_reference_line(0.0, "exact"); run_dir.write_text("error_vs_m.svg", plot.render());
//
// Points that are not finite (or not positive on a log axis) are left out and break the line there.
#include <string>
#include <vector>

namespace pegasus {

enum class AxisScale { kLinear, kLog2, kLog10 };

struct PlotSeries {
  std::string name{};
  std::vector<double> x{}, y{};
  std::vector<double> error{};  // empty, or one half-width per point: a band from y - e to y + e
  bool line = true;
  bool markers = true;
  std::string color{};  // empty: the next colour of the palette
};

class SvgPlot {
 public:
  SvgPlot& title(std::string text);
  SvgPlot& x_label(std::string text);
  SvgPlot& y_label(std::string text);
  SvgPlot& x_scale(AxisScale scale);
  SvgPlot& y_scale(AxisScale scale);
  SvgPlot& size(int width, int height);
  // Throws std::logic_error when x, y (and error, if given) differ in length.
  SvgPlot& add_series(PlotSeries series);
  SvgPlot& add_reference_line(double y, std::string label);

  // The whole SVG document. The plot area is the <rect id="plot-area">; every marker is a
  // <circle class="marker"> inside it.
  std::string render() const;

 private:
  struct Reference {
    double y;
    std::string label;
  };
  std::string title_, x_label_, y_label_;
  AxisScale x_scale_ = AxisScale::kLinear, y_scale_ = AxisScale::kLinear;
  int width_ = 720, height_ = 450;
  std::vector<PlotSeries> series_;
  std::vector<Reference> references_;
};

// Round tick values covering [lo, hi] (about `target` of them, steps of 1, 2 or 5 times a power of ten).
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

}  // namespace pegasus
