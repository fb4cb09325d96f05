// The training layer: stages chain their best thetas, histories merge, seeds come from one place, a plan
// killed after any checkpoint resumes bit-identically, and an iteration callback stops a run early.
#include "pegasus/optimizers/training.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string_view>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/evaluators/monte_carlo.hpp"
#include "pegasus/random/seed.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

// Gradient ascent, then hill climbing from its result: the hover's plan (thesis §5.3).
TrainingPlan GradientThenHillClimb() {
  TrainingPlan plan;
  plan.seed = 11;
  OptimizerOptions g;
  g.method = "gradient";
  g.gradient.max_iterations = 6;
  OptimizerOptions h;
  h.method = "hill-climb";
  h.hill_climbing.max_iterations = 7;
  h.hill_climbing.proposals_per_iteration = 3;
  plan.stages = {{.name = "gradient", .optimizer = g},
                 {.name = "refine", .optimizer = h, .seeds = SeedDomains::Refine()}};
  return plan;
}

TEST(Training, EachStageStartsFromTheBestOfTheOneBefore) {
  auto objective = NegatedRosenbrock(BoxSpec(3, -1.2, 3.0));
  TrainingPlan plan = GradientThenHillClimb();
  Theta theta;
  TrainingSummary summary;
  Train(plan, objective, &theta, &summary);
  ASSERT_EQ(summary.stages.size(), 2u);
  EXPECT_EQ(summary.stage_names, (std::vector<std::string>{"gradient", "refine"}));
  // The second stage's first evaluation is the first stage's best theta.
  EXPECT_EQ(summary.stages[1].initial_value, summary.stages[0].best_value);
  EXPECT_GE(summary.best_value, summary.stages[0].best_value);
  EXPECT_EQ(theta, summary.stages[1].best_theta);
  EXPECT_EQ(summary.initial_value, objective.evaluate(std::vector<double>(3, -1.2)));
}

TEST(Training, HistoryCountsOnAcrossStages) {
  auto objective = NegatedRosenbrock(BoxSpec(3, -1.2, 3.0));
  Theta theta;
  TrainingSummary summary;
  Train(GradientThenHillClimb(), objective, &theta, &summary);
  const auto& first = summary.stages[0];
  const auto& second = summary.stages[1];
  ASSERT_EQ(summary.history.size(), first.history.size() + second.history.size());
  const IterationRecord& boundary = first.history.back();
  for (std::size_t i = 0; i < second.history.size(); ++i) {
    const IterationRecord& merged = summary.history[first.history.size() + i];
    EXPECT_EQ(merged.iteration, first.iterations + second.history[i].iteration);
    EXPECT_EQ(merged.evaluations, first.evaluations + second.history[i].evaluations);
    EXPECT_EQ(merged.value, std::max(second.history[i].value, boundary.value));
  }
  EXPECT_EQ(summary.history.back().evaluations, first.evaluations + second.evaluations);
}

// A stage that ends inside an iteration (here the gradient's probes find U-hat flat, so no iteration ends)
// spent evaluations that no record of its own shows; the next stage counts on from all of them.
TEST(Training, HistoryCountsTheEvaluationsOfAStageThatEndedInsideAnIteration) {
  FunctionObjective flat(BoxSpec(3, -1.2, 3.0), [](std::span<const double>) { return -1.0; });
  Theta theta;
  TrainingSummary summary;
  Train(GradientThenHillClimb(), flat, &theta, &summary);
  const auto& first = summary.stages[0];
  const auto& second = summary.stages[1];
  ASSERT_TRUE(first.history.empty()) << first.message;
  EXPECT_EQ(first.evaluations, 1 + 2 * 3);  // the start, and two probes per parameter
  ASSERT_EQ(summary.history.size(), second.history.size());
  EXPECT_EQ(summary.history.front().iteration, 1);
  EXPECT_EQ(summary.history.back().evaluations, first.evaluations + second.evaluations);
  EXPECT_EQ(summary.history.back().seconds, first.wall_seconds + second.history.back().seconds);
}

