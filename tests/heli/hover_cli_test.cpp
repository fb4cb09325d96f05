// End-to-end tests of `pegasus heli hover`, `heli fly` and `heli control` through the built CLI, on a model
// identified from a one-minute pilot flight and tiny training settings.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "pegasus/io/json_csv.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "support/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using pegasus::test_support::read_text;
using pegasus::test_support::run_pegasus;

// A model.json shared by every test of this file (a pilot flight and a small identification, ~2 s).
class HoverCli : public pegasus::test_support::TempDirTest {
 protected:
  static void SetUpTestSuite() {
    shared_ = fs::temp_directory_path() / ("pegasus-HoverCli-model-" + std::to_string(::getpid()));
    fs::remove_all(shared_);
    auto r = run_pegasus("heli pilot --seconds 60 --hover-seconds 4 --seed 3 --quiet --out " +
                         (shared_ / "train").string());
    ASSERT_EQ(r.code, 0) << r.output;
    r = run_pegasus("heli identify --train " + (shared_ / "train" / "log.csv").string() + " --test " +
                    (shared_ / "train" / "log.csv").string() +
                    " --cv-points 40 --scale-grid 2,4 --coordinate-passes 0 --horizon-s 2 --variants=false "
                    "--quiet --out " +
                    (shared_ / "id").string());
    ASSERT_EQ(r.code, 0) << r.output;
  }
  static void TearDownTestSuite() { fs::remove_all(shared_); }
  static std::string model() { return (shared_ / "id" / "model.json").string(); }
  std::string out(const std::string& name) const { return " --out " + (dir_ / name).string(); }
  static std::string tiny() {
    const bool asan = std::getenv("PEGASUS_SANITIZED") != nullptr;
    return fmt::format(
        " --quiet --scenarios 2 --seconds {} --optimizer.gradient.max-iterations 1 "
        "--optimizer.hill-climbing.max-iterations 2 --optimizer.hill-climbing.proposals-per-iteration 2",
        asan ? 1 : 3);
  }
  // A trained policy file in dir_/hover.
  std::string train() {
    const auto r = run_pegasus("heli hover --model " + model() + tiny() + out("hover"));
    EXPECT_EQ(r.code, 0) << r.output;
    return (dir_ / "hover" / "policy.json").string();
  }
  static fs::path shared_;
};
fs::path HoverCli::shared_;

nlohmann::json json_file(const fs::path& p) { return nlohmann::json::parse(read_text(p)); }

// progress.csv without its wall-time column.
std::string objective_column(const fs::path& p) {
  std::string out;
  for (const auto& row : pegasus::parse_csv(read_text(p))) out += row[0] + "," + row[1] + "," + row[3] + "\n";
  return out;
}

