#pragma once
// The helicopter experiments of thesis chapter 5 for any aircraft a vehicle file describes, each a function
// of typed options that writes a run directory through a RunSink (the `pegasus pilot`, `identify`, `hover`
// and `fly` commands, and their `heli` aliases, read their config sections (heli/runs/heli_config.hpp) into
// these options and call them):
//   run_pilot     the ground truth flown by its scripted pilot (hover, then frequency sweeps), logged;
//   run_identify  system identification by locally weighted regression (§5.2), with the model-selection
//                 study of Fig 5.2, the noise check of Fig 5.3, the model as hover training runs it and the
//                 closed-loop bias check;
//   run_hover     PEGASUS hover training on the identified model (§5.3): policy.json;
//   run_fly       flights of a policy file (or the pilot) on the ground truth with gusts (Figs 5.6-5.7).
// Each writes summary.json (a function of the options alone), CSV series, chart specifications and SVGs,
// and the vehicle file's bytes when there is one; bad input throws InputError naming the file or field.
// Also here: write_pipeline_summary (the pipeline's summary from its stages') and run_control (`control`:
// a policy served line by line).
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "pegasus/core/number_setting.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/heli/training_wind.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/run_sink.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::heli {

// The aircraft a run is for: a vehicle file, or (no file) the X-Cell 60 in the project's own log layout,
// whose outputs then name no vehicle, as they always did.
struct VehicleChoice {
  std::string file;                               // empty: the built-in X-Cell 60
  logs::Vehicle vehicle = logs::xcell_vehicle();  // read from `file`

  static VehicleChoice read(const std::string& file);  // empty: the X-Cell
  bool from_file() const { return !file.empty(); }
  // The vehicle file's bytes, kept beside the results it shaped (vehicle.toml), when there is one.
  void keep(const RunDirectory& dir) const;
  // The name of the vehicle's ground truth (heli/simulators.hpp); a vehicle without one is bad input.
  const std::string& simulator() const;
  // The vehicle's ground truth with the settings; a vehicle without one, or settings it rejects, is bad
  // input.
  std::unique_ptr<GroundTruth> ground_truth(const GroundTruthSettings& settings) const;
  // A pilot's flight of `aircraft` (the pipeline's layout, one row per simulator step) as the vehicle's logs
  // come: log.csv in the pipeline's layout when the vehicle file reads that at the simulator's rate (the
  // built-in X-Cell and the shipped files), else in the file's own layout at its log.rate_hz, with the
  // pipeline's layout beside it in pipeline_log.csv.
  struct PilotLog {
    std::string charted;    // the file in the pipeline's layout, which the charts read
    std::size_t rows = 0;   // of log.csv
    std::size_t every = 1;  // simulator steps per row of log.csv
  };
  PilotLog write_pilot_log(const RunDirectory& dir, const sysid::FlightLog& log,
                           const GroundTruth& aircraft) const;
  // Bad input, before anything flies, when write_pilot_log could not write the file's layout: its rate does
  // not divide the simulator's, or two of its quantities name one CSV column.
  void check_pilot_log(const GroundTruth& aircraft) const;
  // The identified model in `file`; one identified from another vehicle's logs is bad input.
  std::shared_ptr<const sysid::IdentifiedModel> load_model(const std::string& file) const;
};

struct PilotRunOptions {
  VehicleChoice aircraft{};
  GroundTruthSettings settings{};  // gusts and estimate errors
  double seconds = 339;            // flight length, s (thesis: 339 s to train, 140 s to test)
  double hover_seconds = 10;       // plain hover before the sweeps, s
  bool sweeps = true;              // a frequency sweep in each channel in turn after the hover
  double sweep_scale = 1;          // multiplies the pilot's sweep amplitudes
  std::uint64_t seed = 1;
};
// log.csv, truth.csv, their charts, summary.json; a crash of the pilot is a failure after the files are
// written.
void run_pilot(const PilotRunOptions& options, RunSink& sink);

struct IdentifyRunOptions {
  VehicleChoice aircraft{};
  std::string train_log, test_log;  // CSV in the vehicle's layout (the project's own without a file)
  // More hold-out flights, in the same layout, whose steps the noise check pools with the test log's.
  std::vector<std::string> noise_check_logs;
  sysid::IdentifyOptions identify{};
  double horizon_s = 10;       // longest prediction horizon of the report, s
  double start_spacing_s = 2;  // spacing of the open-loop prediction starts on the test log, s
  double reset_s = 2;          // the noise check's EKF is reset to the true state this often, s
  bool variants = true;        // the model-selection variants of Fig 5.2
  double control_rate_hz =
      HoverTrainingOptions{}.control_rate_hz;  // the rate hover training steps the model at
  // Choose the model class from the data (sysid::choose_model_class between the locally weighted and the
  // global linear fit, on the test log as training runs them) instead of identify.local: the default, unless
  // the config or an option sets `local` (issue 48).
  bool choose_class = true;
  // Choose the noise model from the data: ar1+measurement with calibrate_noise, the most honest on both
  // shipped aircraft, when the training log holds at least kHonestNoiseMinSeconds; white noise otherwise
  // (a line says so). The default, unless the config or an option sets `noise` or `calibrate_noise`.
  bool choose_noise = true;
  static constexpr double kHonestNoiseMinSeconds = 120;
  // Move the control gains that closed-loop data biases to their whitened values
  // (sysid::with_whitened_gains). With choose_gains (the default unless the config or an option sets
  // `whitened_gains`), whichever predicts the test log better as training runs it.
  bool whitened_gains = false;
  bool choose_gains = true;