TEST(Training, SeedsComeFromTheRunSeedAndTheStagesDomains) {
  OptimizerOptions o;
  DeriveOptimizerSeeds(5, SeedDomains{}, &o);
  EXPECT_EQ(o.hill_climbing.seed, mix_seed(5, 0x48696c6c));
  EXPECT_EQ(o.nlopt.seed, mix_seed(5, 0x4e4c6f70));
  EXPECT_EQ(o.cmaes.seed, mix_seed(5, 0x434d4145));
  EXPECT_EQ(o.ars.seed, mix_seed(5, 0x41525321));
  DeriveOptimizerSeeds(5, SeedDomains::Refine(), &o);
  EXPECT_EQ(o.hill_climbing.seed, mix_seed(5, 0x52486c6c));
  EXPECT_EQ(o.nlopt.seed, mix_seed(5, 0x524e4c6f));
  EXPECT_EQ(o.cmaes.seed, mix_seed(5, 0x52434d41));
  EXPECT_EQ(o.ars.seed, mix_seed(5, 0x52415253));
  // Domains by options section: one per random method, in the list's order; a stage may choose its own.
  SeedDomains domains;
  std::vector<std::string_view> sections;
  for (const auto& [section, domain] : domains.all()) sections.push_back(section);
  EXPECT_EQ(sections, (std::vector<std::string_view>{"hill_climbing", "nlopt", "cmaes", "ars"}));
  domains.set("cmaes", 7);
  DeriveOptimizerSeeds(5, domains, &o);
  EXPECT_EQ(o.cmaes.seed, mix_seed(5, 7));
  EXPECT_EQ(o.nlopt.seed, mix_seed(5, 0x4e4c6f70));
  EXPECT_NE(domains, SeedDomains{});
  try {
    domains.set("gradient", 1);
    ADD_FAILURE() << "gradient ascent draws no random numbers";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "seed domains: expected the options section of an optimizer that draws random numbers "
                 "(hill_climbing, "
                 "nlopt, cmaes, ars), got 'gradient'");
  }
  EXPECT_THROW(static_cast<void>(domains.of("hill-climb")), InputError);  // a method name, not a section
  // Another run seed gives another hill-climbing run; the same seed the same bits.
  auto objective = NegatedRastrigin(BoxSpec(2, -1.2, 3.0));
  auto run = [&](std::uint64_t seed) {
    TrainingPlan plan = GradientThenHillClimb();
    plan.stages.erase(plan.stages.begin());
    plan.seed = seed;
    Theta theta;
    TrainingSummary s;
    Train(plan, objective, &theta, &s);
    return s.stages[0];
  };
  EXPECT_TRUE(SameOutcome(run(3), run(3)));
  EXPECT_FALSE(SameOutcome(run(3), run(4)));
}

TEST(Training, ResumingFromAnyCheckpointEndsBitIdentically) {
  auto objective = NegatedRosenbrock(BoxSpec(3, -1.2, 3.0));
  std::vector<json> checkpoints;
  TrainingPlan plan = GradientThenHillClimb();
  plan.checkpoint_every = 1;
  plan.on_checkpoint = [&](const json& c) { checkpoints.push_back(c); };
  Theta theta;
  TrainingSummary whole;
  Train(plan, objective, &theta, &whole);
  // One per iteration of each stage, plus the stage boundary.
  ASSERT_EQ(checkpoints.size(),
            static_cast<std::size_t>(whole.stages[0].iterations + whole.stages[1].iterations + 1));
  for (std::size_t c = 0; c < checkpoints.size(); ++c) {
    TrainingPlan resumed = GradientThenHillClimb();
    resumed.checkpoint_every = 1;
    resumed.on_checkpoint = [](const json&) {};
    resumed.resume_from = json::parse(checkpoints[c].dump());  // through text, as from a file
    Theta t;
    TrainingSummary s;
    Train(resumed, objective, &t, &s);
    ASSERT_EQ(s.stages.size(), 2u) << "checkpoint " << c;
    for (std::size_t k = 0; k < 2; ++k) {
      std::string difference;
      EXPECT_TRUE(SameOutcome(s.stages[k], whole.stages[k], &difference))
          << "checkpoint " << c << ", stage " << k << ": " << difference;
    }
    EXPECT_EQ(t, theta);
    ASSERT_EQ(s.history.size(), whole.history.size());
    for (std::size_t i = 0; i < s.history.size(); ++i) {
      EXPECT_EQ(s.history[i].iteration, whole.history[i].iteration);
      EXPECT_EQ(s.history[i].evaluations, whole.history[i].evaluations);
      EXPECT_EQ(s.history[i].value, whole.history[i].value);
    }
  }
}

