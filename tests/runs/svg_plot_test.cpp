#include "pegasus/runs/svg_plot.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <regex>

#include "pegasus/io/atomic_file.hpp"

namespace pegasus {
namespace {

struct Rect {
  double x, y, w, h;
};

double attribute(const std::string& element, const std::string& name) {
  std::smatch m;
  const std::regex re(" " + name + "=\"([-0-9.]+)\"");
  if (!std::regex_search(element, m, re)) ADD_FAILURE() << "no " << name << " in " << element;
  return std::stod(m[1]);
}

Rect plot_area(const std::string& svg) {
  std::smatch m;
  EXPECT_TRUE(std::regex_search(svg, m, std::regex("<rect id=\"plot-area\"[^>]*>")));
  const std::string e = m[0];
  return {attribute(e, "x"), attribute(e, "y"), attribute(e, "width"), attribute(e, "height")};
}

std::vector<std::pair<double, double>> markers(const std::string& svg) {
  std::vector<std::pair<double, double>> out;
  const std::regex re("<circle class=\"marker\"[^>]*>");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it) {
    const std::string e = (*it)[0];
    out.emplace_back(attribute(e, "cx"), attribute(e, "cy"));
  }
  return out;
}

// Parses the document with Python's XML parser: the test fails on anything that is not well-formed XML.
bool well_formed_xml(const std::string& svg) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("pegasus_plot_" + std::to_string(::getpid()) + ".svg");
  write_file_atomic(file, svg);
  const std::string command =
      "python3 -c 'import sys, xml.dom.minidom; xml.dom.minidom.parse(sys.argv[1])' " + file.string() +
      " 2>&1";
  const int rc = std::system(command.c_str());
  std::filesystem::remove(file);
  return rc == 0;
}

void expect_markers_inside(const std::string& svg, std::size_t expected) {
  const Rect area = plot_area(svg);
  const auto points = markers(svg);
  EXPECT_EQ(points.size(), expected);
  for (auto [x, y] : points) {
    EXPECT_GE(x, area.x - 1e-9);
    EXPECT_LE(x, area.x + area.w + 1e-9);
    EXPECT_GE(y, area.y - 1e-9);
    EXPECT_LE(y, area.y + area.h + 1e-9);
  }
}

TEST(SvgPlot, LinearPlotWithBandsAndReferenceLineIsWellFormedAndInside) {
  SvgPlot plot;
  plot.title("Error <vs> m & \"more\"").x_label("m").y_label("|U - U'|");
  plot.add_series(
      {.name = "PEGASUS", .x = {1, 2, 3, 4}, .y = {0.5, -0.25, 0.125, 3}, .error = {0.1, 0.2, 0.1, 1}});
  plot.add_series({.name = "naive MC", .x = {1, 4}, .y = {-2, 7}, .markers = true});
  plot.add_reference_line(1.0, "target");
  const std::string svg = plot.render();
  EXPECT_TRUE(well_formed_xml(svg)) << svg;
  expect_markers_inside(svg, 6);
  EXPECT_NE(svg.find("Error &lt;vs&gt; m &amp; &quot;more&quot;"), std::string::npos);
  EXPECT_NE(svg.find("class=\"reference\""), std::string::npos);
  EXPECT_NE(svg.find(">naive MC<"), std::string::npos);
  EXPECT_NE(svg.find("fill-opacity=\"0.2\""), std::string::npos);  // the error band
}

TEST(SvgPlot, LogAxesPlaceEveryUsablePointInside) {
  for (AxisScale scale : {AxisScale::kLog2, AxisScale::kLog10}) {
    SvgPlot plot;
    plot.x_scale(scale).y_scale(AxisScale::kLog10).title("log");
    plot.add_series({.name = "a", .x = {1, 2, 8, 1024, 3000}, .y = {1e-3, 0.5, 10, 1e4, 2e5}});
    plot.add_series(
        {.name = "b", .x = {0, -1, 16, NAN, 32}, .y = {1, 1, 0.01, 1, -5}});  // 0, -1, NaN, -5 left out
    const std::string svg = plot.render();
    EXPECT_TRUE(well_formed_xml(svg));
    expect_markers_inside(svg, 5 + 1);
  }
}

TEST(SvgPlot, PowersOfTwoAreTickLabelsOnALog2Axis) {
  SvgPlot plot;
  plot.x_scale(AxisScale::kLog2).add_series({.name = "a", .x = {1, 64}, .y = {0, 1}});
  const std::string svg = plot.render();
  for (const char* label : {">1<", ">2<", ">4<", ">32<", ">64<"})
    EXPECT_NE(svg.find(label), std::string::npos) << label;
}

TEST(SvgPlot, DegenerateInputsStillRender) {
  SvgPlot empty;
  EXPECT_TRUE(well_formed_xml(empty.render()));
  SvgPlot flat;
  flat.add_series({.name = "one point", .x = {3}, .y = {5}});
  const std::string svg = flat.render();
  EXPECT_TRUE(well_formed_xml(svg));
  expect_markers_inside(svg, 1);
  SvgPlot zeros;
  zeros.add_series({.name = "zeros", .x = {0, 0}, .y = {0, 0}});
  expect_markers_inside(zeros.render(), 2);
}

TEST(SvgPlot, MismatchedSeriesIsALogicError) {
  SvgPlot plot;
  EXPECT_THROW(plot.add_series({.name = "bad", .x = {1, 2}, .y = {1}}), std::logic_error);
  EXPECT_THROW(plot.add_series({.name = "bad", .x = {1}, .y = {1}, .error = {1, 2}}), std::logic_error);
}

TEST(NiceTicks, AreRoundAndCoverTheRange) {
  EXPECT_EQ(nice_ticks(0, 1), (std::vector<double>{0, 0.2, 0.4, 0.6000000000000001, 0.8, 1}));
  const auto ticks = nice_ticks(-3.7, 12.2);
  EXPECT_LE(ticks.front(), -3.7);
  EXPECT_GE(ticks.back(), 12.2);
  EXPECT_EQ(ticks[1] - ticks[0], 5);
  const auto small = nice_ticks(0.00123, 0.00456);
  EXPECT_LE(small.front(), 0.00123);
  EXPECT_GE(small.back(), 0.00456);
  EXPECT_GE(small.size(), 3u);
  EXPECT_LE(small.size(), 10u);
}

}  // namespace
}  // namespace pegasus
