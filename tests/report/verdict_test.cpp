// The verdicts reports open with (include/pegasus/report/verdict.hpp): made from summaries with known
// figures, each sentence carries the right ones.
#include "pegasus/report/verdict.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

namespace {

using json = nlohmann::json;
using pegasus::report::verdict;

json fly_summary() {
  return {{"flights", 30},
          {"crashes", 0},
          {"rms_position_m", 0.446},
          {"rms_velocity_mps", 0.178},
          {"pilot", {{"flights", 30}, {"crashes", 2}, {"rms_position_m", 0.739}}}};
}

TEST(Verdict, FlightsAgainstThePilot) {
  EXPECT_EQ(verdict("heli fly", fly_summary()),
            "30 flights, no crash; 40% closer to the set point than the scripted pilot (RMS position 0.446 m "
            "against 0.739 m; the pilot: 2 crashes)");
  json worse = fly_summary();
  worse["rms_position_m"] = 1.1085;  // 1.5 times the pilot's
  worse["crashes"] = 1;
  worse["pilot"]["crashes"] = 1;
  EXPECT_EQ(
      verdict("heli fly", worse),
      "30 flights, 1 crash; 50% farther from the set point than the scripted pilot (RMS position 1.11 m "
      "against 0.739 m)");
  json alone = fly_summary();
  alone.erase("pilot");
  EXPECT_EQ(verdict("heli fly", alone), "30 flights, no crash; RMS distance from the set point 0.446 m");
}

TEST(Verdict, APipelineSaysItsFlightsAndItsTraining) {
  json s = fly_summary();
  s["hover"] = {{"initial_uhat", -1920.95}, {"final_uhat", -1390.74}};
  EXPECT_EQ(verdict("heli pipeline", s),
            verdict("heli fly", fly_summary()) + "; hover training U-hat -1920.95 -> -1390.74");
}

TEST(Verdict, IdentifyNamesTheOutputWhoseBandsAreTooNarrow) {
  const json s = {{"noise", "white"},
                  {"outside_2sigma_by_horizon",
                   {{"0.5", {{"roll", 0.05}, {"zdot_b", 0.05}, {"pitch_rate", 0.10}}},
                    {"1", {{"roll", 0.04}, {"zdot_b", 0.30}, {"pitch_rate", 0.06}}},
                    {"2", {{"roll", 0.0}, {"zdot_b", 0.414}, {"pitch_rate", 0.05}}}}}};
  EXPECT_EQ(verdict("heli identify", s),
            "the noise bands are too narrow for zdot_b at 1-2 s: up to 41% outside 2 sd (3-7% expected), and "
            "for 1 more output; see --noise ar1+measurement --calibrate-noise");
  json calibrated = s;
  calibrated["noise"] = "ar1+measurement";
  calibrated["noise_scale"] = json::object();
  const std::string text = verdict("heli identify", calibrated);
  EXPECT_EQ(text.find("; see"), std::string::npos) << text;
  const json honest = {{"outside_2sigma_by_horizon", {{"1", {{"roll", 0.05}, {"yaw", 0.0}}}}}};
  EXPECT_EQ(verdict("heli identify", honest),
            "the noise bands hold or are wide: 1 of 2 cells of the hold-out check within 3-7% outside 2 sd, "
            "none above");
}

TEST(Verdict, TrainingAndOtherCommands) {
  EXPECT_EQ(
      verdict("heli hover", {{"initial_uhat", -1920.954},
                             {"final_uhat", -1390.741},
                             {"iterations", 13},
                             {"evaluations", 291},
                             {"starting_policy", {{"crashed_scenarios", 3}, {"scenarios", 12}}}}),
      "hover training: U-hat -1920.95 -> -1390.74 in 13 iterations (291 evaluations); the starting policy "
      "crashed in 3 of 12 scenarios");
  EXPECT_EQ(verdict("heli pilot", {{"seconds", 200.0}, {"crashed", false}}),
            "the pilot flew 200 s without a crash");
  EXPECT_EQ(verdict("heli pilot",
                    {{"seconds", 200.0}, {"crashed", true}, {"crash_time", 12.5}, {"crash_reason", "tilt"}}),
            "the pilot crashed after 12.5 s (tilt)");
  EXPECT_EQ(verdict("horizon", {{"horizon", 51}}), "a horizon of 51 steps");
  EXPECT_EQ(verdict("mujoco train", {{"initial_uhat", -10.0},
                                     {"final_uhat", 250.5},
                                     {"evaluation", {{"success_rate", 0.75}, {"mean_return", 240.25}}}}),
            "U-hat -10 -> 250.5; the policy succeeds in 75% of the evaluation episodes (mean return 240.2)");
  EXPECT_EQ(verdict("mujoco rollout",
                    {{"evaluation", {{"episodes", 8}, {"mean_return", 12.5}, {"success_rate", nullptr}}}}),
            "8 episodes, mean return 12.5");
}

TEST(Verdict, BicycleShapingAndManoeuvres) {
  EXPECT_EQ(
      verdict("bicycle ride", {{"rides", 50}, {"reached", 47}, {"falls", 3}, {"median_distance_km", 1.0712}}),
      "47 of 50 rides reached the goal, 3 fell; median distance to it 1.07 km");
  EXPECT_EQ(verdict("bicycle train", {{"initial_uhat", -80.5},
                                      {"final_uhat", -12.25},
                                      {"rides", {{"rides", 2}, {"reached", 1}, {"falls", 1}}}}),
            "U-hat -80.5 -> -12.25; 1 of 2 rides reached the goal, 1 fell");
  EXPECT_EQ(verdict("bicycle experiment", {{"rides", 50},
                                           {"median_of_medians_km", 1.2},
                                           {"policies", json::array({{{"reached", 50}, {"falls", 0}},
                                                                     {{"reached", 40}, {"falls", 10}}})}}),
            "2 policies: 90 of 100 rides reached the goal, 10 fell; median of the policies' median distances "
            "1.2 km");
  EXPECT_EQ(verdict("bicycle variance", {{"uhat_std", {{"plain", 2.5}, {"sobol", 0.75}}}}),
            "sd of U-hat over scenario sets: plain 2.5, sobol 0.75");
  EXPECT_EQ(verdict("shaping audit", {{"potential_based", true}, {"max_residual", 2e-12}}),
            "F is potential-based (largest residual 2e-12): it keeps the optimal policy");
  EXPECT_EQ(
      verdict("shaping audit", {{"potential_based", false}, {"counterexample", json::object()}}),
      "F is not potential-based: a counterexample MDP whose optimal policy it changes is in the report");
  EXPECT_EQ(verdict("shaping progress-bonus",
                    {{"progress_bonus", {{"reaches_goal", false}}}, {"potential", {{"reaches_goal", true}}}}),
            "the greedy policy learned with the progress bonus cycles and never reaches the goal; with its "
            "potential-based version it reaches the goal");
  EXPECT_EQ(
      verdict("heli maneuver",
              {{"maneuver", "III.1"}, {"flights", 20}, {"crashes", 0}, {"rms_path_deviation_m", 0.512}}),
      "III.1: 20 flights, no crash; RMS deviation from the path 0.512 m");
  EXPECT_EQ(verdict("shaping gridworld",
                    {{"curves", json::array({{{"potential", "none"}, {"trials_to_within_25pct", nullptr}},
                                             {{"potential", "phi0"}, {"trials_to_within_25pct", 12}}})}}),
            "trials until within 25% of the optimal steps: none never, phi0 12");
  EXPECT_EQ(
      verdict("pendulum train", {{"mean_return_100", -150.5}, {"bar", -200}, {"evaluations_to_bar", 840}}),
      "mean return over 100 episodes -150.5, at or above the bar of -200 (reached after 840 U-hat "
      "evaluations)");
  // The vehicle commands without the heli prefix say the same.
  EXPECT_EQ(verdict("fly", fly_summary()), verdict("heli fly", fly_summary()));
}

TEST(Verdict, PomdpGridworldSaysHowCloseToTheBestInClassAndAgainstMonteCarlo) {
  const auto row = [](const char* model, const char* estimator, int m, double value) {
    return json{{"model", model}, {"estimator", estimator}, {"m", m}, {"mean_true_value", value}};
  };
  // The figures of docs/results/thesis.md (Fig 4.5b), in the order the command writes them.
  const json s = {
      {"best_in_class_value", -9.409},
      {"results",
       json::array({row("normal", "pegasus", 1, -18.24), row("normal", "pegasus", 16, -9.685),
                    row("normal", "pegasus", 64, -9.45), row("hashed", "pegasus", 64, -9.5),
                    row("normal", "montecarlo", 1, -25.3), row("normal", "montecarlo", 16, -10.37)})}};
  EXPECT_EQ(
      verdict("pomdp-gridworld", s),
      "the policy PEGASUS picks with m = 64 scenarios is worth -9.45 (exact), 0.041 below the best in the "
      "class (-9.409); with m = 1, 8.83 below; at m = 16 naive Monte Carlo's pick is worth -10.37, 0.685 "
      "below PEGASUS's");
  json better = s;  // Monte Carlo's pick better at the largest common m (as at m = 4 in the thesis run)
  better["results"][5]["mean_true_value"] = -9.5;
  const std::string text = verdict("pomdp-gridworld", better);
  EXPECT_NE(text.find("worth -9.5, 0.185 above PEGASUS's"), std::string::npos) << text;
  json alone = s;
  alone["results"] = json::array({row("normal", "pegasus", 8, -10.18)});
  EXPECT_EQ(
      verdict("pomdp-gridworld", alone),
      "the policy PEGASUS picks with m = 8 scenarios is worth -10.18 (exact), 0.771 below the best in the "
      "class (-9.409)");
}

json imported_summary() {
  return {{"vehicle", "auav-x2"},
          {"seconds", 68.84},
          {"rate_hz", 50},
          {"dropouts", 4},
          {"dropout_total_ms", 119.0},
          {"truncated_at_byte", nullptr},
          {"constant_controls", json::array({"a3"})},
          {"prediction",
           {{"horizons_s", json::array({0.5, 1, 2})},
            {"rmse",
             {{"identified", {{"0.5", {{"z", 0.035}, {"roll", 0.034}, {"roll_rate", 1.9}}}}},
              {"constant_velocity",
               {{"0.5", {{"z", 0.032}, {"roll", 5.4e-5}, {"roll_rate", 5.4e-4}}},
                {"1", {{"z", 0.065}, {"roll", 9e-5}, {"roll_rate", 5e-4}}}}}}}}}};
}

TEST(Verdict, LogImportComparesTheIdentifiedModelWithHoldingTheVelocity) {
  EXPECT_EQ(
      verdict("log import", imported_summary()),
      "imported 68.8 s at 50 Hz for auav-x2, 4 dropouts (119 ms), 1 control never moved; 0.5 s ahead on "
      "the hold-out part the identified model beats a constant-velocity guess on 0 of 3 variables: this "
      "log does not identify the aircraft's dynamics (its fit turned singular before the 2 longer "
      "horizons)");
  json good = imported_summary();
  good["constant_controls"] = json::array();
  good["dropouts"] = 0;
  good["truncated_at_byte"] = 4096;
  good["prediction"]["rmse"]["identified"]["1"] = {{"z", 0.01}, {"roll", 1e-5}, {"roll_rate", 0.1}};
  EXPECT_EQ(verdict("log import", good),
            "imported 68.8 s at 50 Hz for auav-x2, no dropout, the file cut at byte 4096; 1 s ahead on the "
            "hold-out part the identified model beats a constant-velocity guess on 2 of 3 variables (its fit "
            "turned singular before the 1 longer horizon)");
  json only = imported_summary();
  only.erase("prediction");  // --identify=false
  EXPECT_EQ(verdict("log import", only),
            "imported 68.8 s at 50 Hz for auav-x2, 4 dropouts (119 ms), 1 control never moved");
}

TEST(Verdict, ExportAndTheManoeuvrePilot) {
  json c = {{"class", "hover"}, {"act_function", "pegasus_policy_act"}, {"observation_size", 13},
            {"action_size", 4}, {"header_file", "pegasus_policy.h"},    {"source_file", "pegasus_policy.c"}};
  EXPECT_EQ(verdict("export", c),
            "C99 code of the hover policy: pegasus_policy_act maps 13 observations to 4 actions "
            "(pegasus_policy.h, pegasus_policy.c); compiled with -ffp-contract=off it gives the C++ policy's "
            "bits; it keeps no state");
  c["memory_type"] = "pegasus_policy_memory";
  c["reset_function"] = "pegasus_policy_reset";
  c["vehicle"] = "outside";
  c["vehicle_act_function"] = "pegasus_policy_act_vehicle";
  c["vehicle_observation_names"] = json::array({"n", "e", "d"});
  const std::string text = verdict("export", c);
  EXPECT_NE(
      text.find("; it keeps state in pegasus_policy_memory: call pegasus_policy_reset before each flight; "
                "pegasus_policy_act_vehicle takes the time and outside's own state fields (3 numbers)"),
      std::string::npos)
      << text;
  const json flown = {{"seconds", 123.46}, {"rows", 6173}, {"crashed", false}};
  EXPECT_EQ(verdict("heli maneuver-pilot", flown),
            "the pilot flew 123.5 s of hover, sweeps and manoeuvres without a crash: 6173 rows of "
            "identification data that cover the manoeuvres");
  EXPECT_EQ(verdict("maneuver-pilot", flown), verdict("heli maneuver-pilot", flown));
  EXPECT_EQ(
      verdict("maneuver-pilot", {{"seconds", 40.0},
                                 {"rows", 2000},
                                 {"crashed", true},
                                 {"crash_time", 38.5},
                                 {"crash_reason", "tilt"}}),
      "the pilot crashed after 38.5 s (tilt): the log stops before the manoeuvres it did not fly; try a "
      "smaller --sweep-scale or --gust-sigma");
  // heli control serves a policy on stdin/stdout and writes no run directory: no report, no verdict.
  EXPECT_EQ(verdict("heli control", flown), "");
}

TEST(Verdict, NoneWithoutTheFiguresOrForAnotherCommand) {
  EXPECT_EQ(verdict("heli fly", {{"flights", 30}}), "");
  EXPECT_EQ(verdict("dev count", {{"steps", 3}}), "");
  EXPECT_EQ(verdict("heli fly", json::array()), "");
}

}  // namespace