  // The report's numbers, once (issue 49 item 1): identify's options with their bounds and reading, and
  // the bounds of Python's horizon_mse; control_rate_hz takes hover training's bounds, as it is its rate.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = IdentifyRunOptions;
    v.setting({"horizon_s", 0.1, 100, false, "s", "longest prediction horizon of the report, s"},
              &O::horizon_s);
    v.setting({"start_spacing_s", 0.02, 1000, false, "s",
               "spacing of the open-loop prediction starts on the test log, s"},
              &O::start_spacing_s);
    v.setting(
        {"reset_s", 0.1, 100, false, "s", "the noise check's EKF is reset to the true state this often, s"},
        &O::reset_s);
    const NumberSetting& rate = HoverTrainingOptions::setting("control_rate_hz");
    v.setting({rate.key, rate.lower, rate.upper, rate.lower_open, rate.unit,
               "the rate hover training will step the model at (heli hover --control-rate-hz): the chosen "
               "model's errors are also reported as training runs it"},
              &O::control_rate_hz);
  }
  // Every number within its bounds, and the identification options valid; else false with "KEY: expected
  // ..." in `error`.
  bool IsValid(std::string* error) const;
};
// model.json, cross_validation.csv, mse_vs_horizon.csv, noise_check.csv, their charts, summary.json. The
// bandwidth search checkpoints after each cross-validation step and resumes from the run directory's
// checkpoint.
void run_identify(const IdentifyRunOptions& options, RunSink& sink, ThreadPool& pool);

struct HoverRunOptions {
  VehicleChoice aircraft{};
  std::string model_file;  // model.json of run_identify
  HoverTrainingOptions training{};
  bool judged_cost = false;  // training.reward is the vehicle file's [cost] (logs::judged_reward), whole
  // Where training.disturbance came from; kDefault: run_hover trains in heli::default_training_wind of the
  // model instead (heli/training_wind.hpp).
  WindSource wind_source = WindSource::kNoVehicleFile;
};
// progress.csv, policy.json, summary.json; checkpoints every optimizer iteration and resumes from the run
// directory's checkpoint.
void run_hover(const HoverRunOptions& options, RunSink& sink, ThreadPool& pool);
// summary.json's "wind" of a training that flew in one (hover, manoeuvre): the steady wind, its spread,
// gusts.
nlohmann::json wind_summary(const sysid::Disturbance& d);

struct FlyRunOptions {
  VehicleChoice aircraft{};
  std::string policy_file;         // policy.json of hover or manoeuvre training; empty with pilot_only
  bool pilot_only = false;         // fly the scripted pilot's hover instead of a policy
  bool compare_pilot = false;      // also fly the pilot from the same starts and gusts
  bool baseline_only = false;      // fly the ground truth's hand-tuned baseline (heli/baselines.hpp) instead
  bool compare_baseline = false;   // also fly the baseline from the same starts and gusts, at the same rate
  GroundTruthSettings settings{};  // gusts, estimate errors, start perturbations, steady wind (the start
                                   // position and yaw are the policy's set point)
  FlightOptions flights{};

  // What a user switches, once (issue 49 item 1): `fly`'s options pilot, compare_pilot, baseline and
  // compare_baseline with their help, and their reading (declare_flags, read_flags).
  template <class Visitor>
  static void VisitFlags(Visitor& v) {
    using O = FlyRunOptions;
    v.flag({"pilot", "fly the scripted pilot's hover instead of a policy"}, &O::pilot_only);
    v.flag({"compare_pilot", "also fly the scripted pilot's hover from the same starts and gusts"},
           &O::compare_pilot);
    v.flag(
        {"baseline",
         "fly the ground truth's hand-tuned baseline instead of a policy (xcell: a linear hover controller, "
         "crazyflie2: a cascaded PD; docs/results/baselines.md)"},
        &O::baseline_only);
    v.flag({"compare_baseline",
            "also fly the hand-tuned baseline from the same starts and gusts, at the policy's rate"},
           &O::compare_baseline);
  }
};
// flights.csv (traced flights), per_flight.csv, pilot_flights.csv, baseline_flights.csv, the flight charts
// and the 3-D replay, summary.json; judged by the vehicle file's [cost] when it states one (judged_cost). In
// src/heli/runs/fly_run.cpp.
void run_fly(const FlyRunOptions& options, RunSink& sink, ThreadPool& pool);

// The pipeline's summary.json and headline lines, from the summaries of its `hover` and `fly` stages in the
// run directory's sub-directories of those names; `vehicle`: the vehicle file's aircraft, empty for the
// built-in X-Cell (whose summary then names none, as it always did).
void write_pipeline_summary(const std::string& vehicle, double flight_seconds, RunSink& sink);

struct ControlRunOptions {
  std::string vehicle_file;  // the lines' layout: this vehicle file's own; empty: the pipeline's (the X-Cell)
  std::string policy_file;   // policy.json of hover or manoeuvre training
  std::int64_t bench_lines = 0;  // 0: serve; N: time N synthetic lines (the pipeline's layout) instead
};
// Serves the policy file line by line, a state line from `in` answered by its controls on `out` (errors and
// a warning when the policy was trained for another aircraft go to `err`), until `in` ends; or, with
// bench_lines, prints the loop's lines per second to `report`.
void run_control(const ControlRunOptions& options, std::FILE* in, std::FILE* out, std::FILE* err,
                 std::ostream& report);

}  // namespace pegasus::heli
