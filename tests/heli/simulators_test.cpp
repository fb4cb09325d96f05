// The ground-truth registry: a ground truth registered by name (here a heavier Crazyflie with its own gusts)
// is found by every function that names ground truths, and by the vehicle-file reader, with no other edit;
// the built-in ones come out of it exactly as their models built by hand.
#include "pegasus/heli/simulators.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/baselines.hpp"
#include "pegasus/heli/quadrotor.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/io/atomic_file.hpp"

namespace {

using namespace pegasus::heli;

// A Crazyflie carrying a 6 g payload, in stronger turbulence: a real model with other parameters.
QuadrotorParams heavy_params() {
  QuadrotorParams p;
  p.mass_kg = 0.034;
  p.conditions.gust_sigma = 0.3;
  return p;
}

void register_heavy() {
  register_ground_truth({"heavy-crazyflie", "a Crazyflie 2.0 with a 6 g payload (test)",
                         ground_truth_factory<Quadrotor>(heavy_params()),
                         heavy_params().conditions.gust_sigma, pilot_options_for("crazyflie2")});
}

// n uniforms in (0, 1), a fixed pattern away from the median (so that every draw moves something).
std::vector<double> uniforms(int n, int offset) {
  std::vector<double> u;
  for (int i = 0; i < n; ++i) u.push_back(0.05 + 0.9 * std::fmod(0.37 * (i + offset), 1.0));
  return u;
}

// The true and observed logged states of `seconds` of a flight at the hover point.
std::vector<LoggedState> hover_flight(const GroundTruth& g, double seconds) {
  auto flight = g.start_flight(uniforms(g.initial_noise_dim(), 0));
  std::vector<LoggedState> states;
  for (int t = 0; t < static_cast<int>(seconds / g.step_seconds()); ++t) {
    flight->step(g.hover_point().controls, uniforms(g.step_noise_dim(), t + 1));
    states.push_back(flight->truth());
    states.push_back(flight->observe());
  }
  return states;
}

TEST(GroundTruthRegistry, ARegisteredGroundTruthIsFoundByNameEverywhere) {
  register_heavy();
  const std::vector<std::string> names = simulator_names();
  ASSERT_GE(names.size(), 4u);
  EXPECT_EQ(names[0], "none");
  EXPECT_EQ(names[1], "xcell");
  EXPECT_EQ(names[2], "crazyflie2");
  EXPECT_NE(std::find(names.begin(), names.end(), "heavy-crazyflie"), names.end());
  EXPECT_NE(ground_truth_list().find("xcell, crazyflie2, heavy-heli, heavy-crazyflie"), std::string::npos);
  EXPECT_EQ(own_gust_sigma("heavy-crazyflie"), 0.3);
  EXPECT_EQ(pilot_options_for("heavy-crazyflie").attitude_command_gain,
            pilot_options_for("crazyflie2").attitude_command_gain);

  GroundTruthSettings settings;
  settings.set_start = true;
  settings.start_p_W = Vec3(1, 2, -3);
  const auto heavy = make_ground_truth("heavy-crazyflie", settings);
  const auto light = make_ground_truth("crazyflie2", settings);
  // Its own parameters: more collective to hold its weight, and the settings' start.
  EXPECT_GT(heavy->hover_point().controls[control_axis::thrust],
            light->hover_point().controls[control_axis::thrust] + 0.05);
  auto held = heavy->start_flight(std::vector<double>(heavy->initial_noise_dim(), 0.5));
  EXPECT_EQ(held->truth()[logged::x], 1);
  EXPECT_EQ(held->truth()[logged::z], -3);
  // The scripted pilot flies it, as the commands would.
  const PilotFlight f = fly_pilot(*heavy, pilot_options_for("heavy-crazyflie"), 20, 3);
  EXPECT_EQ(f.crash, CrashReason::kNone);

  // A vehicle file may name it: the reader checks `simulator` against the registry.
  std::string text = pegasus::read_file(PEGASUS_SOURCE_DIR "/experiments/vehicles/crazyflie2.toml");
  const std::string line = "simulator = \"crazyflie2\"";
  ASSERT_NE(text.find(line), std::string::npos);
  text.replace(text.find(line), line.size(), "simulator = \"heavy-crazyflie\"");
  EXPECT_EQ(pegasus::logs::parse_vehicle(text, "heavy.toml").simulator, "heavy-crazyflie");

  // Registering it again replaces it in place; "none" and a nameless entry are refused.
  register_heavy();
  const std::vector<std::string> again = simulator_names();
  EXPECT_EQ(again.size(), names.size());
  EXPECT_EQ(std::count(again.begin(), again.end(), "heavy-crazyflie"), 1);
  EXPECT_THROW(register_ground_truth({"none", "", ground_truth_factory<Quadrotor>(QuadrotorParams{}), 0, {}}),
               std::invalid_argument);
  EXPECT_THROW(register_ground_truth({"blimp", "", nullptr, 0, {}}), std::invalid_argument);
  try {
    make_ground_truth("zeppelin", settings);
    ADD_FAILURE() << "zeppelin was made";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no ground truth named 'zeppelin' (registered: xcell, crazyflie2"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(own_gust_sigma("zeppelin"), std::invalid_argument);
}

TEST(GroundTruthRegistry, TheBuiltInsAreTheirModelsBuiltByHand) {
  GroundTruthSettings settings;
  settings.gust_sigma = 0.7;
  settings.start_pos_sigma = 0.2;
  settings.mean_wind_W = Vec3(1, 0, 0);
  AircraftParams a;
  a.conditions.gust_sigma = 0.7;
  a.conditions.start_pos_sigma = 0.2;
  a.conditions.mean_wind_W = Vec3(1, 0, 0);
  QuadrotorParams q;
  q.conditions.gust_sigma = 0.7;
  q.conditions.start_pos_sigma = 0.2;
  q.conditions.mean_wind_W = Vec3(1, 0, 0);
  EXPECT_EQ(hover_flight(*make_ground_truth("xcell", settings), 1), hover_flight(Aircraft(a), 1));
  EXPECT_EQ(hover_flight(*make_ground_truth("crazyflie2", settings), 1), hover_flight(Quadrotor(q), 1));
  EXPECT_EQ(own_gust_sigma("xcell"), AircraftParams{}.conditions.gust_sigma);
  EXPECT_EQ(own_gust_sigma("crazyflie2"), QuadrotorParams{}.conditions.gust_sigma);
  EXPECT_EQ(pilot_options_for("xcell").k_att, PilotOptions{}.k_att);
  EXPECT_EQ(pilot_options_for("crazyflie2").k_att, 0);
  // Settings the aircraft rejects: one message naming the aircraft.
  settings.set_start = true;
  settings.start_p_W = Vec3(0, 0, 1);
  EXPECT_THROW(make_ground_truth("xcell", settings), std::invalid_argument);
}

// Each ground truth's hand-tuned baseline comes from its entry: a name and gains per aircraft, and a ground
// truth registered without one has none, with a message naming those that have.
TEST(GroundTruthRegistry, EachBaselineComesFromItsGroundTruthsEntry) {
  register_heavy();
  EXPECT_EQ(baseline_name("xcell"), "linear");
  EXPECT_EQ(baseline_name("crazyflie2"), "cascaded-pd");
  EXPECT_EQ(baseline_name("heavy-heli"), "linear");
  EXPECT_EQ(baseline_gains("crazyflie2").law.k_att, 0);  // angle mode: the tilt set point is the command
  EXPECT_EQ(baseline_gains("xcell").law.k_alt, 0.4);
  EXPECT_EQ(baseline_gains("heavy-heli").law.k_alt, 1.1);  // tuned on its own aircraft
  EXPECT_EQ(baseline_gains("heavy-heli").law.k_att, baseline_gains("xcell").law.k_att);
  try {
    baseline_name("heavy-crazyflie");
    ADD_FAILURE() << "heavy-crazyflie has a baseline";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(
        std::string(e.what()),
        "no baseline for the ground truth 'heavy-crazyflie' (baselines: xcell, crazyflie2, heavy-heli)");
  }
  EXPECT_THROW(baseline_gains("heavy-crazyflie"), std::invalid_argument);
  EXPECT_THROW(baseline_name("zeppelin"), std::invalid_argument);
}

// The second helicopter is another aircraft, not the X-Cell renamed: heavier (more collective to hover), in
// its own stronger gusts, seen through a coarser state estimate.
TEST(GroundTruthRegistry, TheHeavyHelicopterIsAnotherAircraft) {
  const auto xcell = make_ground_truth("xcell", {});
  const auto heavy = make_ground_truth("heavy-heli", {});
  EXPECT_GT(heavy->hover_point().controls[2], xcell->hover_point().controls[2] + 0.1);  // a3, the collective
  EXPECT_EQ(own_gust_sigma("heavy-heli"), 2 * own_gust_sigma("xcell"));
  // The RMS of the estimate's position error over 20 s at the hover point, calm (the estimate errors alone).
  GroundTruthSettings calm;
  calm.gust_sigma = 0;
  const auto rms_estimate_error = [](const GroundTruth& g) {
    const std::vector<LoggedState> s = hover_flight(g, 20);
    double sum = 0;
    std::size_t steps = 0;  // hover_flight's rows come in pairs: the truth, then the estimate
    for (std::size_t i = 0; i + 1 < s.size(); i += 2, ++steps)
      for (const int k : {logged::x, logged::y, logged::z}) sum += std::pow(s[i + 1][k] - s[i][k], 2);
    return std::sqrt(sum / static_cast<double>(steps));
  };
  const double heavy_error = rms_estimate_error(*make_ground_truth("heavy-heli", calm));
  const double xcell_error = rms_estimate_error(*make_ground_truth("xcell", calm));
  EXPECT_GT(heavy_error, 2.5 * xcell_error) << heavy_error << " against " << xcell_error;
}

}  // namespace
