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

TEST(Verdict, NoneWithoutTheFiguresOrForAnotherCommand) {
  EXPECT_EQ(verdict("heli fly", {{"flights", 30}}), "");
  EXPECT_EQ(verdict("dev count", {{"steps", 3}}), "");
  EXPECT_EQ(verdict("heli fly", json::array()), "");
}

}  // namespace
