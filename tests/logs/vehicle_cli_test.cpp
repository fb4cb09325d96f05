// `pegasus identify`, `hover`, `control` and `fly` with --vehicle, end to end: an outside aircraft's logs
// (10 Hz, quaternions, body frames, its own channels; outside_aircraft.hpp) identify the same model as the
// X-Cell's own logs of the same flights; a policy trained from them is served in the aircraft's own terms
// and answers what `heli control` answers in the pipeline's; the vehicle file sets the rates, the latent
// states and the starting gains unless an option says otherwise; a vehicle without a ground truth is not
// flown; a bad vehicle file stops every command with one line and no run directory.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "outside_aircraft.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "support/cli_runner.hpp"

namespace {

using namespace pegasus;
using test_support::run_pegasus;
using test_support::run_shell;

class VehicleCli : public test_support::TempDirTest {
 protected:
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  void write(const std::string& name, const std::string& text) const { std::ofstream(dir_ / name) << text; }
  nlohmann::json summary(const std::string& run) const {
    return nlohmann::json::parse(test_support::read_text(dir_ / run / "summary.json"));
  }
  // Two pilot flights of the X-Cell, as its own 10 Hz logs and as the outside aircraft's.
  void make_logs() {
    for (const auto& [name, seconds, seed] :
         {std::tuple{"train", "90", "1"}, std::tuple{"test", "60", "2"}}) {
      const auto r = run_pegasus(fmt::format("heli pilot --seconds {} --seed {} --quiet --out {}", seconds,
                                             seed, path(std::string("pilot-") + name)));
      ASSERT_EQ(r.code, 0) << r.output;
      const sysid::FlightLog own = test_support::every_nth_row(
          sysid::read_flight_log(dir_ / ("pilot-" + std::string(name)) / "log.csv"), 5);
      sysid::write_flight_log(dir_ / (std::string(name) + "-own.csv"), own);
      write(std::string(name) + "-outside.csv", test_support::outside_log_csv(own));
    }
    write("outside.toml", test_support::kOutsideVehicle);
  }
  static constexpr const char* kSmall =
      "--cv-points 40 --scale-grid 1,4 --coordinate-passes 0 --variants=false --quiet";
};

TEST_F(VehicleCli, AnOutsideAircraftIdentifiesHoversAndIsServedInItsOwnTerms) {
  make_logs();
  // The outside aircraft from its vehicle file: 10 Hz model, no latent states, a 10 Hz controller.
  auto r = run_pegasus(fmt::format("identify --vehicle {} --train {} --test {} {} --out {}",
                                   path("outside.toml"), path("train-outside.csv"), path("test-outside.csv"),
                                   kSmall, path("id-outside")));
  ASSERT_EQ(r.code, 0) << r.output;
  // The same flights in the pipeline's layout, with the options the vehicle file stands for.
  r =
      run_pegasus(fmt::format("heli identify --train {} --test {} --rate-hz 10 --extra-states=false "
                              "--control-rate-hz 10 {} --out {}",
                              path("train-own.csv"), path("test-own.csv"), kSmall, path("id-own")));
  ASSERT_EQ(r.code, 0) << r.output;
  nlohmann::json outside = summary("id-outside"), own = summary("id-own");
  EXPECT_EQ(outside["vehicle"], "outside-heli");
  EXPECT_EQ(outside["control_rate_hz"], 10.0);
  EXPECT_EQ(outside["rate_hz"], 10.0);
  EXPECT_EQ(outside["structure"], own["structure"]);
  EXPECT_EQ(outside["structure"].get<std::string>().find("a1s"), std::string::npos) << outside["structure"];
  for (const auto& [input, width] : own["bandwidth"].items()) {  // the same choices on the grid
    if (width.is_string())
      EXPECT_EQ(outside["bandwidth"][input], width) << input;
    else
      EXPECT_NEAR(outside["bandwidth"][input].get<double>(), width.get<double>(), 1e-12 * width.get<double>())
          << input;
  }
  for (const char* seconds : {"1", "5"})
    for (const auto& [var, mse] : own["mse_at_seconds"][seconds].items())
      EXPECT_NEAR(outside["mse_at_seconds"][seconds][var].get<double>(), mse.get<double>(),
                  1e-6 * mse.get<double>())
          << seconds << " s " << var;
  // At the defaults the class and the noise come from the data, the same from either layout, and say so.
  EXPECT_EQ(outside["model_choice"]["chosen"], own["model_choice"]["chosen"]);
  ASSERT_EQ(outside["model_choice"]["candidates"].size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {  // the same up to the layouts' rounding (quaternions, body frames)
    const double a = outside["model_choice"]["candidates"][i]["score"].get<double>(),
                 b = own["model_choice"]["candidates"][i]["score"].get<double>();
    EXPECT_NEAR(a, b, 1e-9 * b) << i;
  }
  EXPECT_EQ(outside["choices"]["model_class"]["by"], "hold-out prediction") << outside["choices"];
  EXPECT_EQ(outside["choices"]["model_class"]["class"], outside["model_choice"]["chosen"]);
  EXPECT_EQ(outside["local"], outside["model_choice"]["chosen"] == "locally weighted");
  EXPECT_EQ(outside["noise"], "white");  // 90 s of training log: too short for the calibrated noise
  EXPECT_EQ(outside["choices"]["noise"]["by"], "training log too short");
  EXPECT_NE(r.output.find("model class: "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("noise: white, as the training log's 90 s are fewer than the 120 s"),
            std::string::npos)
      << r.output;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "id-outside" / "vehicle.toml"));
  // The resolved config says where each value came from: the vehicle file.
  const std::string config = test_support::read_text(dir_ / "id-outside" / "config.toml");
  EXPECT_NE(config.find("extra_states = false"), std::string::npos) << config;
  EXPECT_NE(config.find("control_rate_hz = 10.0"), std::string::npos) << config;

  // Hover from the vehicle file: a 10 Hz controller with LQR starting gains (the constants are the X-Cell's).
  r = run_pegasus(
      fmt::format("hover --vehicle {} --model {} --scenarios 3 --seconds 3 "
                  "--optimizer.gradient.max-iterations 2 --then-hill-climb=false --quiet --out {}",
                  path("outside.toml"), path("id-outside/model.json"), path("hover")));
  ASSERT_EQ(r.code, 0) << r.output;
  const nlohmann::json hover = summary("hover");
  EXPECT_EQ(hover["vehicle"], "outside-heli");
  EXPECT_EQ(hover["control_rate_hz"], 10.0);
  EXPECT_EQ(hover["starting_gains"]["method"], "lqr") << hover["starting_gains"];
  // Every start tried, with its crash count; the last taken, and the choices name it.
  ASSERT_TRUE(hover["start_tries"].is_array() && !hover["start_tries"].empty()) << hover;
  EXPECT_EQ(hover["start_tries"].back()["taken"], true) << hover["start_tries"];
  EXPECT_EQ(hover["start_tries"].back()["crashed_scenarios"], hover["starting_policy"]["crashed_scenarios"]);
  EXPECT_EQ(hover["choices"]["start"]["gains"], hover["start_tries"].back()["gains"]) << hover["choices"];
  // The class identify chose, or the global fit beside a local one that cannot fly the default wind.
  EXPECT_EQ(hover["choices"]["model_class"], hover["choices"].contains("training_model")
                                                 ? nlohmann::json("global linear")
                                                 : outside["model_choice"]["chosen"]);
  EXPECT_EQ(hover["choices"]["optimizer"], "gradient");
  const auto policy = nlohmann::json::parse(test_support::read_text(dir_ / "hover" / "policy.json"));
  EXPECT_EQ(policy["provenance"]["vehicle"], "outside-heli");
  // An option given wins over the vehicle file.
  r =
      run_pegasus(fmt::format("hover --vehicle {} --model {} --scenarios 3 --seconds 3 --control-rate-hz 50 "
                              "--starting-gains constant --optimizer.gradient.max-iterations 1 "
                              "--then-hill-climb=false --max-start-crash-fraction 1 --quiet --out {}",
                              path("outside.toml"), path("id-outside/model.json"), path("hover-50")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(summary("hover-50").contains("control_rate_hz"));  // 50 Hz: the key is left out
  EXPECT_FALSE(summary("hover-50").contains("starting_gains"));

  // Served in the outside aircraft's terms: its own log as the input, its channels as the answer, equal to
  // what `heli control` answers on the same states in the pipeline's layout.
  r = run_shell(fmt::format("({} control --vehicle {} --policy {} < {} > {} 2> {})", PEGASUS_CLI_PATH,
                            path("outside.toml"), path("hover/policy.json"), path("test-outside.csv"),
                            path("answers-outside.csv"), path("said-outside.txt")));
  ASSERT_EQ(r.code, 0) << r.output;
  // No malformed line; the log's column of no state or control is named once, as ignored.
  EXPECT_EQ(test_support::read_text(dir_ / "said-outside.txt"),
            "stdin:1: header: columns not of this layout, ignored: 9 'battery_v'\n");
  r = run_shell(fmt::format("({} heli control --policy {} < {} > {})", PEGASUS_CLI_PATH,
                            path("hover/policy.json"), path("test-own.csv"), path("answers-own.csv")));
  ASSERT_EQ(r.code, 0) << r.output;
  // Without --vehicle the lines are the X-Cell's: serving another aircraft's policy so is said, once.
  EXPECT_NE(r.output.find("was trained for vehicle 'outside-heli'; serving it in the terms of 'xcell60'"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
  const auto native = parse_csv(test_support::read_text(dir_ / "answers-outside.csv"));
  const auto canonical = parse_csv(test_support::read_text(dir_ / "answers-own.csv"));
  ASSERT_EQ(native.size(), canonical.size());
  ASSERT_GT(native.size(), 500u);
  EXPECT_EQ(native[0], (std::vector<std::string>{"thr", "ail", "ele", "rudder_us"}));
  EXPECT_EQ(canonical[0], (std::vector<std::string>{"a1", "a2", "a3", "a4"}));
  for (std::size_t i = 1; i < native.size(); ++i) {
    heli::Controls a{};
    for (std::size_t c = 0; c < 4; ++c) a[c] = std::stod(canonical[i][c]);
    const auto expected = test_support::outside_controls(a);
    for (std::size_t c = 0; c < 4; ++c)
      ASSERT_NEAR(std::stod(native[i][c]), expected[c], 1e-7 * (c == 3 ? 1000 : 1))
          << "line " << i << " " << c;
  }

  // Served as another aircraft, it still answers, with a warning that names both.
  r = run_shell(
      fmt::format("({} control --vehicle {}/experiments/vehicles/xcell60.toml --policy {} < {} >/dev/null)",
                  PEGASUS_CLI_PATH, PEGASUS_SOURCE_DIR, path("hover/policy.json"), path("test-own.csv")));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("was trained for vehicle 'outside-heli'; serving it in the terms of 'xcell60'"),
            std::string::npos)
      << r.output;
  // So do fly, on another aircraft's ground truth, and export, in another aircraft's terms.
  r =
      run_pegasus(fmt::format("fly --vehicle {}/experiments/vehicles/xcell60.toml --policy {} --flights 1 "
                              "--seconds 1 --quiet --out {}",
                              PEGASUS_SOURCE_DIR, path("hover/policy.json"), path("fly-xcell")));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("was trained for vehicle 'outside-heli'; flying it on 'xcell60'"),
            std::string::npos)
      << r.output;
  r = run_pegasus(
      fmt::format("export --vehicle {}/experiments/vehicles/xcell60.toml --policy {} --quiet --out {}",
                  PEGASUS_SOURCE_DIR, path("hover/policy.json"), path("export-xcell")));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("was trained for vehicle 'outside-heli'; writing it in the terms of 'xcell60'"),
            std::string::npos)
      << r.output;

  // No ground truth of this aircraft: fly says so and how to fly it instead.
  r = run_pegasus(fmt::format("fly --vehicle {} --policy {} --out {}", path("outside.toml"),
                              path("hover/policy.json"), path("fly")));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("vehicle.simulator: 'none'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("pegasus control --vehicle"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "fly"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "fly.partial"));
  // Nor its manoeuvres, refused before any training (the flights at the end would need the ground truth).
  r = run_pegasus(fmt::format("maneuver --vehicle {} --model {} --out {}", path("outside.toml"),
                              path("id-outside/model.json"), path("maneuver")));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("vehicle.simulator: 'none'"), std::string::npos) << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "maneuver"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "maneuver.partial"));
}

