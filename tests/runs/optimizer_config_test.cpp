// The one optimizer section of every training command (runs/optimizer_config.hpp), written over the list of
// methods: every method's fields with the command's defaults, the offered methods as the choices, values read
// back into the options, and errors named as the user wrote them.
#include "pegasus/runs/optimizer_config.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "support/input_error.hpp"

namespace pegasus {
namespace {

using test_support::input_error_message;

TEST(OptimizerConfig, DeclaresEveryMethodsFieldsWithTheCommandsDefaultsAndOffersItsMethods) {
  OptimizerOptions defaults;
  defaults.method = "hill-climb";
  defaults.hill_climbing.proposals_per_iteration = 8;
  defaults.cmaes.restarts = 3;
  ConfigSchema s;
  declare_optimizer_options(s, "optimizer", defaults, continuous_class_methods(false));
  s.validate();
  EXPECT_EQ(s.get_string("optimizer.method"), "hill-climb");
  EXPECT_EQ(s.get_int("optimizer.hill_climbing.proposals_per_iteration"), 8);
  EXPECT_EQ(s.get_int("optimizer.cmaes.restarts"), 3);
  EXPECT_EQ(s.get_double("optimizer.gradient.max_step"), GradientAscentOptions{}.max_step);
  // A continuous class without finite bounds: no exhaustive search, crs2 or esch among the choices, but
  // every method's fields (a resolved config.toml of any command is a valid input of any other).
  EXPECT_TRUE(s.has("optimizer.exhaustive.block_size"));
  EXPECT_TRUE(s.has("optimizer.nlopt.population"));
  EXPECT_EQ(s.field("optimizer.method").allowed_choices(),
            (std::vector<std::string>{"gradient", "hill-climb", "bobyqa", "sbplx", "cmaes", "ars"}));
  // Seeds are the run's, never the section's.
  EXPECT_FALSE(s.has("optimizer.hill_climbing.seed"));
  EXPECT_FALSE(s.has("optimizer.cmaes.stream"));

  ConfigSchema every;
  declare_optimizer_options(every, "refine", defaults, {}, /*allow_none=*/true);
  EXPECT_EQ(every.field("refine.method").allowed_choices(),
            (std::vector<std::string>{"exhaustive", "gradient", "hill-climb", "bobyqa", "sbplx", "crs2",
                                      "esch", "cmaes", "ars", "none"}));
}

TEST(OptimizerConfig, AFieldsRangeIsItsTypesAndItsOptionsOwn) {
  ConfigSchema s;
  declare_optimizer_options(s, "optimizer", OptimizerOptions{});
  // A 64-bit count takes values past a 32-bit int's; a 32-bit one stops at its own bound.
  s.set_from_cli("optimizer.gradient.max_evaluations", "5000000000");
  EXPECT_EQ(s.get_int("optimizer.gradient.max_evaluations"), 5'000'000'000);
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("optimizer.gradient.max_backtracks", "5000000000"); }),
            "--optimizer.gradient.max-backtracks: expected an integer in [0, 2147483647], got '5000000000'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("optimizer.cmaes.restarts", "21"); }),
            "--optimizer.cmaes.restarts: expected an integer in [0, 20], got '21'");
  EXPECT_EQ(input_error_message([&] { s.set_from_cli("optimizer.gradient.max_step", "inf"); }),
            "--optimizer.gradient.max-step: expected a number in (0, inf), got 'inf'");
}

TEST(OptimizerConfig, ValuesReachTheOptionsAndUndeclaredOnesKeepTheirs) {
  ConfigSchema s;
  declare_optimizer_options(s, "optimizer", OptimizerOptions{}, continuous_class_methods(true));
  s.load_toml_string(
      "[optimizer]\nmethod = \"ars\"\nars.directions = 5\nars.top_directions = 2\nars.step_size = "
      "0.5\nnlopt.population = 40\n",
      "run.toml");
  s.set_from_cli("optimizer.gradient.max_backtracks", "4");
  s.validate();
  OptimizerOptions read;
  read.ars.seed = 99;  // not a field of the section: kept
  read_optimizer_options(s, "optimizer", &read);
  EXPECT_EQ(read.method, "ars");
  EXPECT_EQ(read.ars.directions, 5);
  EXPECT_EQ(read.ars.top_directions, 2);
  EXPECT_EQ(read.ars.step_size, 0.5);
  EXPECT_EQ(read.nlopt.population, 40);
  EXPECT_EQ(read.gradient.max_backtracks, 4);
  EXPECT_EQ(read.ars.seed, 99u);
}

TEST(OptimizerConfig, ErrorsNameTheFieldAsTheUserWroteIt) {
  auto schema = [] {
    ConfigSchema s;
    declare_optimizer_options(s, "optimizer", OptimizerOptions{}, continuous_class_methods(false));
    return s;
  };
  // A field's own range (VisitFields), checked when it is set.
  ConfigSchema a = schema();
  EXPECT_EQ(input_error_message([&] { a.set_from_cli("optimizer.hill_climbing.step_shrink", "1.5"); }),
            "--optimizer.hill-climbing.step-shrink: expected a number in (0, 1], got '1.5'");
  // A field no method has.
  ConfigSchema b = schema();
  EXPECT_EQ(input_error_message([&] { b.load_toml_string("[optimizer]\nars.step = 3\n", "run.toml"); }),
            "run.toml:2: unknown key 'optimizer.ars.step' (did you mean 'optimizer.ars.step_size'?)");
  // A cross-field rule of the selected method (IsValid), under the value the user gave.
  ConfigSchema c = schema();
  c.load_toml_string("[optimizer]\nmethod = \"hill-climb\"\nhill_climbing.initial_step = 2.0\n", "run.toml");
  EXPECT_EQ(
      input_error_message([&] { c.validate(); }),
      "run.toml:3: optimizer.hill_climbing.initial_step: expected 0 < initial_step <= max_step = 1, got 2");
}

}  // namespace
}  // namespace pegasus
