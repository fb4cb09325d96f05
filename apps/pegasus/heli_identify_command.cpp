// `pegasus heli identify` and `pegasus identify --vehicle`: system identification by locally weighted
// regression from flight logs (thesis §5.2), with the model-selection study of Fig 5.2, the noise check of
// Fig 5.3, the model as hover training will run it, and the closed-loop bias check; and the bandwidth floors
// every identifying command declares.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "experiment_commands.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/logs/vehicle.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/flight_charts.hpp"
#include "pegasus/runs/progress.hpp"
#include "pegasus/sysid/flight_log.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/sysid/model_selection.hpp"

namespace pegasus::cli {

using namespace pegasus::heli;
using namespace pegasus::sysid;

void declare_bandwidth_floor(ConfigSchema& s) {
  const BandwidthFloor d;
  s.add_double("bandwidth_floor.angle_rad", d.angle_rad, "narrowest kernel bandwidth of roll and pitch, rad")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.velocity_mps", d.velocity_mps,
               "narrowest kernel bandwidth of the body velocities, m/s")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.rate_radps", d.rate_radps,
               "narrowest kernel bandwidth of the body rates (and the gyro state), rad/s")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.flap_rad", d.flap_rad,
               "narrowest kernel bandwidth of the flapping states, rad")
      .range(0, 1e6);
  s.add_double("bandwidth_floor.control", d.control,
               "narrowest kernel bandwidth of each control, in its [-1, 1] units (a control the pilot barely "
               "moved is not given a bandwidth below this)")
      .range(0, 1e6);
}

BandwidthFloor read_bandwidth_floor(const ConfigSchema& c) {
  return {.angle_rad = c.get_double("bandwidth_floor.angle_rad"),
          .velocity_mps = c.get_double("bandwidth_floor.velocity_mps"),
          .rate_radps = c.get_double("bandwidth_floor.rate_radps"),
          .flap_rad = c.get_double("bandwidth_floor.flap_rad"),
          .control = c.get_double("bandwidth_floor.control")};
}

void declare_identify(ConfigSchema& s) {
  const IdentifyRunOptions d;
  const IdentifyOptions& id = d.identify;
  declare_vehicle(s, "[log] model_rate_hz, [vehicle] latent_states, [model] templates and [control] rate_hz");
  s.add_string("train", "", "training flight log (CSV in the vehicle's layout, see README)").input_file();
  s.add_string("test", "", "hold-out flight log (CSV)").input_file();
  s.add_double("rate_hz", id.structure.rate_hz, "identification rate, Hz (the log is downsampled)")
      .range(1, 50);
  s.add_bool("local", id.local, "locally weighted regression (false: globally linear)");
  s.add_bool("extra_states", id.structure.extra_states,
             "use the flapping and yaw-gyro states of the published model");
  s.add_bool("intercept", id.structure.intercept, "regress on a constant");
  s.add_bool("templates", id.structure.templates, "fix kinematic and gravity coefficients (thesis 5.2.2)");
  s.add_double("window_s", id.window_s,
               "cross-validation leaves out this window around each held-out point, s")
      .range(0, 1000);
  s.add_int("cv_points", id.cv_points, "held-out points per cross-validation evaluation").range(10, 100000);
  s.add_double_list("scale_grid", id.scale_grid, "bandwidths tried, in input standard deviations")
      .min(1e-6)
      .min_size(1);
  s.add_int("coordinate_passes", id.coordinate_passes, "passes of per-input bandwidth refinement")
      .range(0, 10);
  declare_bandwidth_floor(s);
  s.add_string(
       "noise", to_string(id.noise),
       "the model's noise: white per model step (Eqs 5.5-5.6) or ar1 (each output's noise a white part "
       "plus a first-order autoregressive part fitted to the residuals' autocorrelation up to 2 s) or "
       "ar1+measurement (ar1 plus an error of the logged states themselves, which the model does not fly)")
      .choices({"white", "ar1", "ar1+measurement"});
  s.add_bool(
      "calibrate_noise", id.calibrate_noise,
      "scale each output's noise, the part the model flies and (ar1+measurement) the log's own error apart, "
      "so that the training log's own noise check (each window predicted without its data) has about 4.55% "
      "of its steps outside +-2 sd in each of three spans of the reset window (to 1/4, 1/2 and all of it)");
  s.add_double("horizon_s", d.horizon_s, "longest prediction horizon of the report, s").range(0.1, 100);
  s.add_double("start_spacing_s", d.start_spacing_s,
               "spacing of the open-loop prediction starts on the test log, s")
      .range(0.02, 1000);
  s.add_double("reset_s", d.reset_s, "the noise check's EKF is reset to the true state this often, s")
      .range(0.1, 100);
  s.add_bool("variants", d.variants, "also report the model-selection variants of Fig 5.2");
  s.add_double("control_rate_hz", d.control_rate_hz,
               "the rate hover training will step the model at (heli hover --control-rate-hz): the chosen "
               "model's errors are also reported as training runs it")
      .greater_than(0)
      .max(1000);
}

void resolve_identify(ConfigSchema& s) {
  if (s.get_string("vehicle").empty()) return;
  const logs::Vehicle v = logs::read_vehicle(s.get_string("vehicle"));
  from_vehicle(s, v, "rate_hz", v.log.model_rate_hz, "log.model_rate_hz");
  from_vehicle(s, v, "extra_states", v.xcell_latent_states, "vehicle.latent_states");
  from_vehicle(s, v, "templates", v.kinematic_templates, "model.templates");
  from_vehicle(s, v, "control_rate_hz", v.control_rate_hz, "control.rate_hz");
}

void run_identify(RunContext& ctx) {
  const auto& c = ctx.config;
  IdentifyRunOptions o;
  o.aircraft = aircraft_of(c);
  o.train_log = c.get_string("train");
  o.test_log = c.get_string("test");
  o.horizon_s = c.get_double("horizon_s");
  o.start_spacing_s = c.get_double("start_spacing_s");
  o.reset_s = c.get_double("reset_s");
  o.variants = c.get_bool("variants");
  o.control_rate_hz = c.get_double("control_rate_hz");
  IdentifyOptions& id = o.identify;
  id.structure.rate_hz = c.get_double("rate_hz");
  id.structure.extra_states = c.get_bool("extra_states");
  id.structure.intercept = c.get_bool("intercept");
  id.structure.templates = c.get_bool("templates");
  id.local = c.get_bool("local");
  id.window_s = c.get_double("window_s");
  id.cv_points = static_cast<int>(c.get_int("cv_points"));
  id.scale_grid = c.get_double_list("scale_grid");
  id.coordinate_passes = static_cast<int>(c.get_int("coordinate_passes"));
  id.min_bandwidth = read_bandwidth_floor(c);
  id.noise = parse_noise_model(c.get_string("noise"));
  id.calibrate_noise = c.get_bool("calibrate_noise");
  RunSink sink = ctx.sink();
  heli::run_identify(o, sink, ctx.pool());
}

}  // namespace pegasus::cli
