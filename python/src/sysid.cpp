// Flight logs, system identification and open-loop prediction of thesis §5.2 (sysid/): a model identified
// from a CSV path or from numpy arrays with column names, saved and loaded as `pegasus heli identify` does.
#include <fmt/format.h>

#include <map>
#include <sstream>
#include <string>
#include <utility>

#include "common.hpp"
#include "pegasus/core/number_setting.hpp"
#include "pegasus/core/or_list.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus::python {

namespace {

using sysid::FlightLog;
using sysid::IdentifiedModel;

ThreadPool checked_pool(std::int64_t threads) {
  if (threads < 1 || threads > 1024)
    throw py::value_error(fmt::format("threads: expected an integer in [1, 1024], got {}", threads));
  return ThreadPool(static_cast<int>(threads));
}

sysid::LogReadOptions read_options(std::int64_t min_rows) {
  if (min_rows < 2)
    throw py::value_error(fmt::format("min_rows: expected an integer >= 2, got {}", min_rows));
  sysid::LogReadOptions o;
  o.min_rows = static_cast<int>(min_rows);
  return o;
}

// A log from numpy data [rows, columns] and the columns' names, through the CSV reader's checks.
FlightLog log_from_arrays(ArrayLikeArg data, const std::vector<std::string>& columns, std::int64_t min_rows) {
  const Array a = as_matrix(data, "data", -1, static_cast<py::ssize_t>(columns.size()));
  std::ostringstream text;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    if (columns[c].find_first_of(",\n\"") != std::string::npos)
      throw py::value_error(
          fmt::format("columns[{}]: expected a name without commas, quotes or newlines", c));
    text << (c ? "," : "") << columns[c];
  }
  text << '\n';
  for (py::ssize_t r = 0; r < a.shape(0); ++r) {
    for (py::ssize_t c = 0; c < a.shape(1); ++c)
      text << (c ? "," : "") << fmt::format("{}", a.data()[r * a.shape(1) + c]);
    text << '\n';
  }
  return sysid::parse_flight_log(text.str(), "data", read_options(min_rows));
}

}  // namespace

