#pragma once
// The manoeuvre experiments of thesis §5.4 (Figs 5.8-5.10) for any aircraft with a ground truth, as library
// functions writing a run directory through a RunSink (the `maneuver` and `maneuver-pilot` commands, and
// their `heli` aliases, map their options onto these):
//   run_maneuver        PEGASUS learns an AMA Class III manoeuvre or a figure-eight on the identified model,
//                       with the two ablations (no learned z delay, no shaping) on the same budget, and flies
//                       each on the ground truth with gusts against the ideal path (and the pilot);
//   run_maneuver_pilot  the scripted pilot through hover, sweeps and the manoeuvres: identification data
//                       that covers them.
#include <cstdint>
#include <string>
#include <vector>

#include "pegasus/heli/maneuver_task.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "pegasus/heli/trajectory.hpp"

namespace pegasus::heli {

struct ManeuverRunOptions {
  VehicleChoice aircraft{};
  std::string model_file;         // model.json of run_identify
  std::string hover_policy_file;  // optional: a trained hover policy to start from (else the model's trim)
  ManeuverTrainingOptions training{};  // the manoeuvre, its size and limits, the reward, optimizer and seed
  bool ablations = true;               // also train without the learned delay and without shaping
  ManeuverFlightOptions flights{};     // flights, gusts, start perturbation (seed and simulator: set here)
  int trace_flights = 20;              // flights written to flights.csv
  bool compare_pilot = false;          // also fly the vehicle's scripted pilot along the same set points
  // Where training.disturbance came from (the options or the vehicle file's [hover.wind], resolved into them;
  // kDefault, none stated: run_maneuver trains calm).
  WindSource wind_source = WindSource::kNoVehicleFile;
};
// policy.json (and policy_no_delay.json, policy_no_shaping.json), progress CSVs, ideal_path.csv,
// flights.csv, path_deviation.csv, the charts and the 3-D replay, summary.json; checkpoints after every
// optimizer iteration and resumes from the run directory's checkpoint.
void run_maneuver(const ManeuverRunOptions& options, RunSink& sink, ThreadPool& pool);

struct ManeuverPilotRunOptions {
  VehicleChoice aircraft{};
  std::vector<std::string> maneuvers = {"III.1", "III.2", "III.3"};  // flown after the sweeps
  ManeuverSize size{};
  TrajectoryLimits limits{};
  double seconds = 339;       // hover and sweeps before the manoeuvres, s
  double hover_seconds = 10;  // plain hover before the sweeps, s
  double sweep_scale = 1;     // multiplies the pilot's sweep amplitudes
  int repeats = 2;            // times the manoeuvres are flown, one after another
  double gust_sigma = 0.5;    // m/s per axis
  std::uint64_t seed = 1;
};
// log.csv, its charts, summary.json; a crash of the pilot is a failure after the files are written.
void run_maneuver_pilot(const ManeuverPilotRunOptions& options, RunSink& sink);

}  // namespace pegasus::heli