class StopAfter final : public IterationCallback {
 public:
  explicit StopAfter(std::int64_t iterations) : iterations_(iterations) {}
  CallbackReturnType operator()(const IterationReport& report) override {
    seen.push_back(report.record.iteration);
    return report.record.iteration >= iterations_ ? CallbackReturnType::kTerminate
                                                  : CallbackReturnType::kContinue;
  }
  std::vector<std::int64_t> seen;

 private:
  std::int64_t iterations_;
};

TEST(Training, AnIterationCallbackStopsTheRunEarly) {
  auto objective = NegatedRosenbrock(BoxSpec(3, -1.2, 3.0));
  TrainingPlan plan = GradientThenHillClimb();
  StopAfter stop(2);
  plan.callbacks = {&stop};
  Theta theta;
  TrainingSummary summary;
  Train(plan, objective, &theta, &summary);
  ASSERT_EQ(summary.stages.size(), 1u);  // the refinement never ran
  EXPECT_TRUE(summary.stopped_by_callback);
  EXPECT_EQ(summary.stages[0].iterations, 2);
  EXPECT_EQ(summary.stages[0].termination_type, TerminationType::kUserRequested);
  EXPECT_EQ(stop.seen, (std::vector<std::int64_t>{1, 2}));
}

TEST(Training, EveryMethodTellsItsCallbacksEachIteration) {
  auto objective = ConcaveQuadratic(BoxSpec(2, -1.2, 3.0), {0.5, -0.5}, {1, 2});
  for (const char* method : {"gradient", "hill-climb", "bobyqa", "sbplx", "cmaes", "ars"}) {
    OptimizerOptions o;
    o.method = method;
    o.gradient.max_iterations = 4;
    o.hill_climbing.max_iterations = 4;
    o.nlopt.max_evaluations = 4;
    o.cmaes.max_iterations = 4;
    o.ars.max_iterations = 4;
    StopAfter never(1000);
    o.SetCallbacks({&never});
    Theta theta;
    OptimizerSummary s;
    Solve(o, objective, &theta, &s);
    ASSERT_EQ(never.seen.size(), static_cast<std::size_t>(s.iterations)) << method;
    for (std::size_t i = 0; i < never.seen.size(); ++i)
      EXPECT_EQ(never.seen[i], static_cast<std::int64_t>(i + 1));
  }
}

TEST(Training, AnInvalidPlanNamesTheStageAndField) {
  auto objective = NegatedRosenbrock(BoxSpec(2, -1.2, 3.0));
  TrainingPlan plan = GradientThenHillClimb();
  plan.stages[1].optimizer.hill_climbing.initial_step = -1;
  std::string error;
  EXPECT_FALSE(plan.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("stages[1].optimizer.hill_climbing.initial_step"));
  Theta theta;
  TrainingSummary summary;
  EXPECT_THROW(Train(plan, objective, &theta, &summary), InputError);
  TrainingPlan bad = GradientThenHillClimb();
  bad.resume_from = json{{"format", "pegasus.training.checkpoint"}, {"version", 1}, {"stage", 7}};
  try {
    Train(bad, objective, &theta, &summary);
    FAIL() << "a checkpoint of another plan was accepted";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("stage"));
  }
}