void bind_sysid(py::module_& m) {
  py::class_<FlightLog>(m, "FlightLog", R"doc(
A helicopter flight log (thesis §5.2): time, the 12 world-frame states (x, y, z, roll, pitch, yaw, xdot, ydot,
zdot, roll_rate, pitch_rate, yaw_rate) and the controls a1..a4. From read_flight_log(path) or
flight_log(data, columns).)doc")
      .def_property_readonly("rows", &FlightLog::rows, "Number of samples (rows) in the log.")
      .def_property_readonly("dt", &FlightLog::dt, "Mean sample interval, s.")
      .def_property_readonly(
          "time", [](const FlightLog& log) { return vector_array(log.time); }, "Sample times [rows], s.")
      .def_property_readonly(
          "states",
          [](const FlightLog& log) {
            Array out = matrix(static_cast<py::ssize_t>(log.rows()), sysid::kLogStates);
            for (std::size_t r = 0; r < log.rows(); ++r)
              std::copy(log.states[r].begin(), log.states[r].end(),
                        out.mutable_data() + r * sysid::kLogStates);
            return out;
          },
          "The 12 logged states [rows, 12]: x, y, z (world NED, m), roll, pitch, yaw (rad), xdot, ydot, zdot "
          "(in W, m/s), roll_rate, pitch_rate, yaw_rate (Euler-angle rates, rad/s).")
      .def_property_readonly(
          "controls",
          [](const FlightLog& log) {
            Array out = matrix(static_cast<py::ssize_t>(log.rows()), 4);
            for (std::size_t r = 0; r < log.rows(); ++r)
              std::copy(log.controls[r].begin(), log.controls[r].end(), out.mutable_data() + r * 4);
            return out;
          },
          "The controls [rows, 4]: a1, a2 (longitudinal, lateral cyclic), a3 (main collective), a4 (tail "
          "collective).");
  m.def(
      "read_flight_log",
      [](const std::string& path, std::int64_t min_rows, const std::string& vehicle) {
        if (vehicle.empty()) return sysid::read_flight_log(path, read_options(min_rows));
        return logs::read_vehicle_log(path, logs::read_vehicle(vehicle), read_options(min_rows));
      },
      py::arg("path"), py::arg("min_rows") = 100, py::arg("vehicle") = "",
      "Reads and checks a CSV flight log (README's format, or the layout the vehicle file `vehicle` "
      "describes, turned into the pipeline's); ValueError 'FILE:LINE:COLUMN: what was expected'.");
  m.def("flight_log", &log_from_arrays, py::arg("data"), py::arg("columns"), py::arg("min_rows") = 100,
        "A flight log from numpy data [rows, columns] with the columns' names (time, x, ..., a4; others "
        "ignored).");

  py::class_<IdentifiedModel, std::shared_ptr<IdentifiedModel>>(m, "IdentifiedModel", R"doc(
An identified helicopter model (thesis §5.2): locally weighted (or global linear) regression of the body
variables' changes, its bandwidth and noise. Save it as the model.json `pegasus heli hover` loads.)doc")
      .def_property_readonly(
          "dt", &IdentifiedModel::dt,
          "The model step, s: log rows per step times the log's mean interval (about 1 / rate_hz: "
          "0.1 at the default 10 Hz).")
      .def_property_readonly("is_global", &IdentifiedModel::is_global,
                             "True: one global linear fit (no input has a kernel bandwidth); False: locally "
                             "weighted regression.")
      .def_property_readonly(
          "sigma2",
          [](const IdentifiedModel& model) {
            return vector_array(std::span<const double>(model.sigma2().data(), sysid::kBodyVars));
          },
          "Noise variance of each body variable's change per model step (roll, pitch, xdot_b, ydot_b, "
          "zdot_b, roll_rate, pitch_rate, yaw_rate; squared units); Eq 5.4 scales it by 1 + leverage.")
      .def_property_readonly(
          "horizon_sd_factors",
          [](const IdentifiedModel& model) {
            const auto& factors = model.horizon_sd_factors();
            Array out = matrix(static_cast<py::ssize_t>(factors.size()), sysid::kBodyVars);
            for (std::size_t t = 0; t < factors.size(); ++t)
              std::copy(factors[t].data(), factors[t].data() + sysid::kBodyVars,
                        out.mutable_data() + t * sysid::kBodyVars);
            return out;
          },
          "The calibration's factor on each body variable's band sd at each model step after a reset "
          "[steps, 8] (calibrate_noise with horizon_sd_factors; 0 rows: none, every factor 1).")
      .def_property_readonly(
          "inv_bandwidth", [](const IdentifiedModel& model) { return vector_array(model.inv_bandwidth()); },
          "1 / the kernel bandwidth of each of the 16 regression inputs (roll .. a4, one), per unit of the "
          "input; 0: the kernel ignores the input (the constant's entry is unused).")
      .def(
          "to_json", [](const IdentifiedModel& model) { return JsonObject(to_python(model.to_json())); },
          "The model file's contents (model.json) as a dict.")
      .def(
          "save", [](const IdentifiedModel& model, const std::string& path) { model.save(path); },
          py::arg("path"), "Writes model.json to path atomically.")
      .def_static(
          "load",
          [](const std::string& path) {
            return std::make_shared<IdentifiedModel>(IdentifiedModel::load(path));
          },
          py::arg("path"));

  static const sysid::IdentifyOptions kIdentifyDefaults{};
  // The bounds the calls check, written into their docstrings from the same settings (as the CLI's --help).
  // The floors' keys (BandwidthFloor::VisitFields), for a refusal, and each with its own bounds, for the doc.
  static const std::vector<std::string> kFloorKeys = [] {
    std::vector<std::string> keys;
    for (const NumberSetting& n : sysid::BandwidthFloor::settings()) keys.emplace_back(n.key);
    return keys;
  }();
  static const std::string kFloorBounds = [] {
    std::string out;
    for (const NumberSetting& n : sysid::BandwidthFloor::settings())
      out += fmt::format("{}{} in {}", out.empty() ? "keys " : ", ", n.key, n.range_in_unit());
    return out;
  }();
  auto report_bounds = [](std::initializer_list<const char*> keys) {
    std::string out;
    for (const char* key : keys)
      out += fmt::format("{}{} in {}", out.empty() ? "" : ", ", key,
                         number_setting<heli::IdentifyRunOptions>(key).range_in_unit());
    return " Bounds (identify's): " + out + ".";
  };
  static const std::string kIdentifyDoc =
      "Identifies a model from a training log as `pegasus heli identify` does (same options, same bits, any "
      "threads). rate_hz in " +
      number_setting<sysid::ModelStructure>("rate_hz").range_in_unit() +
      " (the CLI's). bandwidth_floor overrides the narrowest bandwidths (" + kFloorBounds +
      "; the defaults are the CLI's); noise is \"white\", \"ar1\" or \"ar1+measurement\" (the CLI's "
      "--noise).";
  m.def(
      "identify",
      [](const FlightLog& log, double rate_hz, bool local, bool extra_states, bool intercept, bool templates,
         double window_s, std::int64_t cv_points, std::vector<double> scale_grid,
         std::int64_t coordinate_passes, const std::map<std::string, double>& bandwidth_floor,
         const std::string& noise, bool calibrate_noise, bool horizon_sd_factors,
         double calibration_leave_out_s, double calibration_spacing_s, std::int64_t threads) {
        sysid::IdentifyOptions o;
        o.noise = sysid::parse_noise_model(noise);  // InputError: a ValueError (module.cpp)
        o.calibrate_noise = calibrate_noise;
        o.horizon_sd_factors = horizon_sd_factors;
        o.calibration_leave_out_s = calibration_leave_out_s;
        o.calibration_spacing_s = calibration_spacing_s;
        for (const auto& [key, value] : bandwidth_floor) {
          if (!set_number(o.min_bandwidth, key, value))  // BandwidthFloor::VisitFields
            throw py::value_error(
                fmt::format("bandwidth_floor: unknown key '{}'; expected {}", key, or_list(kFloorKeys)));
        }
        o.structure.rate_hz = rate_hz;
        o.structure.extra_states = extra_states;
        o.structure.intercept = intercept;
        o.structure.templates = templates;
        o.local = local;
        o.window_s = window_s;
        o.cv_points = static_cast<int>(std::clamp<std::int64_t>(cv_points, -1, 1 << 30));
        o.scale_grid = std::move(scale_grid);
        o.coordinate_passes = static_cast<int>(std::clamp<std::int64_t>(coordinate_passes, -1, 1 << 30));
        std::string error;
        if (!o.IsValid(&error)) throw py::value_error(error);
        ThreadPool pool = checked_pool(threads);
        ReleaseGilInterruptibly release;
        return std::make_shared<IdentifiedModel>(sysid::identify(log, o, pool));
      },
      // Every default is IdentifyOptions's, as the CLI's (less the CLI's choices from the data: noise).
      py::arg("log"), py::kw_only(), py::arg("rate_hz") = kIdentifyDefaults.structure.rate_hz,
      py::arg("local") = kIdentifyDefaults.local,
      py::arg("extra_states") = kIdentifyDefaults.structure.extra_states,
      py::arg("intercept") = kIdentifyDefaults.structure.intercept,
      py::arg("templates") = kIdentifyDefaults.structure.templates,
      py::arg("window_s") = kIdentifyDefaults.window_s, py::arg("cv_points") = kIdentifyDefaults.cv_points,
      py::arg("scale_grid") = kIdentifyDefaults.scale_grid,
      py::arg("coordinate_passes") = kIdentifyDefaults.coordinate_passes,
      py::arg("bandwidth_floor") = std::map<std::string, double>{},
      py::arg("noise") = sysid::to_string(kIdentifyDefaults.noise),
      py::arg("calibrate_noise") = kIdentifyDefaults.calibrate_noise,
      py::arg("horizon_sd_factors") = kIdentifyDefaults.horizon_sd_factors,
      py::arg("calibration_leave_out_s") = kIdentifyDefaults.calibration_leave_out_s,
      py::arg("calibration_spacing_s") = kIdentifyDefaults.calibration_spacing_s, py::arg("threads") = 1,
      kIdentifyDoc.c_str());

  // Fig 5.2's errors of a HorizonMse as a dict: seconds, mse [T, 15], count, names.
  auto horizon_dict = [](const sysid::HorizonMse& h) {
    Array mse = matrix(static_cast<py::ssize_t>(h.mse.size()), sysid::kReportVars);
    for (std::size_t t = 0; t < h.mse.size(); ++t)
      std::copy(h.mse[t].begin(), h.mse[t].end(), mse.mutable_data() + t * sysid::kReportVars);
    std::vector<std::string> names(sysid::kReportVarNames.begin(), sysid::kReportVarNames.end());
    py::dict out;
    out["seconds"] = vector_array(h.seconds);
    out["mse"] = mse;
    out["count"] = h.count;
    out["names"] = names;
    return out;
  };
  // The bounds and defaults of identify's report options (IdentifyRunOptions::VisitFields), as the CLI's.
  static const heli::IdentifyRunOptions kReportDefaults{};
  auto check_number = [](const char* key, double x) {
    const NumberSetting& n = number_setting<heli::IdentifyRunOptions>(key);
    if (!n.within(x)) throw py::value_error(n.refusal(n.key, "a number", x));
  };
  auto check_horizon = [check_number](double horizon_s, double start_spacing_s) {
    check_number("horizon_s", horizon_s);
    check_number("start_spacing_s", start_spacing_s);
  };
  static const std::string kHorizonDoc =
      "Open-loop prediction error against horizon on a test log (thesis Fig 5.2): seconds, mse [T, 15], "
      "count, names." +
      report_bounds({"horizon_s", "start_spacing_s"});
  m.def(
      "horizon_mse",
      [horizon_dict, check_horizon](const IdentifiedModel& model, const FlightLog& test, double horizon_s,
                                    double start_spacing_s, std::int64_t threads) {
        check_horizon(horizon_s, start_spacing_s);
        ThreadPool pool = checked_pool(threads);
        sysid::HorizonMse h;
        {
          ReleaseGilInterruptibly release;
          h = sysid::horizon_mse(model, test, horizon_s, start_spacing_s, pool);
        }
        return horizon_dict(h);
      },
      py::arg("model"), py::arg("test"), py::kw_only(), py::arg("horizon_s") = kReportDefaults.horizon_s,
      py::arg("start_spacing_s") = kReportDefaults.start_spacing_s, py::arg("threads") = 1,
      kHorizonDoc.c_str());
  static const std::string kAsTrainedDoc =
      "horizon_mse as hover training runs the model: the learned model at control_rate_hz, noise off "
      "(`heli identify`'s mse_at_seconds_as_trained)." +
      report_bounds({"control_rate_hz", "horizon_s", "start_spacing_s"});
  m.def(
      "horizon_mse_as_trained",
      [horizon_dict, check_horizon, check_number](const IdentifiedModel& model, const FlightLog& test,
                                                  double control_rate_hz, double horizon_s,
                                                  double start_spacing_s, std::int64_t threads) {
        check_horizon(horizon_s, start_spacing_s);
        check_number("control_rate_hz", control_rate_hz);
        ThreadPool pool = checked_pool(threads);
        sysid::HorizonMse h;
        {
          ReleaseGilInterruptibly release;
          h = sysid::horizon_mse_as_trained(model, test, control_rate_hz, horizon_s, start_spacing_s, pool);
        }
        return horizon_dict(h);
      },
      py::arg("model"), py::arg("test"), py::kw_only(),
      py::arg("control_rate_hz") = kReportDefaults.control_rate_hz,
      py::arg("horizon_s") = kReportDefaults.horizon_s,
      py::arg("start_spacing_s") = kReportDefaults.start_spacing_s, py::arg("threads") = 1,
      kAsTrainedDoc.c_str());
  static const std::string kNoiseCheckDoc =
      "Fig 5.3's check on a test log (or on several, their steps pooled: `heli identify "
      "--noise-check-logs`), reset to the logged state every reset_s: seconds [H] since a reset, "
      "outside [H, 8] (each body variable's share of the steps outside +-2 sd; `heli identify`'s "
      "noise_check_by_horizon.csv), steps [H], outside_fraction [8] over all steps, names. Honest bands miss "
      "3-7% at every horizon." +
      report_bounds({"reset_s"});
  m.def(
      "noise_check",
      [check_number](const IdentifiedModel& model, const FlightLogsArg& test, double reset_s,
                     std::int64_t threads) {
        check_number("reset_s", reset_s);
        // One log, or several whose steps are pooled (sysid::pooled_noise_check).
        std::vector<const FlightLog*> logs;
        std::vector<py::object> held;  // a sequence's items alive while the GIL is released
        if (py::isinstance<FlightLog>(test)) {
          logs.push_back(&test.cast<const FlightLog&>());
        } else if (py::isinstance<py::sequence>(test) && !py::isinstance<py::str>(test)) {
          const auto items = test.cast<py::sequence>();
          for (std::size_t i = 0; i < items.size(); ++i) {
            py::object item = items[i];  // owned: a sequence may make its items when asked
            if (!py::isinstance<FlightLog>(item))
              throw py::type_error("test: expected a FlightLog or a sequence of FlightLog");
            logs.push_back(&item.cast<const FlightLog&>());
            held.push_back(std::move(item));
          }
          if (logs.empty()) throw py::value_error("test: expected at least one FlightLog");
        } else {
          throw py::type_error("test: expected a FlightLog or a sequence of FlightLog");
        }
        ThreadPool pool = checked_pool(threads);
        sysid::NoiseCheck check;
        {
          ReleaseGilInterruptibly release;
          std::vector<sysid::NoiseCheck> checks;
          for (const FlightLog* log : logs)
            checks.push_back(sysid::noise_check(model, *log, reset_s, 0.0, pool));
          check = sysid::pooled_noise_check(checks);  // one log's: its own check
        }
        // Every horizon with steps counted, as noise_check_by_horizon.csv has them.
        const std::vector<sysid::BandMisses> cells =
            sysid::band_misses_at_every_step(check, model.structure().rate_hz);
        const auto horizons = static_cast<py::ssize_t>(cells.size()) / sysid::kBodyVars;
        std::vector<double> seconds;
        std::vector<std::int64_t> steps;
        Array outside = matrix(horizons, sysid::kBodyVars);
        for (std::size_t i = 0; i < cells.size(); ++i) {
          outside.mutable_data()[i] = cells[i].outside;  // horizon-major, every variable in order
          if (cells[i].variable == 0) {
            seconds.push_back(cells[i].seconds);
            steps.push_back(cells[i].steps);
          }
        }
        const std::vector<double> overall(check.outside_fraction.data(),
                                          check.outside_fraction.data() + sysid::kBodyVars);
        py::dict out;
        out["seconds"] = vector_array(seconds);
        out["outside"] = outside;
        out["steps"] = steps;
        out["outside_fraction"] = vector_array(overall);
        out["names"] = std::vector<std::string>(sysid::kBodyVarNames.begin(), sysid::kBodyVarNames.end());
        return out;
      },
      py::arg("model"), py::arg("test"), py::kw_only(), py::arg("reset_s") = kReportDefaults.reset_s,
      py::arg("threads") = 1, kNoiseCheckDoc.c_str());
  m.def(
      "closed_loop_bias",
      [](const IdentifiedModel& model) {
        py::list out;
        for (const auto& b : sysid::closed_loop_bias(model.data(), model.regression().templates(),
                                                     model.noise_correlation())) {
          py::dict d;
          d["output"] = b.output;
          d["control"] = b.control;
          d["least_squares"] = b.least_squares;
          d["whitened"] = b.whitened;
          d["relative"] = b.relative;
          d["effect_share"] = b.effect_share;
          out.append(d);
        }
        return out;
      },
      py::arg("model"),
      "The control gains of least squares against a fit that whitens the model's AR(1) noise (empty for a "
      "white-noise model): `heli identify --noise ar1`'s closed_loop_bias.");
}

}  // namespace pegasus::python
