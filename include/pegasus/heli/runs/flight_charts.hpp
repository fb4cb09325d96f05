#pragma once
// The charts of aircraft flights, written by every command that flies (heli hover/fly, maneuver, pilot,
// log): the series are tables of flights with a time column and the logged state by name (state.hpp:
// x, y, z, roll, pitch, yaw, xdot, ydot, zdot, ...; NED metres, radians), grouped by a `flight` column when
// a file holds several flights.
#include <string>
#include <utility>
#include <vector>

#include "pegasus/heli/flights.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/runs/charts.hpp"

namespace pegasus {

// flights.csv, the table of flights every flying command writes: flight, t, the logged state by name, a1..a4,
// target_x, target_y, target_z, target_yaw, and the body-frame velocities xdot_b, ydot_b, zdot_b (Fig 5.6).
class FlightsCsv {
 public:
  FlightsCsv();
  void add(std::int64_t flight, const heli::FlightRow& row);
  const CsvWriter& csv() const { return csv_; }

 private:
  CsvWriter csv_;
};

// One table of flights and how to draw it.
struct FlightSeries {
  std::string file{};   // CSV in the run directory
  std::string label{};  // "policy flight", "pilot flight", "true state", ...
  std::string time = "t";
  bool grouped = true;           // a `flight` column numbers the flights
  bool body_velocities = false;  // the file has xdot_b, ydot_b, zdot_b (body-frame velocities)
};

// Body-frame velocities (when every file has them, else world velocities) and world positions of the first
// flight of each file against time: the first file solid blue, the others dashed red (Figs 5.6-5.7).
ChartSection flight_traces_section(const std::vector<FlightSeries>& files, std::string id, std::string title,
                                   std::string intro);
// The 3-D replay of every flight of the files (the first `max_flights` of each when not 0), against the
// ideal path when `ideal_path` names its file (columns t, x, y, z).
Chart flight_replay_chart(const std::vector<FlightSeries>& files, const std::string& ideal_path = "",
                          std::size_t max_flights = 0);

// The charts of a flight log (`log_file`: a `time` column, the logged state and the `controls` by name) with
// the true state beside it when `truth_file` names its file: flight traces (the last chart: world position
// against time), the controls, and the 3-D replay.
std::vector<ChartSection> flight_log_sections(const std::string& log_file, const std::string& truth_file,
                                              const std::vector<std::string>& controls);

// Identification error against horizon (Fig 5.2): one chart per variable of `file` (columns model, seconds,
// variable, mse), one trace per model.
ChartSection mse_vs_horizon_section(const std::string& file, const std::vector<std::string>& variables);

}  // namespace pegasus
