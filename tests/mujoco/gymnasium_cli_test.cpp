// The Gymnasium recipes (experiments/mujoco/gymnasium/NAME-train.toml) run as the manual says, with the model
// on the command line (here the test models of tests/mujoco/gymnasium/, in place of the user's Gymnasium
// XML): one iteration of ARS with two directions, so that the test stays fast, and the recipe's step size,
// noise, one scenario, linear policy and normalisation in the run's config.toml and summary.json.
#ifdef PEGASUS_HAVE_MUJOCO
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "mujoco_test_support.hpp"
#include "support/cli_runner.hpp"

namespace pegasus {
namespace {

using test_support::read_text;

class GymnasiumCli : public test_support::TempDirTest {};

TEST_F(GymnasiumCli, EveryRecipeRunsOnTheModelGivenOnTheCommandLine) {
  struct Recipe {
    std::string name, step_size, noise;
    int parameters;  // linear: actions x (observation + 1)
  };
  const std::vector<Recipe> recipes = {
      {"swimmer", "0.02", "0.01", 2 * 9},       {"hopper", "0.01", "0.025", 3 * 12},
      {"half_cheetah", "0.02", "0.03", 6 * 18}, {"walker2d", "0.03", "0.025", 6 * 18},
      {"ant", "0.015", "0.025", 8 * 30},
  };
  const auto root = std::filesystem::path(PEGASUS_SOURCE_DIR);
  for (const auto& r : recipes) {
    SCOPED_TRACE(r.name);
    const auto out = dir_ / r.name;
    // From the repository's root, as the recipe's task path is written.
    const auto run =
        test_support::run_shell("cd '" + root.string() + "' && " + PEGASUS_CLI_PATH +
                                " mujoco train --config experiments/mujoco/gymnasium/" + r.name +
                                "-train.toml --model tests/mujoco/gymnasium/" + r.name +
                                ".xml --optimizer.ars.max-iterations 1 --optimizer.ars.directions 2 "
                                "--optimizer.ars.top-directions 1 --evaluation-episodes 2 --quiet --out " +
                                out.string());
    ASSERT_EQ(run.code, 0) << run.output;
    const auto s = nlohmann::json::parse(read_text(out / "summary.json"));
    EXPECT_EQ(s.at("method"), "ars");
    EXPECT_EQ(s.at("policy_class"), "linear");
    EXPECT_EQ(s.at("parameters"), r.parameters);
    EXPECT_EQ(s.at("scenarios"), 1);
    EXPECT_EQ(s.at("horizon"), 1000);
    EXPECT_EQ(s.at("evaluation").at("episodes"), 2);
    const std::string config = read_text(out / "config.toml");
    EXPECT_NE(config.find("\nstep_size = " + r.step_size + "\n"), std::string::npos);
    EXPECT_NE(config.find("\nexploration_noise = " + r.noise + "\n"), std::string::npos);
    EXPECT_NE(config.find("\nnormalize = true\n"), std::string::npos);
  }
}

}  // namespace
}  // namespace pegasus
#endif
