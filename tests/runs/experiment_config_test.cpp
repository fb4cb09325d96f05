// The experiments' config sections (DOMAIN/runs/*_config.hpp and the sections beside single experiments): a
// section read at its defaults gives its Options struct's defaults (defaults live once), a value set in the
// schema reaches the options, and a vehicle file fills only the fields the user left at their defaults.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "pegasus/codegen/runs/export_run.hpp"
#include "pegasus/experiments/runs/bicycle_config.hpp"
#include "pegasus/experiments/runs/pendulum_run.hpp"
#include "pegasus/experiments/runs/pomdp_gridworld_run.hpp"
#include "pegasus/experiments/runs/shaping_config.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/heli/runs/log_import_run.hpp"
#include "pegasus/heli/runs/maneuver_config.hpp"

namespace pegasus {
namespace {

constexpr std::uint64_t kSeed = 7;
constexpr int kThreads = 3;

// A section's schema at its defaults, checked as a command would before reading it.
template <typename Declare>
ConfigSchema defaults_of(Declare declare) {
  ConfigSchema s;
  declare(s);
  s.validate();
  return s;
}

void expect_same_optimizer(const OptimizerOptions& read, const OptimizerOptions& defaults) {
  EXPECT_EQ(read.method, defaults.method);
  EXPECT_EQ(read.gradient.max_iterations, defaults.gradient.max_iterations);
  EXPECT_EQ(read.gradient.relative_step, defaults.gradient.relative_step);
  EXPECT_EQ(read.hill_climbing.max_iterations, defaults.hill_climbing.max_iterations);
  EXPECT_EQ(read.cmaes.max_iterations, defaults.cmaes.max_iterations);
  EXPECT_EQ(read.ars.max_iterations, defaults.ars.max_iterations);
  EXPECT_EQ(read.nlopt.max_evaluations, defaults.nlopt.max_evaluations);
}

TEST(ExperimentConfig, HoverDefaultsAreTheOptionsStructs) {
  const ConfigSchema s = defaults_of(heli::declare_hover_config);
  const heli::HoverRunOptions read = heli::read_hover_config(s, kSeed);
  const heli::HoverTrainingOptions d;
  const heli::HoverTrainingOptions& o = read.training;
  EXPECT_FALSE(read.aircraft.from_file());
  EXPECT_EQ(o.scenarios, d.scenarios);
  EXPECT_EQ(o.seconds, d.seconds);
  EXPECT_EQ(o.gamma, d.gamma);
  EXPECT_EQ(o.refit_every, d.refit_every);
  EXPECT_EQ(o.control_rate_hz, d.control_rate_hz);
  EXPECT_EQ(o.lqr_start, d.lqr_start);
  EXPECT_EQ(o.integral_seconds, d.integral_seconds);
  EXPECT_EQ(o.integral_limit_position, d.integral_limit_position);
  EXPECT_EQ(o.integral_limit_yaw, d.integral_limit_yaw);
  EXPECT_EQ(o.start_pos_sigma, d.start_pos_sigma);
  EXPECT_EQ(o.start_vel_sigma, d.start_vel_sigma);
  EXPECT_EQ(o.max_tilt_rad, d.max_tilt_rad);
  EXPECT_EQ(o.max_start_crash_fraction, d.max_start_crash_fraction);
  EXPECT_EQ(o.target.x, d.target.x);
  EXPECT_EQ(o.target.y, d.target.y);
  EXPECT_EQ(o.target.z, d.target.z);
  EXPECT_EQ(o.target.yaw, d.target.yaw);
  // The reward the CLI trains is the one the library's defaults describe (they once differed: 25 vs 100).
  EXPECT_EQ(o.reward.alpha_pos, d.reward.alpha_pos);
  EXPECT_EQ(o.reward.alpha_vel, d.reward.alpha_vel);
  EXPECT_EQ(o.reward.alpha_yaw, d.reward.alpha_yaw);
  EXPECT_EQ(o.reward.alpha_action, d.reward.alpha_action);
  EXPECT_EQ(o.reward.alpha_attitude, d.reward.alpha_attitude);
  EXPECT_EQ(o.reward.alpha_rate, d.reward.alpha_rate);
  EXPECT_EQ(o.centre_at_trim, d.centre_at_trim);
  EXPECT_EQ(o.then_hill_climb, d.then_hill_climb);
  expect_same_optimizer(o.optimizer, d.optimizer);
  EXPECT_EQ(o.seed, kSeed);
}

TEST(ExperimentConfig, ValuesSetInTheSchemaReachTheOptions) {
  ConfigSchema s = defaults_of(heli::declare_hover_config);
  s.set("scenarios", std::int64_t{12});
  s.set("reward.position_m", 2.0);
  s.set("reward.rate_radps", 0.5);
  s.set("target", std::vector<double>{1, 2, -3, 0.5});
  s.set("optimizer.method", std::string("cmaes"));
  s.set("optimizer.cmaes.max_iterations", std::int64_t{9});
  s.validate();
  const heli::HoverTrainingOptions o = heli::read_hover_config(s, kSeed).training;
  EXPECT_EQ(o.scenarios, 12);
  EXPECT_EQ(o.reward.alpha_pos[2], 0.25);
  EXPECT_EQ(o.reward.alpha_rate[1], 4.0);
  EXPECT_EQ(o.target.z, -3);
  EXPECT_EQ(o.target.yaw, 0.5);
  EXPECT_EQ(o.optimizer.method, "cmaes");
  EXPECT_EQ(o.optimizer.cmaes.max_iterations, 9);

  ConfigSchema id = defaults_of(heli::declare_identify_config);
  id.set("calibration_leave_out_s", 6.0);
  id.set("calibration_spacing_s", 0.25);
  id.set("horizon_sd_factors", false);
  id.set("noise_check_logs", std::vector<std::string>{"a.csv", "b.csv"});
  id.validate();
  const heli::IdentifyRunOptions run = heli::read_identify_config(id);
  EXPECT_EQ(run.noise_check_logs, (std::vector<std::string>{"a.csv", "b.csv"}));
  const sysid::IdentifyOptions& identify = run.identify;
  EXPECT_EQ(identify.calibration_leave_out_s, 6.0);
  EXPECT_EQ(identify.calibration_spacing_s, 0.25);
  EXPECT_FALSE(identify.horizon_sd_factors);
  // Left unset, the class, the noise and the gains come from the data; set, the option decides (issue 48).
  EXPECT_TRUE(run.choose_class && run.choose_noise && run.choose_gains);
  id.set("local", false, "--local");
  id.set("calibrate_noise", true, "--calibrate-noise");
  id.set("whitened_gains", true, "--whitened-gains");
  const heli::IdentifyRunOptions set = heli::read_identify_config(id);
  EXPECT_FALSE(set.choose_class || set.choose_noise || set.choose_gains);
  EXPECT_FALSE(set.identify.local);
  EXPECT_TRUE(set.identify.calibrate_noise && set.whitened_gains);
}

TEST(ExperimentConfig, AVehicleFileFillsOnlyWhatTheUserLeftAtDefaults) {
  const std::string vehicle =
      (std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments/vehicles/crazyflie2.toml").string();
  ConfigSchema s = defaults_of(heli::declare_hover_config);
  s.set("vehicle", vehicle, "--vehicle");
  s.set("control_rate_hz", 25.0, "--control-rate-hz");
  heli::resolve_hover_config(s);
  s.validate();
  const heli::HoverRunOptions read = heli::read_hover_config(s, kSeed);
  EXPECT_TRUE(read.aircraft.from_file());
  EXPECT_EQ(read.training.control_rate_hz, 25.0);  // the user's, not the file's 50
  EXPECT_EQ(read.training.target.z, -2.0);         // the file's [hover] target
  EXPECT_TRUE(read.training.lqr_start);            // the file's starting_gains = "lqr"
  EXPECT_EQ(read.training.integral_seconds, 5.0);
  EXPECT_EQ(read.training.max_tilt_rad, 1.0);
  EXPECT_EQ(s.origin("control_rate_hz"), "--control-rate-hz");
  EXPECT_NE(s.origin("target").find("hover.target"), std::string::npos) << s.origin("target");

  ConfigSchema g = defaults_of(heli::declare_fly_config);
  g.set("vehicle", vehicle, "--vehicle");
  heli::resolve_gust_sigma(g);
  EXPECT_EQ(heli::read_fly_config(g, kSeed).settings.gust_sigma, heli::own_gust_sigma("crazyflie2"));
}

// Every field a section's resolve step takes from a vehicle file is named, by the file's key, in the help of
// its `vehicle` field, which says that those replace the defaults shown.
TEST(ExperimentConfig, TheVehicleFieldsHelpNamesEveryKeyTheResolveStepFills) {
  const std::string vehicle =
      (std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments/vehicles/crazyflie2.toml").string();
  struct Section {
    void (*declare)(ConfigSchema&);
    void (*resolve)(ConfigSchema&);
    std::size_t least_filled;
  };
  for (const Section& section : {Section{heli::declare_hover_config, heli::resolve_hover_config, 6},
                                 Section{heli::declare_identify_config, heli::resolve_identify_config, 4}}) {
    ConfigSchema s = defaults_of(section.declare);
    s.set("vehicle", vehicle, "--vehicle");
    section.resolve(s);
    const std::string& help = s.field("vehicle").help();
    std::size_t filled = 0;
    for (const ConfigField& f : s.fields()) {
      const std::string& origin = s.origin(f.name());
      if (origin == "default" || f.name() == "vehicle") continue;
      ++filled;
      const std::string key = origin.substr(origin.rfind(": ") + 2);
      const std::string named = key.starts_with("hover.reward.") ? "hover.reward.*" : key;
      EXPECT_NE(help.find(named), std::string::npos) << f.name() << " from " << key << " not in: " << help;
    }
    EXPECT_GE(filled, section.least_filled) << help;  // the file's settings were applied at all
  }
}

TEST(ExperimentConfig, HelicopterSectionsReadTheirDefaults) {
  const heli::PilotRunOptions pilot = heli::read_pilot_config(defaults_of(heli::declare_pilot_config), kSeed);
  const heli::PilotRunOptions pilot_defaults;
  EXPECT_EQ(pilot.seconds, pilot_defaults.seconds);
  EXPECT_EQ(pilot.hover_seconds, pilot_defaults.hover_seconds);
  EXPECT_EQ(pilot.sweeps, pilot_defaults.sweeps);
  EXPECT_EQ(pilot.sweep_scale, pilot_defaults.sweep_scale);
  EXPECT_EQ(pilot.settings.gust_sigma, heli::own_gust_sigma("xcell"));
  EXPECT_EQ(pilot.seed, kSeed);

  const heli::IdentifyRunOptions identify =
      heli::read_identify_config(defaults_of(heli::declare_identify_config));
  const heli::IdentifyRunOptions identify_defaults;
  const sysid::IdentifyOptions& id = identify.identify;
  const sysid::IdentifyOptions& id_defaults = identify_defaults.identify;
  EXPECT_EQ(id.structure.rate_hz, id_defaults.structure.rate_hz);
  EXPECT_EQ(id.structure.extra_states, id_defaults.structure.extra_states);
  EXPECT_EQ(id.structure.templates, id_defaults.structure.templates);
  EXPECT_EQ(id.local, id_defaults.local);
  EXPECT_EQ(id.window_s, id_defaults.window_s);
  EXPECT_EQ(id.cv_points, id_defaults.cv_points);
  EXPECT_EQ(id.scale_grid, id_defaults.scale_grid);
  EXPECT_EQ(id.coordinate_passes, id_defaults.coordinate_passes);
  EXPECT_EQ(id.noise, id_defaults.noise);
  EXPECT_EQ(id.calibrate_noise, id_defaults.calibrate_noise);
  EXPECT_EQ(id.horizon_sd_factors, id_defaults.horizon_sd_factors);
  EXPECT_EQ(id.min_bandwidth.control, id_defaults.min_bandwidth.control);
  EXPECT_EQ(id.min_bandwidth.angle_rad, id_defaults.min_bandwidth.angle_rad);
  EXPECT_EQ(identify.horizon_s, identify_defaults.horizon_s);
  EXPECT_EQ(identify.variants, identify_defaults.variants);
  EXPECT_EQ(identify.control_rate_hz, identify_defaults.control_rate_hz);

  const heli::FlyRunOptions fly = heli::read_fly_config(defaults_of(heli::declare_fly_config), kSeed);
  const heli::FlyRunOptions fly_defaults;
  EXPECT_EQ(fly.flights.flights, fly_defaults.flights.flights);
  EXPECT_EQ(fly.flights.seconds, fly_defaults.flights.seconds);
  EXPECT_EQ(fly.flights.trace_flights, fly_defaults.flights.trace_flights);
  EXPECT_EQ(fly.settings.estimate_noise, fly_defaults.settings.estimate_noise);
  // Flights start as perturbed as hover training's scenarios.
  EXPECT_EQ(fly.settings.start_pos_sigma, heli::HoverTrainingOptions{}.start_pos_sigma);
  EXPECT_EQ(fly.flights.seed, kSeed);

  const heli::ManeuverRunOptions maneuver =
      heli::read_maneuver_config(defaults_of(heli::declare_maneuver_config), kSeed);
  const heli::ManeuverRunOptions maneuver_defaults;
  const heli::ManeuverTrainingOptions& m = maneuver.training;
  const heli::ManeuverTrainingOptions& md = maneuver_defaults.training;
  EXPECT_EQ(m.name, md.name);
  EXPECT_EQ(m.size.start_W, md.size.start_W);
  EXPECT_EQ(m.size.figure_eight_radius, md.size.figure_eight_radius);
  EXPECT_EQ(m.limits.speed, md.limits.speed);
  EXPECT_EQ(m.scenarios, md.scenarios);
  EXPECT_EQ(m.gamma, md.gamma);
  EXPECT_EQ(m.reward.alpha_pos, md.reward.alpha_pos);
  EXPECT_EQ(m.reward.alpha_action, md.reward.alpha_action);
  EXPECT_EQ(m.shaping_per_metre, md.shaping_per_metre);
  EXPECT_EQ(m.policy.learn_delay, md.policy.learn_delay);
  expect_same_optimizer(m.optimizer, md.optimizer);
  EXPECT_EQ(maneuver.ablations, maneuver_defaults.ablations);
  EXPECT_EQ(maneuver.flights.flights, maneuver_defaults.flights.flights);
  EXPECT_EQ(maneuver.trace_flights, maneuver_defaults.trace_flights);

  const heli::ManeuverPilotRunOptions maneuver_pilot =
      heli::read_maneuver_pilot_config(defaults_of(heli::declare_maneuver_pilot_config), kSeed);
  EXPECT_EQ(maneuver_pilot.maneuvers, heli::ManeuverPilotRunOptions{}.maneuvers);
  EXPECT_EQ(maneuver_pilot.repeats, heli::ManeuverPilotRunOptions{}.repeats);
}

TEST(ExperimentConfig, OtherSectionsReadTheirDefaults) {
  const BicycleExperimentOptions bicycle =
      read_bicycle_experiment_config(defaults_of(declare_bicycle_experiment_config), kSeed, kThreads);
  const BicycleExperimentOptions bd;
  EXPECT_EQ(bicycle.trials, bd.trials);
  EXPECT_EQ(bicycle.lesson_trials, bd.lesson_trials);
  EXPECT_EQ(bicycle.training.scenarios, bd.training.scenarios);
  EXPECT_EQ(bicycle.training.gamma, bd.training.gamma);
  EXPECT_EQ(bicycle.training.horizon, bd.training.horizon);
  EXPECT_EQ(bicycle.training.shaping_per_metre, bd.training.shaping_per_metre);
  EXPECT_EQ(bicycle.training.bicycle.fall_reward, bd.training.bicycle.fall_reward);
  EXPECT_EQ(bicycle.training.variant, bd.training.variant);
  EXPECT_EQ(bicycle.training.initial_policy, bd.training.initial_policy);
  expect_same_optimizer(bicycle.training.optimizer, bd.training.optimizer);
  EXPECT_EQ(bicycle.riding.max_km, bd.riding.max_km);
  EXPECT_EQ(bicycle.riding.bicycle.goal.x, bd.riding.bicycle.goal.x);
  EXPECT_EQ(bicycle.riding.bicycle.goal.radius, bd.riding.bicycle.goal.radius);
  EXPECT_EQ(bicycle.training.threads, kThreads);

  const PendulumTrainingOptions pendulum =
      read_pendulum_training_config(defaults_of(declare_pendulum_training_config), kSeed, kThreads);
  const PendulumTrainingOptions pd;
  EXPECT_EQ(pendulum.scenarios, pd.scenarios);
  EXPECT_EQ(pendulum.refine_scenarios, pd.refine_scenarios);
  EXPECT_EQ(pendulum.evaluation_episodes, pd.evaluation_episodes);
  EXPECT_EQ(pendulum.bar, pd.bar);
  expect_same_optimizer(pendulum.optimizer, pd.optimizer);
  expect_same_optimizer(pendulum.refine_optimizer, pd.refine_optimizer);

  const PomdpGridworldOptions pomdp =
      read_pomdp_gridworld_config(defaults_of(declare_pomdp_gridworld_config), kSeed, kThreads);
  const PomdpGridworldOptions gd;
  EXPECT_EQ(pomdp.scenarios, gd.scenarios);
  EXPECT_EQ(pomdp.trials, gd.trials);
  EXPECT_EQ(pomdp.gamma, gd.gamma);
  EXPECT_EQ(pomdp.horizon, gd.horizon);
  EXPECT_EQ(pomdp.variant, gd.variant);

  const ShapingExperimentOptions shaping = read_shaping_learning_config(
      defaults_of([](ConfigSchema& s) { declare_shaping_learning_config(s, ShapingWorld::kGridworld); }),
      ShapingWorld::kGridworld, kSeed, kThreads);
  const ShapingExperimentOptions sd;
  EXPECT_EQ(shaping.size, sd.size);
  EXPECT_EQ(shaping.potentials, sd.potentials);
  EXPECT_EQ(shaping.runs, sd.runs);
  EXPECT_EQ(shaping.alpha, sd.alpha);
  EXPECT_EQ(shaping.intended, sd.intended);
  const ProgressBonusOptions bonus =
      read_progress_bonus_config(defaults_of(declare_progress_bonus_config), kSeed);
  EXPECT_EQ(bonus.bonus, ProgressBonusOptions{}.bonus);
  EXPECT_EQ(bonus.episodes, ProgressBonusOptions{}.episodes);
  EXPECT_EQ(read_shaping_audit_config(defaults_of(declare_shaping_audit_config)).tolerance,
            ShapingAuditRunOptions{}.tolerance);

  const LogImportRunOptions log = read_log_import_config(defaults_of(declare_log_import_config));
  const LogImportRunOptions ld;
  EXPECT_EQ(log.identify, ld.identify);
  EXPECT_EQ(log.train_fraction, ld.train_fraction);
  EXPECT_EQ(log.identification.window_s, ld.identification.window_s);
  EXPECT_EQ(log.identification.cv_points, ld.identification.cv_points);
  EXPECT_EQ(log.start_spacing_s, ld.start_spacing_s);

  EXPECT_EQ(read_export_config(defaults_of(declare_export_config)).prefix, codegen::CPolicyOptions{}.prefix);
}

}  // namespace
}  // namespace pegasus
