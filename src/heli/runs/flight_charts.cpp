#include "pegasus/heli/runs/flight_charts.hpp"

#include <algorithm>

#include "pegasus/vehicle/frames.hpp"
#include "pegasus/vehicle/state.hpp"

namespace pegasus {

namespace {

std::vector<std::string> flights_header() {
  std::vector<std::string> header = {"flight", "t"};
  for (const char* n : heli::kLoggedStateNames) header.emplace_back(n);
  for (const char* n : {"a1", "a2", "a3", "a4", "target_x", "target_y", "target_z", "target_yaw", "xdot_b",
                        "ydot_b", "zdot_b"})
    header.emplace_back(n);
  return header;
}

}  // namespace

FlightsCsv::FlightsCsv() : csv_(flights_header()) {}

void FlightsCsv::add(std::int64_t flight, const heli::FlightRow& row) {
  std::vector<CsvCell> cells = {flight, row.time};
  cells.reserve(csv_.header().size());
  for (double v : row.truth) cells.emplace_back(v);
  for (double v : row.controls) cells.emplace_back(v);
  for (double v : {row.target.x, row.target.y, row.target.z, row.target.yaw}) cells.emplace_back(v);
  const heli::Vec3 v_B = heli::body_from_world(heli::attitude_of(row.truth), heli::velocity_of(row.truth));
  for (double v : {v_B[0], v_B[1], v_B[2]}) cells.emplace_back(v);
  csv_.add_row(std::move(cells));
}

namespace {

constexpr const char* kFirstColor = "#1f77b4";
constexpr const char* kOtherColor = "#d62728";

ChartTrace flight_trace(const FlightSeries& f, std::size_t index, const std::string& y, double factor) {
  return {.file = f.file,
          .x = f.time,
          .y = y,
          .group_by = f.grouped ? std::vector<std::string>{"flight"} : std::vector<std::string>{},
          .name = f.label,
          .y_factor = factor,
          .max_groups = 1,
          .dash = index == 0 ? "" : "dash",
          .color = index == 0 ? kFirstColor : kOtherColor};
}

}  // namespace

ChartSection flight_traces_section(const std::vector<FlightSeries>& files, std::string id, std::string title,
                                   std::string intro) {
  struct Quantity {
    const char* title;
    const char* y_title;
    const char* column;
    double factor;
  };
  const bool body =
      std::all_of(files.begin(), files.end(), [](const FlightSeries& f) { return f.body_velocities; });
  std::vector<Quantity> quantities;
  if (body) {
    quantities = {{"Body velocity xdot_b (forward)", "xdot_b (m/s)", "xdot_b", 1.0},
                  {"Body velocity ydot_b (right)", "ydot_b (m/s)", "ydot_b", 1.0},
                  {"Body velocity zdot_b (down)", "zdot_b (m/s)", "zdot_b", 1.0}};
  } else {
    quantities = {{"Velocity xdot (north)", "xdot (m/s)", "xdot", 1.0},
                  {"Velocity ydot (east)", "ydot (m/s)", "ydot", 1.0},
                  {"Velocity zdot (down)", "zdot (m/s)", "zdot", 1.0}};
  }
  quantities.push_back({"Position x (north)", "x (m)", "x", 1.0});
  quantities.push_back({"Position y (east)", "y (m)", "y", 1.0});
  quantities.push_back({"Altitude -z", "altitude -z (m)", "z", -1.0});
  ChartSection section{.id = std::move(id), .title = std::move(title), .intro = std::move(intro)};
  for (const auto& q : quantities) {
    Chart chart{.title = q.title, .x = {"time (s)"}, .y = {q.y_title}, .size = "small"};
    for (std::size_t i = 0; i < files.size(); ++i)
      chart.traces.push_back(flight_trace(files[i], i, q.column, q.factor));
    section.charts.push_back(std::move(chart));
  }
  return section;
}

Chart flight_replay_chart(const std::vector<FlightSeries>& files, const std::string& ideal_path,
                          std::size_t max_flights) {
  Chart chart{.kind = ChartKind::kReplay, .title = "3-D replay", .size = "wide", .path = ideal_path};
  for (const auto& f : files) {
    chart.traces.push_back(
        {.file = f.file,
         .x = f.time,
         .group_by = f.grouped ? std::vector<std::string>{"flight"} : std::vector<std::string>{},
         .name = f.label,
         .max_groups = max_flights});
  }
  return chart;
}

std::vector<ChartSection> flight_log_sections(const std::string& log_file, const std::string& truth_file,
                                              const std::vector<std::string>& controls) {
  std::vector<FlightSeries> files = {
      {.file = log_file, .label = "logged estimate", .time = "time", .grouped = false}};
  if (!truth_file.empty())
    files.insert(files.begin(),
                 {.file = truth_file, .label = "true state", .time = "time", .grouped = false});
  ChartSection flight = flight_traces_section(
      files, "flight", "Flight",
      truth_file.empty() ? "The logged flight (state estimate)."
                         : "True state (blue) and the logged state estimate (red, dashed).");
  Chart position{.title = "Position (world, NED)", .x = {"time (s)"}, .y = {"m"}};
  for (const char* v : {"x", "y", "z"})
    position.traces.push_back({.file = files.front().file, .x = "time", .y = v, .name = v});
  flight.charts.push_back(std::move(position));
  Chart controls_chart{.title = "Controls", .x = {"time (s)"}, .y = {"control"}, .size = "wide"};
  for (const auto& a : controls)
    controls_chart.traces.push_back({.file = log_file, .x = "time", .y = a, .name = a, .width = 1});
  return {
      std::move(flight),
      {.id = "controls", .title = "Controls", .intro = "The controls as logged.", .charts = {controls_chart}},
      {.id = "replay",
       .title = "3-D replay",
       .intro = "Drag to turn the view, scroll to zoom; Play runs the flight in real time, the slider moves "
                "through it.",
       .charts = {flight_replay_chart(files)}}};
}

ChartSection mse_vs_horizon_section(const std::string& file, const std::vector<std::string>& variables) {
  ChartSection section{
      .id = "identification",
      .title = "Identification error against horizon (Fig 5.2)",
      .intro =
          "Mean-squared error on the hold-out flight between each state variable and the model's open-loop "
          "prediction from a perfect initial state, against the prediction horizon (" +
          file + ")."};
  for (const auto& v : variables) {
    section.charts.push_back(
        {.title = "Hold-out MSE of " + v + " against prediction horizon",
         .x = {"prediction horizon (s)"},
         .y = {"mean-squared error"},
         .traces =
             {{.file = file, .x = "seconds", .y = "mse", .group_by = {"model"}, .where = {{"variable", v}}}},
         .size = "small"});
  }
  return section;
}

}  // namespace pegasus