TEST_F(HoverCli, HoverWritesPolicyProgressAndSummary) {
  const std::string policy = train();
  const auto s = json_file(dir_ / "hover" / "summary.json");
  for (const char* key :
       {"initial_uhat", "final_uhat", "iterations", "evaluations", "gradient", "hill_climb", "policy"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_GE(s.at("final_uhat").get<double>(), s.at("initial_uhat").get<double>());
  EXPECT_EQ(s.at("starting_policy").at("scenarios"), 2);
  EXPECT_EQ(s.at("starting_policy").at("crashed_scenarios"), 0);
  const std::string progress = read_text(dir_ / "hover" / "progress.csv");
  EXPECT_EQ(progress.substr(0, progress.find('\n')), "iteration,evaluations,seconds,objective");
  EXPECT_EQ(std::count(progress.begin(), progress.end(), '\n'), 1 + 1 + 2);
  const auto p = json_file(policy);
  EXPECT_EQ(p.at("format"), "pegasus-heli-policy");
  EXPECT_EQ(p.at("version"), 1);
  EXPECT_EQ(p.at("class"), "hover");
  EXPECT_EQ(p.at("parameters").size(), 34u);
  EXPECT_EQ(p.at("parameters")[0].at("name"), "a1.bias");
  EXPECT_TRUE(p.at("target").contains("yaw"));
  EXPECT_TRUE(p.at("trim").contains("a4"));
}

// Issues 48/53: where stderr is no terminal (here a pipe), hover prints a line on the clock between optimizer
// iterations (an iteration at 25 Hz took minutes): the count of evaluations and the best U-hat so far. The
// interval is forced short; --quiet prints none, and the lines change nothing in summary.json.
TEST_F(HoverCli, ANonTerminalRunPrintsProgressLinesOnTheClock) {
  const std::string budget =
      " --scenarios 2 --seconds 3 --optimizer.gradient.max-iterations 1 "
      "--optimizer.hill-climbing.max-iterations 2 "
      "--optimizer.hill-climbing.proposals-per-iteration 2";
  const auto r =
      pegasus::test_support::run_shell("PEGASUS_PROGRESS_INTERVAL_S=0.01 " + std::string(PEGASUS_CLI_PATH) +
                                       " heli hover --model " + model() + budget + out("ticked"));
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string line = "hover training: ";
  EXPECT_NE(r.output.find(line + "0 of 3 optimizer iterations done, "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" U-hat evaluations, best U-hat evaluated -"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" elapsed\n"), std::string::npos) << r.output;
  const auto quiet =
      pegasus::test_support::run_shell("PEGASUS_PROGRESS_INTERVAL_S=0.01 " + std::string(PEGASUS_CLI_PATH) +
                                       " heli hover --model " + model() + budget + " --quiet" + out("quiet"));
  ASSERT_EQ(quiet.code, 0) << quiet.output;
  EXPECT_EQ(quiet.output.find(" optimizer iterations done, "), std::string::npos) << quiet.output;
  EXPECT_EQ(read_text(dir_ / "ticked" / "summary.json"), read_text(dir_ / "quiet" / "summary.json"));
}

// The same for identify: which part of the identification runs.
TEST_F(HoverCli, ANonTerminalIdentifyPrintsWhatItIsDoingOnTheClock) {
  const std::string log = (shared_ / "train" / "log.csv").string();
  const auto r = pegasus::test_support::run_shell(
      "PEGASUS_PROGRESS_INTERVAL_S=0.01 " + std::string(PEGASUS_CLI_PATH) + " heli identify --train " + log +
      " --test " + log +
      " --cv-points 40 --scale-grid 2,4 --coordinate-passes 0 --horizon-s 2 --variants=false" +
      out("identify"));
  ASSERT_EQ(r.code, 0) << r.output;
  // Which parts a line catches depends on the clock; that one names what runs and the time does not.
  const auto at = r.output.find("identify: the ");
  ASSERT_NE(at, std::string::npos) << r.output;
  EXPECT_NE(r.output.find(" elapsed\n", at), std::string::npos) << r.output;
}

TEST_F(HoverCli, APhaseIsReportedUnderItsOwnMethod) {
  const auto r =
      run_pegasus("heli hover --model " + model() + tiny() + " --optimizer.method hill-climb" + out("climb"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = json_file(dir_ / "climb" / "summary.json");
  EXPECT_TRUE(s.at("gradient").is_null()) << s.dump();
  EXPECT_EQ(s.at("hill_climb").at("method"), "hill-climb");
  EXPECT_EQ(s.at("hill_climb").at("iterations"), 2);
  EXPECT_EQ(s.at("hill_climb").at("best_uhat"), s.at("final_uhat"));
}

TEST_F(HoverCli, AStartingPolicyThatCrashesTheModelStopsTrainingWithOneLine) {
  // Starts at about 30 m/s, far outside the minute of logs the model was identified from: the learned model
  // crashes (no training point within 4 bandwidths) before any optimizer could learn from a rollout.
  const std::string args = "heli hover --model " + model() + tiny() + " --start-vel-sigma 30";
  const auto r = run_pegasus(args + out("refused"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(
      r.output.find("hover training: the starting policy crashes the learned model in 2 of 2 scenarios"),
      std::string::npos)
      << r.output;
  // One error line; before it only the line that names the reward's terms (said before training starts).
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 2) << r.output;
  EXPECT_NE(r.output.find("reward ("), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("pegasus:"), r.output.rfind("pegasus:")) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "refused"));
  EXPECT_FALSE(fs::exists(dir_ / "refused.partial"));
  // Asked to go on, it trains and says what it saw.
  const auto forced = run_pegasus(args + " --max-start-crash-fraction 1" + out("forced"));
  ASSERT_EQ(forced.code, 0) << forced.output;
  EXPECT_NE(forced.output.find("warning: the starting policy crashes the learned model in 2 of 2 scenarios"),
            std::string::npos)
      << forced.output;
  const auto s = json_file(dir_ / "forced" / "summary.json");
  EXPECT_EQ(s.at("starting_policy").at("crashed_scenarios"), 2);
  // The same starting weights on the same scenarios: the refusal and the summary tell the same crash time,
  // a whole number of 0.02 s steps after the start.
  const double crash_s = s.at("starting_policy").at("mean_seconds_to_crash").get<double>();
  EXPECT_GT(crash_s, 0.0);
  EXPECT_NEAR(std::remainder(2 * crash_s, 0.02), 0.0, 1e-9);  // the mean of 2 step counts
  EXPECT_NE(r.output.find(fmt::format("(after {:.2f} s on average)", crash_s)), std::string::npos)
      << r.output;
}

TEST_F(HoverCli, RewardTermsForAttitudeAndRatesChangeTheObjectiveAndZeroTypicalSizesAreChecked) {
  const std::string args = "heli hover --model " + model() + tiny();
  ASSERT_EQ(run_pegasus(args + out("plain")).code, 0);
  ASSERT_EQ(run_pegasus(args + " --reward.attitude-rad 0.05 --reward.rate-radps 0.2" + out("priced")).code,
            0);
  // The same starting weights on the same scenarios, charged for their attitude and rates too.
  EXPECT_LT(json_file(dir_ / "priced" / "summary.json").at("initial_uhat").get<double>(),
            json_file(dir_ / "plain" / "summary.json").at("initial_uhat").get<double>());
  ASSERT_EQ(run_pegasus(args + " --reward.action 0" + out("free")).code, 0);
  EXPECT_GT(json_file(dir_ / "free" / "summary.json").at("initial_uhat").get<double>(),
            json_file(dir_ / "plain" / "summary.json").at("initial_uhat").get<double>());
  const auto tiny_scale = run_pegasus(args + " --reward.rate-radps 1e-7" + out("bad"));
  EXPECT_EQ(tiny_scale.code, 2);
  EXPECT_NE(tiny_scale.output.find("reward.rate"), std::string::npos) << tiny_scale.output;
  EXPECT_NE(tiny_scale.output.find("0 or at least 1e-06"), std::string::npos) << tiny_scale.output;
}

TEST_F(HoverCli, HoverIsTheSameForOneAndTwoThreads) {
  const std::string args = "heli hover --model " + model() + tiny();
  ASSERT_EQ(run_pegasus(args + " --threads 1" + out("t1")).code, 0);
  ASSERT_EQ(run_pegasus(args + " --threads 2" + out("t2")).code, 0);
  EXPECT_EQ(read_text(dir_ / "t1" / "policy.json"), read_text(dir_ / "t2" / "policy.json"));
  EXPECT_EQ(objective_column(dir_ / "t1" / "progress.csv"), objective_column(dir_ / "t2" / "progress.csv"));
}

// SIGKILL after the first checkpoint, then --resume: the policy equals an uninterrupted run's.
TEST_F(HoverCli, KilledTrainingResumesToTheSamePolicy) {
  const std::string args = "heli hover --model " + model() +
                           " --quiet --scenarios 2 --seconds 2 --optimizer.gradient.max-iterations 2 "
                           "--optimizer.hill-climbing.max-iterations 30 "
                           "--optimizer.hill-climbing.proposals-per-iteration 2 --threads 1";
  ASSERT_EQ(run_pegasus(args + out("whole")).code, 0);
  const fs::path target = dir_ / "killed";
  // 31 iterations remain after the first checkpoint, so the kill lands mid-run.
  ASSERT_EQ(pegasus::test_support::kill_pegasus_after_first_checkpoint(args, target),
            pegasus::test_support::KillOutcome::kKilled)
      << "the run left no checkpoint or finished before it could be killed";
  const auto resumed = run_pegasus(args + " --resume" + out("killed"));
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  EXPECT_EQ(read_text(dir_ / "whole" / "policy.json"), read_text(target / "policy.json"));
  EXPECT_EQ(objective_column(dir_ / "whole" / "progress.csv"), objective_column(target / "progress.csv"));
}

TEST_F(HoverCli, FlyWritesTheDocumentedSummaryAndTraces) {
  const std::string policy = train();
  const auto r = run_pegasus("heli fly --quiet --policy " + policy +
                             " --compare-pilot --flights 3 --seconds 3 --trace-flights 2" + out("fly"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = json_file(dir_ / "fly" / "summary.json");
  for (const auto* j : {&s, &s.at("pilot")}) {
    for (const char* key : {"flights", "crashes", "rms_position_m", "rms_velocity_mps", "rms_yaw_rad"})
      EXPECT_TRUE(j->contains(key)) << key;
    EXPECT_EQ(j->at("flights"), 3);
    EXPECT_GT(j->at("rms_position_m").get<double>(), 0.0);
  }
  for (const char* file : {"flights.csv", "pilot_flights.csv"}) {
    const std::string text = read_text(dir_ / "fly" / file);
    EXPECT_EQ(
        text.substr(0, text.find('\n')),
        "flight,t,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate,a1,a2,a3,a4,target_x,"
        "target_y,target_z,target_yaw,xdot_b,ydot_b,zdot_b")
        << file;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1 + 2 * 150) << file;
    // The body-frame velocities (Fig 5.6) are R_WB^T v_W of the same row, the one transform of frames.hpp.
    const auto rows = pegasus::parse_csv(text);
    for (std::size_t row : {std::size_t{1}, std::size_t{77}, rows.size() - 2}) {
      auto cell = [&](std::size_t c) { return std::stod(rows[row][c]); };
      const pegasus::heli::Vec3 v_B =
          pegasus::heli::body_from_world({cell(5), cell(6), cell(7)}, {cell(8), cell(9), cell(10)});
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(cell(22 + static_cast<std::size_t>(k)), v_B[k], 1e-12) << file << row;
    }
  }
  for (const char* file :
       {"position_x.svg", "altitude.svg", "velocity_xb.svg", "velocity_zb.svg", "per_flight.csv"})
    EXPECT_TRUE(fs::exists(dir_ / "fly" / file)) << file;
  const auto p = run_pegasus("heli fly --quiet --pilot --flights 2 --seconds 2" + out("pilot"));
  ASSERT_EQ(p.code, 0) << p.output;
  const auto ps = json_file(dir_ / "pilot" / "summary.json");
  EXPECT_EQ(ps.at("controller"), "pilot");
  EXPECT_EQ(ps.at("flights"), 2);
}

// The integral term end to end: hover writes its weights, integrator and summary; fly flies it in a steady
// wind (said in the summary) with its memory, and it ends closer to the set point than the thesis's class.
TEST_F(HoverCli, TheIntegralTermIsTrainedWrittenAndFlownInASteadyWind) {
  const std::string without = train();
  auto r = run_pegasus("heli hover --model " + model() + tiny() + " --integral-seconds 5" + out("integral"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = json_file(dir_ / "integral" / "summary.json");
  ASSERT_TRUE(s.contains("integral")) << s.dump();
  EXPECT_EQ(s.at("integral").at("integral_seconds"), 5.0);
  EXPECT_EQ(s.at("integral").at("limit_position"), 50.0);
  EXPECT_FALSE(json_file(dir_ / "hover" / "summary.json").contains("integral"));  // off: as before
  const std::string with = (dir_ / "integral" / "policy.json").string();
  const auto p = json_file(with);
  ASSERT_EQ(p.at("parameters").size(), 38u);
  EXPECT_EQ(p.at("parameters")[37].at("name"), "a4.int");
  EXPECT_EQ(s.at("integral").at("a4"), p.at("parameters")[37].at("value"));
  EXPECT_EQ(p.at("options").at("integral").at("dt"), 0.02);
  // 20 s in a 4.5 m/s wind without gusts: the integral has time to lean into it.
  const std::string fly = " --quiet --flights 2 --seconds 20 --gust-sigma 0 --wind 4,2,0 --policy ";
  r = run_pegasus("heli fly" + fly + with + out("fly-with"));
  ASSERT_EQ(r.code, 0) << r.output;
  r = run_pegasus("heli fly" + fly + without + out("fly-without"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto flown_with = json_file(dir_ / "fly-with" / "summary.json"),
             flown_without = json_file(dir_ / "fly-without" / "summary.json");
  EXPECT_EQ(flown_with.at("wind"), (std::vector<double>{4, 2, 0}));
  EXPECT_EQ(flown_with.at("crashes"), 0);
  EXPECT_LT(flown_with.at("rms_position_m").get<double>(),
            0.7 * flown_without.at("rms_position_m").get<double>());
  r = run_pegasus("heli fly --quiet --wind 4,2 --policy " + with + out("bad-wind"));
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("wind"), std::string::npos) << r.output;
}

// A controller for a flight computer that runs it at 10 Hz: trained on the learned model stepping at 10 Hz
// (refit every step from the 10 Hz model), its policy file says so, and `heli fly` calls it every fifth 50 Hz
// step of the aircraft, holding its controls in between; a rate that does not divide 50 Hz is refused.
TEST_F(HoverCli, AControllerTrainedAt10HzIsFlownAt10Hz) {
  const auto r =
      run_pegasus("heli hover --model " + model() + tiny() + " --control-rate-hz 10" + out("hover10"));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(r.output.find("warning: the controller's step"), std::string::npos) << r.output;
  const auto s = json_file(dir_ / "hover10" / "summary.json");
  EXPECT_EQ(s.at("control_rate_hz"), 10.0);
  EXPECT_EQ(s.at("refit_every"), 1);
  // Slower than the 10 Hz model, each control step is one model step's change stretched: said, not refused.
  const auto slow = run_pegasus("heli hover --model " + model() + tiny() +
                                " --control-rate-hz 5 --max-start-crash-fraction 1" + out("hover5"));
  ASSERT_EQ(slow.code, 0) << slow.output;
  EXPECT_NE(
      slow.output.find("warning: the controller's step (0.2 s) is 2 steps of the 10 Hz model, which takes "
                       "it as one step's change times 2"),
      std::string::npos)
      << slow.output;
  const std::string policy = (dir_ / "hover10" / "policy.json").string();
  EXPECT_EQ(json_file(policy).at("options").at("control_rate_hz"), 10.0);
  // The 50 Hz default writes neither key (files as before).
  const std::string policy50 = train();
  EXPECT_FALSE(json_file(policy50).contains("options"));
  EXPECT_FALSE(json_file(dir_ / "hover" / "summary.json").contains("control_rate_hz"));
  // The same steps at 10 Hz: a 3 s scenario is 30 steps, so the training differs from the 50 Hz one.
  EXPECT_NE(s.at("initial_uhat"), json_file(dir_ / "hover" / "summary.json").at("initial_uhat"));

  const auto f =
      run_pegasus("heli fly --quiet --policy " + policy + " --flights 1 --seconds 2" + out("fly10"));
  ASSERT_EQ(f.code, 0) << f.output;
  const auto rows = pegasus::parse_csv(read_text(dir_ / "fly10" / "flights.csv"));
  ASSERT_EQ(rows.size(), 1u + 100u);
  int changes = 0;
  for (std::size_t t = 2; t < rows.size(); ++t) {
    const bool same = rows[t][14] == rows[t - 1][14] && rows[t][16] == rows[t - 1][16];
    const bool call = (t - 1) % 5 == 0;  // steps 0, 5, 10, ... call the controller
    if (!call) {
      EXPECT_TRUE(same) << "step " << t - 1;
    }
    changes += same ? 0 : 1;
  }
  EXPECT_GT(changes, 15);  // it does act at its calls (19 of them after the first)

  auto j = json_file(policy);
  j["options"]["control_rate_hz"] = 15.0;
  std::ofstream(dir_ / "bad.json") << j.dump();
  const auto bad =
      run_pegasus("heli fly --quiet --policy " + (dir_ / "bad.json").string() + " --flights 1" + out("bad"));
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find("bad.json: options.control_rate_hz: 15 Hz does not divide the aircraft's 50 Hz"),
            std::string::npos)
      << bad.output;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

// --starting-gains lqr starts training from LQR gains on the identified model and says which it used.
TEST_F(HoverCli, LqrStartingGainsAreReportedAndStartTraining) {
  const auto r = run_pegasus("heli hover --model " + model() + tiny() + " --starting-gains lqr" + out("lqr"));
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = json_file(dir_ / "lqr" / "summary.json");
  const auto& g = s.at("starting_gains");
  EXPECT_EQ(g.at("method"), "lqr");
  EXPECT_EQ(g.at("reason"), "");
  EXPECT_LT(g.at("spectral_radius").get<double>(), 1.0);
  // The policy file's starting point is not the constants': the first U-hat differs from the default run's.
  train();
  const auto d = json_file(dir_ / "hover" / "summary.json");
  EXPECT_FALSE(d.contains("starting_gains"));
  EXPECT_NE(s.at("initial_uhat"), d.at("initial_uhat"));
  const auto bad =
      run_pegasus("heli hover --model " + model() + tiny() + " --starting-gains pid" + out("bad"));
  EXPECT_EQ(bad.code, 2);
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

TEST_F(HoverCli, BadPolicyFileExitsTwoNamingFileAndField) {
  const std::string policy = train();
  auto j = json_file(policy);
  j["parameters"][5]["value"] = "oops";
  const fs::path bad = dir_ / "bad.json";
  std::ofstream(bad) << j.dump();
  for (const std::string& command :
       {"heli fly --quiet --flights 1 --seconds 1 --policy " + bad.string() + out("f"),
        "heli control --policy " + bad.string() + " </dev/null"}) {
    const auto r = run_pegasus(command);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_NE(r.output.find(bad.string() + ": parameters[5].value (a1.att): expected a number"),
              std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir_ / "f"));
    EXPECT_FALSE(fs::exists(dir_ / "f.partial"));
  }
  const auto missing = run_pegasus("heli fly --quiet --flights 1" + out("f"));
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.output.find("--policy"), std::string::npos) << missing.output;
  // A set point below the ground (z up, not NED's down): every flight would start there and crash at once.
  j = json_file(policy);
  j["target"]["z"] = 10.0;
  std::ofstream(bad) << j.dump();
  const auto underground =
      run_pegasus("heli fly --quiet --flights 1 --seconds 1 --policy " + bad.string() + out("f"));
  EXPECT_EQ(underground.code, 2) << underground.output;
  EXPECT_NE(underground.output.find(bad.string() + ": target.z = 10 is at or below the ground"),
            std::string::npos)
      << underground.output;
  EXPECT_FALSE(fs::exists(dir_ / "f.partial"));
  // Files that name no vehicle are the built-in X-Cell's: another aircraft's training refuses its model, its
  // flights warn about its policy, and a manoeuvre refuses another aircraft's hover policy (its trim).
  const std::string crazyflie = std::string(PEGASUS_SOURCE_DIR) + "/experiments/vehicles/crazyflie2.toml";
  const auto other_model =
      run_pegasus("hover --vehicle " + crazyflie + " --model " + model() + tiny() + out("q"));
  EXPECT_EQ(other_model.code, 2) << other_model.output;
  EXPECT_NE(
      other_model.output.find("the model was identified from xcell60's logs, and this run is for crazyflie2"),
      std::string::npos)
      << other_model.output;
  const auto other_fly = run_pegasus("fly --vehicle " + crazyflie +
                                     " --flights 1 --seconds 0.1 --quiet --policy " + policy + out("qf"));
  EXPECT_EQ(other_fly.code, 0) << other_fly.output;
  EXPECT_NE(other_fly.output.find("was trained for vehicle 'xcell60'; flying it on 'crazyflie2'"),
            std::string::npos)
      << other_fly.output;
  j = json_file(policy);
  j["provenance"]["vehicle"] = "crazyflie2";
  std::ofstream(bad) << j.dump();
  const auto other_hover = run_pegasus("heli maneuver --name III.2 --model " + model() + " --hover-policy " +
                                       bad.string() + " --quiet" + out("m"));
  EXPECT_EQ(other_hover.code, 2) << other_hover.output;
  EXPECT_NE(other_hover.output.find(
                bad.string() + ": vehicle: the hover policy was trained for 'crazyflie2', and this manoeuvre "
                               "is for 'xcell60'"),
            std::string::npos)
      << other_hover.output;
  EXPECT_FALSE(fs::exists(dir_ / "m"));
  const auto training =
      run_pegasus("heli hover --model " + model() + tiny() + " --target 0,0,10,0" + out("h"));
  EXPECT_EQ(training.code, 2) << training.output;
  // The run's error names the field as the user set it: the option, the config file's line, the vehicle's
  // key.
  EXPECT_NE(training.output.find("pegasus: --target: z = 10 is at or below the ground of xcell60"),
            std::string::npos)
      << training.output;
  EXPECT_FALSE(fs::exists(dir_ / "h"));
  EXPECT_FALSE(fs::exists(dir_ / "h.partial"));
  const fs::path config = dir_ / "underground.toml";
  std::ofstream(config) << "scenarios = 2\ntarget = [0, 0, 10, 0]\n";
  const auto from_config =
      run_pegasus("heli hover --model " + model() + " --config " + config.string() + out("h"));
  EXPECT_EQ(from_config.code, 2) << from_config.output;
  EXPECT_NE(from_config.output.find(config.string() + ":2: key 'target': z = 10 is at or below the ground"),
            std::string::npos)
      << from_config.output;
  std::ifstream shipped(crazyflie);
  std::stringstream text;
  text << shipped.rdbuf();
  std::string vehicle_text = text.str();
  const std::string shipped_target = "target = [0, 0, -2, 0]";
  ASSERT_NE(vehicle_text.find(shipped_target), std::string::npos);
  vehicle_text.replace(vehicle_text.find(shipped_target), shipped_target.size(), "target = [0, 0, 1, 0]");
  const fs::path vehicle = dir_ / "underground_vehicle.toml";
  std::ofstream(vehicle) << vehicle_text;
  const auto from_vehicle =
      run_pegasus("hover --vehicle " + vehicle.string() + " --model " + model() + tiny() + out("h"));
  EXPECT_EQ(from_vehicle.code, 2) << from_vehicle.output;
  EXPECT_NE(from_vehicle.output.find(vehicle.string() + ": hover.target: z = 1 is at or below the ground"),
            std::string::npos)
      << from_vehicle.output;
  EXPECT_FALSE(fs::exists(dir_ / "h"));
}

TEST_F(HoverCli, ControlAnswersEveryLineAndMalformedOnesWithTheTrim) {
  const std::string policy = train();
  const fs::path in = dir_ / "in.csv";
  std::ofstream(in) << "x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate\n"
                       "0,0,-10,0,0,0,0,0,0,0,0,0\n"
                       "0,0,-10,oops,0,0,0,0,0,0,0,0\n"
                       "0.5,0,-10,0,0,0,0.2,0,0,0,0,0\n"
                       "1,2\n";
  const fs::path err = dir_ / "err.txt";
  // stderr to a file, stdout through cat (run_pegasus adds "2>&1", which then applies to cat).
  const auto r =
      run_pegasus("heli control --policy " + policy + " <" + in.string() + " 2>" + err.string() + " | cat");
  ASSERT_EQ(r.code, 0) << r.output;
  const auto rows = pegasus::parse_csv(r.output);
  ASSERT_EQ(rows.size(), 5u) << r.output;
  EXPECT_EQ(rows[0], (std::vector<std::string>{"a1", "a2", "a3", "a4"}));
  const auto p = json_file(policy);
  for (std::size_t line : {std::size_t{2}, std::size_t{4}}) {
    ASSERT_EQ(rows[line].size(), 4u);
    for (std::size_t c = 0; c < 4; ++c)
      EXPECT_EQ(std::stod(rows[line][c]), p.at("trim").at("a" + std::to_string(c + 1)).get<double>()) << line;
  }
  for (std::size_t line : {std::size_t{1}, std::size_t{3}})
    for (const auto& cell : rows[line]) {
      EXPECT_LE(std::abs(std::stod(cell)), 1.0);
    }
  EXPECT_LT(std::stod(rows[3][0]), std::stod(rows[1][0]));  // ahead and moving forward: cyclic back
  const std::string errors = read_text(err);
  EXPECT_EQ(std::count(errors.begin(), errors.end(), '\n'), 2) << errors;
  EXPECT_NE(errors.find("stdin:3: field 4: expected a finite number, got 'oops'; answered the trim controls"),
            std::string::npos)
      << errors;
  // The header names the columns, so lines are read by it.
  EXPECT_NE(errors.find("stdin:5: expected at least 12 fields, as the header says, got 2"), std::string::npos)
      << errors;
}

// The main job's chain on a tiny setting: every stage's run directory, the headline summary and the plots.
TEST_F(HoverCli, PipelineRunsEveryStageAndPrintsTheHeadline) {
  const std::string args =
      "heli pipeline --quiet --train-seconds 60 --test-seconds 25 --cv-points 40 --scale-grid 2,4 "
      "--coordinate-passes 0 --scenarios 2 --scenario-seconds 2 --gradient-iterations 0 "
      "--hill-climbing-iterations 1 "
      "--flights 2 --flight-seconds 3";
  const auto r = run_pegasus(args + out("demo"));
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* stage : {"pilot-train", "pilot-test", "identify", "hover", "fly"})
    EXPECT_TRUE(fs::exists(dir_ / "demo" / stage / "summary.json")) << stage;
  const auto s = json_file(dir_ / "demo" / "summary.json");
  for (const char* key :
       {"flights", "crashes", "rms_position_m", "rms_velocity_mps", "rms_yaw_rad", "pilot", "hover"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_EQ(s.at("flights"), 2);
  EXPECT_NE(r.output.find("headline figures"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find((dir_ / "demo" / "fly" / "position_x.svg").string()), std::string::npos)
      << r.output;
  // The files the plots line names after it (it once named a position_z.svg that no stage writes).
  EXPECT_NE(r.output.find(", position_y.svg, altitude.svg, velocity_xb/yb/zb.svg"), std::string::npos)
      << r.output;
  for (const char* plot : {"position_x.svg", "position_y.svg", "altitude.svg", "velocity_xb.svg",
                           "velocity_yb.svg", "velocity_zb.svg"})
    EXPECT_TRUE(fs::exists(dir_ / "demo" / "fly" / plot)) << plot;
  // Each stage is the command a user would type in the run directory, and its run.json says which.
  const auto hover_run = json_file(dir_ / "demo" / "hover" / "run.json");
  EXPECT_EQ(hover_run.at("command"), "heli hover");
  const std::vector<std::string> argv = hover_run.at("argv");
  std::string line;
  for (const auto& word : argv) line += (line.empty() ? "" : " ") + word;
  EXPECT_TRUE(
      line.starts_with("pegasus heli hover --model identify/model.json --scenarios 2 --seconds 2 "
                       "--optimizer.gradient.max-iterations 0 "
                       "--optimizer.hill-climbing.max-iterations 1 --seed 1 "))
      << line;
  const std::string flights = read_text(dir_ / "demo" / "fly" / "summary.json");

  // Killed after the hover stage: the rerun with --resume keeps the finished stages and gives the same
  // flights.
  fs::rename(dir_ / "demo", dir_ / "killed.partial");
  for (const char* gone : {"fly", "summary.json", "run.json", "report.html"})
    fs::remove_all(dir_ / "killed.partial" / gone);
  const auto resumed = run_pegasus(args + out("killed") + " --resume");
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  for (const char* stage : {"pilot-train", "pilot-test", "identify", "hover"})
    EXPECT_NE(resumed.output.find(fmt::format("[{}] done before, kept", stage)), std::string::npos)
        << stage << "\n"
        << resumed.output;
  EXPECT_EQ(read_text(dir_ / "killed" / "fly" / "summary.json"), flights);
  EXPECT_EQ(json_file(dir_ / "killed" / "summary.json"), s);
}

// noise_check_flights: more pilot hold-out flights on their own seeds, pooled in identify's noise check,
// listed as stages, and the check's pass or fail carried to the pipeline's summary.
TEST_F(HoverCli, PipelinePoolsItsNoiseCheckFlightsInIdentify) {
  const auto r = run_pegasus(
      "heli pipeline --quiet --train-seconds 60 --test-seconds 25 --noise-check-flights 2 "
      "--noise-check-seconds 30 --cv-points 40 --scale-grid 2,4 --coordinate-passes 0 --scenarios 2 "
      "--scenario-seconds 2 --gradient-iterations 0 --hill-climbing-iterations 1 --flights 2 "
      "--flight-seconds 3" +
      out("pooled"));
  ASSERT_EQ(r.code, 0) << r.output;
  const fs::path run = dir_ / "pooled";
  EXPECT_EQ(json_file(run / "pilot-check-1" / "summary.json").at("seconds"), 30.0);
  EXPECT_NE(read_text(run / "pilot-check-1" / "log.csv"), read_text(run / "pilot-check-2" / "log.csv"));
  EXPECT_NE(read_text(run / "pilot-check-1" / "log.csv"), read_text(run / "pilot-test" / "log.csv"));
  const auto identify = json_file(run / "identify" / "summary.json");
  ASSERT_EQ(identify.at("noise_check_by_log").size(), 3u);
  int steps = 0;
  for (const auto& log : identify.at("noise_check_by_log")) steps += log.at("steps").get<int>();
  EXPECT_EQ(identify.at("noise_check_steps").get<int>(), steps);
  EXPECT_EQ(identify.at("noise_check_by_log")[2].at("log"), "pilot-check-2/log.csv");
  const auto s = json_file(run / "summary.json");
  EXPECT_EQ(s.at("stages"), nlohmann::json({"pilot-train", "pilot-test", "pilot-check-1", "pilot-check-2",
                                            "identify", "hover", "fly"}));
  EXPECT_EQ(s.at("noise_check_passes"), identify.at("noise_check_passes"));
  EXPECT_NE(r.output.find("noise check: the learned model's 2 sd bands"), std::string::npos) << r.output;
}

}  // namespace