// An aircraft the project can fly whose logs come in another layout and at another rate: the pilot writes
// log.csv as its vehicle file describes (10 Hz, quaternions, body frames, its channels), which identify then
// reads, and the flight in the pipeline's layout beside it; a rate the simulator cannot log is refused
// before anything flies.
// A vehicle file's aircraft with no wind stated trains in the default wind; a locally weighted model whose
// starting policy cannot fly it gives way to the global linear fit identify recorded beside it, and trains
// exactly as that fit's own model file does (issue 48). A stated wind keeps the local model.
TEST_F(VehicleCli, ALocalModelThatCannotFlyTheTrainingWindGivesWayToTheGlobalFitBesideIt) {
  make_logs();
  auto r =
      run_pegasus(fmt::format("identify --vehicle {} --train {} --test {} {} --out {}", path("outside.toml"),
                              path("train-outside.csv"), path("test-outside.csv"), kSmall, path("id")));
  ASSERT_EQ(r.code, 0) << r.output;
  // The same fits with the local one chosen (whichever class these short logs chose): the local model with
  // the global fit recorded beside it, and the global fit alone.
  const sysid::IdentifiedModel identified = sysid::IdentifiedModel::load(dir_ / "id" / "model.json");
  const std::optional<sysid::IdentifiedModel> other = identified.alternative();
  ASSERT_TRUE(other.has_value());
  const sysid::IdentifiedModel& local_fit = identified.is_global() ? *other : identified;
  sysid::IdentifiedModel local(local_fit.structure(), local_fit.data(), local_fit.inv_bandwidth(),
                               identified.sigma2(), identified.noise_correlation());
  local.set_vehicle("outside-heli");
  local.set_model_choice({{"chosen", "locally weighted"}}, std::array<double, sysid::kInputs>{});
  local.save(dir_ / "local.json");
  sysid::IdentifiedModel global = *local.alternative();
  ASSERT_TRUE(global.is_global());
  global.save(dir_ / "global.json");
  const std::string train =
      "--scenarios 10 --seconds 5 --optimizer.gradient.max-iterations 2 --then-hill-climb=false --quiet";
  r = run_pegasus(fmt::format("hover --vehicle {} --model {} {} --out {}", path("outside.toml"),
                              path("local.json"), train, path("switched")));
  ASSERT_EQ(r.code, 0) << r.output;
  const nlohmann::json switched = summary("switched");
  ASSERT_TRUE(switched["choices"].contains("training_model")) << switched["choices"];
  EXPECT_EQ(switched["choices"]["training_model"]["class"], "global linear");
  EXPECT_EQ(switched["choices"]["model_class"], "global linear");
  EXPECT_EQ(switched["choices"]["wind"]["by"], "default for a global linear model");
  EXPECT_NE(switched["choices"]["training_model"]["reason"].get<std::string>().find(
                "the locally weighted model's starting policy crashed"),
            std::string::npos);
  EXPECT_NE(r.output.find("model: the global linear fit identify made beside the chosen locally weighted"),
            std::string::npos)
      << r.output;
  // Trained exactly as on the global fit's own file.
  r = run_pegasus(fmt::format("hover --vehicle {} --model {} {} --out {}", path("outside.toml"),
                              path("global.json"), train, path("on-global")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(summary("on-global")["final_uhat"], switched["final_uhat"]);
  const auto weights = [&](const std::string& run) {
    return nlohmann::json::parse(test_support::read_text(dir_ / run / "policy.json"))["parameters"];
  };
  EXPECT_EQ(weights("on-global"), weights("switched"));
  EXPECT_FALSE(summary("on-global")["choices"].contains("training_model"));
  // A stated wind is the user's: the local model stays.
  r =
      run_pegasus(fmt::format("hover --vehicle {} --model {} {} --wind.sigma 0 --max-start-crash-fraction 1 "
                              "--out {}",
                              path("outside.toml"), path("local.json"), train, path("stated")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(summary("stated")["choices"]["model_class"], "locally weighted");
  EXPECT_FALSE(summary("stated")["choices"].contains("training_model"));
}

TEST_F(VehicleCli, ThePilotLogsInTheVehiclesOwnLayoutAndRate) {
  write("outside-sim.toml", test_support::replaced(test_support::kOutsideVehicle, "name = \"outside-heli\"",
                                                   "name = \"outside-heli\"\nsimulator = \"xcell\""));
  auto r = run_pegasus(fmt::format("pilot --vehicle {} --seconds 40 --quiet --out {}",
                                   path("outside-sim.toml"), path("pilot")));
  ASSERT_EQ(r.code, 0) << r.output;
  r = run_pegasus(fmt::format("heli pilot --seconds 40 --quiet --out {}", path("xcell")));
  ASSERT_EQ(r.code, 0) << r.output;
  // The same flight: the pipeline's layout byte for byte, and log.csv reads back to its every fifth row.
  EXPECT_EQ(test_support::read_text(dir_ / "pilot" / "pipeline_log.csv"),
            test_support::read_text(dir_ / "xcell" / "log.csv"));
  const logs::Vehicle vehicle = logs::read_vehicle(path("outside-sim.toml"));
  const sysid::FlightLog own =
      test_support::every_nth_row(sysid::read_flight_log(dir_ / "xcell" / "log.csv"), 5);
  const sysid::FlightLog read = logs::read_vehicle_log(dir_ / "pilot" / "log.csv", vehicle);
  EXPECT_EQ(test_support::log_difference(read, own), "");
  EXPECT_EQ(summary("pilot")["rate_hz"], 10.0);
  EXPECT_EQ(summary("pilot")["rows"], own.rows());
  r = run_pegasus(fmt::format("identify --vehicle {} --train {} --test {} {} --out {}",
                              path("outside-sim.toml"), path("pilot/log.csv"), path("pilot/log.csv"), kSmall,
                              path("id")));
  EXPECT_EQ(r.code, 0) << r.output;
  // A 12.5 Hz model has no step at 1 s or 5 s: the summary says so instead of leaving the keys out silently.
  r = run_pegasus(fmt::format("heli identify --train {} --test {} --rate-hz 12.5 {} --out {}",
                              path("xcell/log.csv"), path("xcell/log.csv"), kSmall, path("id-12.5")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(summary("id-12.5")["mse_seconds_skipped"], nlohmann::json::array({1, 5}));
  EXPECT_FALSE(summary("id-12.5")["mse_at_seconds"].contains("1"));
  EXPECT_TRUE(summary("id-12.5")["mse_at_seconds"].contains("10"));
  EXPECT_FALSE(summary("id")["mse_at_seconds"].empty());
  EXPECT_FALSE(summary("id").contains("mse_seconds_skipped"));
  // 30 Hz does not divide the simulator's 50 Hz.
  write("outside-30.toml",
        test_support::replaced(
            test_support::replaced(test_support::kOutsideVehicle, "rate_hz = 10\nmodel_rate_hz = 10",
                                   "rate_hz = 30\nmodel_rate_hz = 10"),
            "name = \"outside-heli\"", "name = \"outside-heli\"\nsimulator = \"xcell\""));
  r = run_pegasus(
      fmt::format("pilot --vehicle {} --seconds 40 --out {}", path("outside-30.toml"), path("pilot30")));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("log.rate_hz: the xcell ground truth steps at 50 Hz"), std::string::npos)
      << r.output;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "pilot30"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "pilot30.partial"));
}

// A ROS-convention multirotor (ros-quadrotor.toml: ENU, FLU, quaternion x, y, z, w, degrees) flown on the
// Crazyflie's ground truth: the pilot writes its log in ROS terms (z up, facing north as a quarter turn about
// up), the same flight as the Crazyflie file's byte for byte in the pipeline's layout, and the log reads back
// through the file to the Crazyflie's own rows (issue 53).
TEST_F(VehicleCli, ARosConventionVehicleLogsInRosTermsTheSameFlight) {
  const std::filesystem::path vehicles =
      std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "vehicles";
  write("ros.toml", test_support::replaced(test_support::read_text(vehicles / "ros-quadrotor.toml"),
                                           "name = \"ros-quadrotor\"",
                                           "name = \"ros-quadrotor\"\nsimulator = \"crazyflie2\""));
  auto r = run_pegasus(
      fmt::format("pilot --vehicle {} --seconds 20 --quiet --out {}", path("ros.toml"), path("ros")));
  ASSERT_EQ(r.code, 0) << r.output;
  r = run_pegasus(fmt::format("pilot --vehicle {} --seconds 20 --quiet --out {}",
                              (vehicles / "crazyflie2.toml").string(), path("cf")));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(test_support::read_text(dir_ / "ros" / "pipeline_log.csv"),
            test_support::read_text(dir_ / "cf" / "log.csv"));
  const logs::Vehicle ros = logs::read_vehicle(path("ros.toml"));
  const sysid::FlightLog own = sysid::read_flight_log(dir_ / "cf" / "log.csv");
  EXPECT_EQ(test_support::log_difference(logs::read_vehicle_log(dir_ / "ros" / "log.csv", ros), own), "");
  // The first row in ROS terms: about 2 m up (z up), facing north (x, y, z, w near 0, 0, 0.707, 0.707).
  const auto table = parse_csv(test_support::read_text(dir_ / "ros" / "log.csv"));
  ASSERT_GE(table.size(), 2u);
  EXPECT_EQ(table[0][1], "px");
  EXPECT_EQ(table[0][10], "qw");
  EXPECT_NEAR(std::stod(table[1][3]), 2, 0.1);        // pz
  EXPECT_NEAR(std::stod(table[1][9]), 0.707, 0.01);   // qz
  EXPECT_NEAR(std::stod(table[1][10]), 0.707, 0.01);  // qw
}

TEST_F(VehicleCli, ABadVehicleFileStopsEveryCommandWithOneLineAndNoRunDirectory) {
  write("bad.toml", std::string(test_support::kOutsideVehicle) + "\n[hover]\nstarting_gain = \"lqr\"\n");
  write("log.csv", "t\n");
  for (const std::string& command :
       {std::string("identify --train ") + path("log.csv") + " --test " + path("log.csv"),
        std::string("hover --model ") + path("model.json"),
        std::string("heli identify --train x --test y")}) {
    const auto r = run_pegasus(command + " --vehicle " + path("bad.toml") + " --out " + path("run"));
    EXPECT_EQ(r.code, 2) << command << "\n" << r.output;
    EXPECT_NE(r.output.find("bad.toml:51: hover.starting_gain: unknown key"), std::string::npos)
        << command << "\n"
        << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "run"));
    EXPECT_FALSE(std::filesystem::exists(dir_ / "run.partial"));
  }
}

}  // namespace