// A stage may start from a mapping of the previous stage's best (a refinement that frees more parameters):
// the two-parameter stage's best, with a third coordinate appended, is where the three-parameter stage
// starts, and a resume at the stage boundary maps it the same way.
TEST(Training, AStageMapsTheThetaItStartsFrom) {
  auto small = NegatedRosenbrock(BoxSpec(2, -1.2, 3.0));
  auto large = NegatedRosenbrock(BoxSpec(3, -1.2, 3.0));
  TrainingPlan plan = GradientThenHillClimb();
  plan.stages[0].objective = &small;
  plan.stages[1].objective = &large;
  plan.stages[1].start_from = [](const Theta& t) {
    Theta out = t;
    out.push_back(0.5);
    return out;
  };
  std::vector<json> checkpoints;
  plan.checkpoint_every = 100;
  plan.on_checkpoint = [&](const json& c) { checkpoints.push_back(c); };
  Theta theta;
  TrainingSummary whole;
  Train(plan, small, &theta, &whole);
  ASSERT_EQ(whole.stages.size(), 2u);
  Theta expected_start = whole.stages[0].best_theta;
  ASSERT_EQ(expected_start.size(), 2u);
  expected_start.push_back(0.5);
  EXPECT_EQ(whole.stages[1].initial_value, large.evaluate(expected_start));
  EXPECT_EQ(whole.best_theta.size(), 3u);

  ASSERT_FALSE(checkpoints.empty());
  const json boundary = checkpoints.front();
  ASSERT_EQ(boundary.at("stage"), 1);
  plan.resume_from = boundary;
  TrainingSummary resumed;
  Theta again;
  Train(plan, small, &again, &resumed);
  EXPECT_EQ(again, theta);
  EXPECT_EQ(resumed.best_value, whole.best_value);
}

// The caller's state rides in every checkpoint, taken at the moment it is written.
TEST(Training, CheckpointsCarryTheCallersStateAtThatMoment) {
  auto objective = NegatedRosenbrock(BoxSpec(3, -1.2, 3.0));
  TrainingPlan plan = GradientThenHillClimb();
  int calls = 0;
  plan.caller_state = [&] { return json{{"calls", ++calls}}; };
  std::vector<json> checkpoints;
  plan.checkpoint_every = 2;
  plan.on_checkpoint = [&](const json& c) { checkpoints.push_back(c); };
  Theta theta;
  TrainingSummary summary;
  Train(plan, objective, &theta, &summary);
  ASSERT_GE(checkpoints.size(), 3u);
  for (std::size_t k = 0; k < checkpoints.size(); ++k)
    EXPECT_EQ(checkpoints[k].at("caller").at("calls"), static_cast<int>(k) + 1) << k;
  plan.caller_state = nullptr;
  checkpoints.clear();
  Train(plan, objective, &theta, &summary);
  ASSERT_FALSE(checkpoints.empty());
  EXPECT_TRUE(checkpoints.front().at("caller").is_null());
}

// A checkpoint whose entries have other types is bad input naming the checkpoint, never a JSON type error.
TEST(Training, ACheckpointOfOtherTypesIsBadInput) {
  auto objective = NegatedRosenbrock(BoxSpec(2, -1.2, 3.0));
  for (const json& bad : {json(3), json{{"format", 5}}, json{{"format", nullptr}, {"stage", "x"}},
                          json{{"format", "pegasus.training.checkpoint"}, {"version", "1"}},
                          json{{"format", "pegasus.training.checkpoint"}, {"version", 1}, {"stage", -1}}}) {
    SCOPED_TRACE(bad.dump());
    TrainingPlan plan = GradientThenHillClimb();
    plan.resume_from = bad;
    Theta theta;
    TrainingSummary summary;
    try {
      Train(plan, objective, &theta, &summary);
      ADD_FAILURE() << "accepted";
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("checkpoint"));
    }
  }
  EXPECT_THROW((void)TrainingCheckpointIterations(json{{"format", 5}}), InputError);
  EXPECT_EQ(TrainingCheckpointIterations(json{{"format", "pegasus.training.checkpoint"},
                                              {"finished", {{{"iterations", 4}}, 7}},
                                              {"optimizer", {{"iterations", "3"}}}}),
            4);
}

}  // namespace
}  // namespace pegasus
