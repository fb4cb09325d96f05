// Flight logs in a vehicle's own layout (heli/vehicle_file.hpp): its CSV columns, reading and writing them,
// and `control --vehicle`'s line format.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/io/json_csv.hpp"

namespace pegasus::logs {

bool logs_in_pipeline_layout(const Vehicle& v) {
  const VehicleLogSpec& l = v.log;
  const auto named = [](const TopicFields& q, std::initializer_list<const char*> names) {
    return q.topic.empty() && std::equal(q.fields.begin(), q.fields.end(), names.begin(), names.end());
  };
  if (!(l.time == "time" && l.pipeline_conventions() && l.attitude_form == "euler" &&
        l.velocity_frame == "world" && l.rates_form == "euler" && named(l.position, {"x", "y", "z"}) &&
        named(l.velocity, {"xdot", "ydot", "zdot"}) && named(l.attitude, {"roll", "pitch", "yaw"}) &&
        named(l.rates, {"roll_rate", "pitch_rate", "yaw_rate"})))
    return false;
  for (std::size_t c = 0; c < 4; ++c) {
    const ControlChannel& ch = l.controls[c];
    if (!(ch.topic.empty() && ch.scale == 1 && ch.offset == 0 &&
          ch.field == sysid::kLogControlColumns[static_cast<std::size_t>(ch.column(c))]))
      return false;
  }
  return true;
}

std::vector<std::string> vehicle_log_columns(const Vehicle& vehicle) {
  const VehicleLogSpec& spec = vehicle.log;
  std::vector<std::string> header{spec.time};
  const std::vector<std::string> state = vehicle.state_fields();
  header.insert(header.end(), state.begin(), state.end());
  for (const auto& c : spec.controls) header.push_back(c.field);
  for (std::size_t i = 0; i < header.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (header[i] == header[j])
        throw InputError(
            fmt::format("{}: the column '{}' stands for two quantities (of different topics); "
                        "expected distinct field names for a CSV log",
                        spec.file, printable(header[i])));
  return header;
}

std::string vehicle_log_csv(const sysid::FlightLog& log, const Vehicle& vehicle, std::size_t every) {
  CsvWriter csv(vehicle_log_columns(vehicle));
  for (std::size_t i = 0; i < log.rows(); i += std::max<std::size_t>(every, 1)) {
    std::vector<CsvCell> row{log.time[i]};
    for (const double x : vehicle.native_state(log.states[i])) row.emplace_back(x);
    for (const double a : vehicle.native_of(log.controls[i])) row.emplace_back(a);
    csv.add_row(std::move(row));
  }
  return csv.str();
}

sysid::FlightLog parse_vehicle_log(const std::string& text, const std::string& name, const Vehicle& vehicle,
                                   const sysid::LogReadOptions& options) {
  const VehicleLogSpec& spec = vehicle.log;
  std::vector<std::string> columns{spec.time};
  const std::vector<std::string> state = vehicle.state_fields();
  columns.insert(columns.end(), state.begin(), state.end());
  for (const auto& c : spec.controls) columns.push_back(c.field);
  const sysid::CsvColumns table = sysid::read_csv_columns(text, name, columns);
  sysid::FlightLog log;
  const std::size_t first_control = 1 + state.size();
  for (std::size_t i = 0; i < table.rows.size(); ++i) {
    const std::vector<double>& row = table.rows[i];
    log.time.push_back(row[0]);
    const heli::LoggedState s = vehicle.state_of(std::span<const double>(row).subspan(1, state.size()));
    for (std::size_t j = 3; j < 6; ++j)
      if (!std::isfinite(s[j]))
        throw InputError(fmt::format("{}:{}:{}: the attitude quaternion has no direction (all zero)", name,
                                     table.lines[i], printable(spec.attitude.fields[0])));
    log.states.push_back(s);
    heli::Controls a = vehicle.axes_of(std::span<const double>(row).subspan(first_control, 4));
    for (std::size_t c = 0; c < 4; ++c) {
      const ControlChannel& ch = spec.controls[c];
      double& axis = a[static_cast<std::size_t>(ch.column(c))];
      if (!(std::abs(axis) <= 1 + 1e-6))
        throw InputError(
            fmt::format("{}:{}:{}: {} gives {} (a{}) = {}; expected [-1, 1] after the channel's range or "
                        "scale and offset "
                        "in {}",
                        name, table.lines[i], printable(ch.field), row[first_control + c],
                        kControlAxisNames[static_cast<std::size_t>(ch.column(c))], ch.column(c) + 1, axis,
                        spec.file.empty() ? std::string("the vehicle") : spec.file));
      axis = std::clamp(axis, -1.0, 1.0);
    }
    log.controls.push_back(a);
  }
  sysid::check_log_rows(log, table.lines, table.last_line, name, options, spec.time);
  const double rate = 1 / log.dt();
  if (std::abs(rate / spec.rate_hz - 1) > options.rate_tolerance)
    throw InputError(fmt::format("{}: rows come at {:.6g} Hz; expected log.rate_hz = {} Hz of {}", name, rate,
                                 spec.rate_hz, spec.file.empty() ? std::string("the vehicle") : spec.file));
  return log;
}

sysid::FlightLog read_vehicle_log(const std::filesystem::path& file, const Vehicle& vehicle,
                                  const sysid::LogReadOptions& options) {
  return parse_vehicle_log(sysid::read_log_text(file), file.string(), vehicle, options);
}

heli::ControlLineFormat control_line_format(const Vehicle& vehicle) {
  heli::ControlLineFormat f;
  f.control_names.clear();
  for (const auto& c : vehicle.log.controls) {
    f.control_names.push_back(c.label());
    f.control_columns.push_back(c.field);  // a log row's own column, where the answer names it otherwise
  }
  f.controls_of = [vehicle](const heli::Controls& a) { return vehicle.native_of(a); };
  // A vehicle logged in the pipeline's own layout (the X-Cell's file) is read as `heli control` reads it: a
  // line without a header in the order of its own log (x..yaw_rate), not position, velocity, attitude, rates.
  if (logs_in_pipeline_layout(vehicle)) return f;
  f.time_field = vehicle.log.time;
  f.state_fields = vehicle.state_fields();
  f.state_of = [vehicle](std::span<const double> v) { return vehicle.state_of(v); };
  return f;
}

}  // namespace pegasus::logs
