// The helicopter experiments as library functions (heli/runs/heli_runs.hpp): a program that chains them on
// its own run directories gets exactly the summaries the CLI's pipeline writes for the same settings.
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <sstream>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/runs/heli_runs.hpp"
#include "support/cli_runner.hpp"

namespace pegasus::heli {
namespace {

namespace fs = std::filesystem;
using test_support::read_text;
using test_support::run_pegasus;

class HeliRuns : public test_support::TempDirTest {
 protected:
  // Runs `experiment` into the committed run directory dir_/name (its config: a note of what ran).
  void run(const std::string& name, const std::function<void(RunSink&)>& experiment) {
    ConfigSchema config;
    config.add_string("experiment", "", "what ran");
    config.set("experiment", name);
    RunDirectory dir = RunDirectory::open(dir_ / name, config);
    std::ostringstream out;
    nlohmann::json timings = nlohmann::json::object();
    RunSink sink{.dir = dir, .out = out, .timings = timings, .quiet = true};
    experiment(sink);
    dir.commit();
  }
};

TEST_F(HeliRuns, TheLibraryChainGivesThePipelinesSummaries) {
  const auto r = run_pegasus(
      "heli pipeline --quiet --train-seconds 60 --test-seconds 25 --cv-points 40 --scale-grid 2,4 "
      "--coordinate-passes 0 --scenarios 2 --scenario-seconds 2 --gradient-iterations 0 "
      "--hill-climbing-iterations 1 --flights 2 --flight-seconds 3 --seed 5 --threads 2 --out " +
      (dir_ / "cli").string());
  ASSERT_EQ(r.code, 0) << r.output;

  ThreadPool pool(2);
  for (const auto& [name, seconds, seed] :
       {std::tuple{"pilot-train", 60.0, 5}, std::tuple{"pilot-test", 25.0, 6}}) {
    // Named before the lambda: clang 14 cannot capture a structured binding.
    const PilotRunOptions pilot{.seconds = seconds, .seed = static_cast<std::uint64_t>(seed)};
    run(name, [&](RunSink& sink) { run_pilot(pilot, sink); });
  }
  run("identify", [&](RunSink& sink) {
    IdentifyRunOptions o;
    o.train_log = (dir_ / "pilot-train" / "log.csv").string();
    o.test_log = (dir_ / "pilot-test" / "log.csv").string();
    o.identify.cv_points = 40;
    o.identify.scale_grid = {2, 4};
    o.identify.coordinate_passes = 0;
    o.variants = false;
    run_identify(o, sink, pool);
  });
  run("hover", [&](RunSink& sink) {
    HoverRunOptions o{.model_file = (dir_ / "identify" / "model.json").string()};
    o.training.scenarios = 2;
    o.training.seconds = 2;
    o.training.optimizer.gradient.max_iterations = 0;
    o.training.optimizer.hill_climbing.max_iterations = 1;
    o.training.seed = 5;
    run_hover(o, sink, pool);
  });
  run("fly", [&](RunSink& sink) {
    FlyRunOptions o{.policy_file = (dir_ / "hover" / "policy.json").string(), .compare_pilot = true};
    o.settings.gust_sigma = 0.5;
    o.settings.start_pos_sigma = 1.0;
    o.settings.start_vel_sigma = 0.3;
    o.flights = {.flights = 2, .seconds = 3, .seed = 7};
    run_fly(o, sink, pool);
  });
  for (const char* stage : {"pilot-train", "pilot-test", "identify", "hover", "fly"}) {
    const std::string library = read_text(dir_ / stage / "summary.json");
    ASSERT_FALSE(library.empty()) << stage;
    std::string cli = read_text(dir_ / "cli" / stage / "summary.json");
    if (std::string(stage) == "fly") {  // the controller is named by the path it was given
      const std::string relative = "\"hover/policy.json\"";
      cli.replace(cli.find(relative), relative.size(),
                  nlohmann::json((dir_ / "hover" / "policy.json").string()).dump());
    }
    EXPECT_EQ(library, cli) << stage;
  }
}

TEST_F(HeliRuns, BadInputNamesTheFileAndWritesNothing) {
  ConfigSchema config;
  RunDirectory dir = RunDirectory::open(dir_ / "hover", config);
  std::ostringstream out;
  nlohmann::json timings = nlohmann::json::object();
  RunSink sink{.dir = dir, .out = out, .timings = timings, .quiet = true};
  ThreadPool pool(1);
  const std::string missing = (dir_ / "none" / "model.json").string();
  try {
    run_hover({.model_file = missing}, sink, pool);
    FAIL() << "a missing model was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path() / "summary.json"));
  EXPECT_FALSE(fs::exists(dir.path() / "policy.json"));
}

}  // namespace
}  // namespace pegasus::heli
