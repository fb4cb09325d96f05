#include "pegasus/optimizers/cmaes.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>

#include "pegasus/core/error.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "support/bits.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::StartsWith;

using test_support::Bits;

TEST(Cmaes, FindsTheMaximumOfAnIllConditionedQuadraticWithinItsEvaluationBudget) {
  // Curvatures 1e4 apart in scaled units (widths 0.1 to 10 times each parameter's scale).
  const Theta peak = {0.003, -2.5, 370.0};
  auto objective = ConcaveQuadratic(ThreeScaleSpec(), peak, {0.001, 1.0, 1000.0}, 4.0);
  CmaesOptions options;
  options.max_evaluations = 2000;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kConvergence) << summary.FullReport();
  EXPECT_LE(summary.evaluations, 2000);
  EXPECT_NEAR(summary.best_value, 4.0, 1e-10);
  const Theta width = {0.001, 1.0, 1000.0};
  for (std::size_t i = 0; i < peak.size(); ++i) EXPECT_NEAR(theta[i], peak[i], 1e-5 * width[i]) << i;
  EXPECT_EQ(summary.method, "cmaes");
  EXPECT_EQ(summary.initial_value, objective.evaluate(ThreeScaleSpec().initial()));
}

TEST(Cmaes, FindsTheMaximumOfTheRosenbrockValleyInFourDimensions) {
  auto objective = NegatedRosenbrock(BoxSpec(4, -1.0, 5.0));
  CmaesOptions options;
  options.max_evaluations = 6000;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_GE(summary.best_value, -1e-10) << summary.FullReport();
  EXPECT_LE(summary.evaluations, 6000);
  for (const double t : theta) EXPECT_NEAR(t, 1.0, 1e-4);
}

TEST(Cmaes, ALargePopulationFindsTheGlobalMaximumOfRastriginFromEverySeed) {
  // Local maxima near every integer point; the start (3, 3) is on one of them, far from the global one.
  // A local method from (3, 3) ends on the local maximum there; CMA-ES with a large population and a wide
  // first distribution smooths over the ripples (seeds 0 to 19 all find the global maximum; 10 are tested).
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    SCOPED_TRACE(seed);
    auto objective = NegatedRastrigin(BoxSpec(2, 3.0, 5.12));
    CmaesOptions options;
    options.seed = seed;
    options.population_size = 100;
    options.initial_step = 3.0;
    options.max_evaluations = 10000;
    Theta theta;
    OptimizerSummary summary;
    Solve(options, objective, &theta, &summary);
    EXPECT_GE(summary.best_value, -1e-8) << summary.FullReport();
    for (const double t : theta) EXPECT_NEAR(t, 0.0, 1e-5);
  }
}

// IPOP (Auger and Hansen 2005): a run that converges on a local maximum of Rastrigin in 4 dimensions stops;
// with up to 8 restarts, each from the same start (3, 3, 3, 3) with twice the population, a later run finds
// the global maximum.
TEST(Cmaes, RestartsWithDoubledPopulationsLeaveTheLocalMaximumOneRunEndsOn) {
  int stayed = 0, rescued = 0;
  for (std::uint64_t seed = 0; seed < 10; ++seed) {
    SCOPED_TRACE(seed);
    CmaesOptions options;
    options.seed = seed;
    options.initial_step = 2.0;
    options.max_evaluations = 100000;
    options.x_tolerance = 1e-9;
    auto objective = NegatedRastrigin(BoxSpec(4, 3.0, 5.12));
    Theta theta;
    OptimizerSummary one_run;
    Solve(options, objective, &theta, &one_run);
    ASSERT_EQ(one_run.termination_type, TerminationType::kConvergence) << one_run.FullReport();
    if (one_run.best_value > -1e-6) continue;  // this seed's one run found the global maximum anyway
    ++stayed;
    options.restarts = 8;
    OptimizerSummary restarted;
    Solve(options, objective, &theta, &restarted);
    EXPECT_GT(restarted.best_value, -1e-6) << restarted.FullReport();
    EXPECT_THAT(restarted.message, HasSubstr("restart"));
    rescued += restarted.best_value > -1e-6 ? 1 : 0;
  }
  // One run stays on a local maximum (U-hat -1 to -11) from every seed of 10 (seeds 0 to 9 were checked);
  // the restarted runs all end on the global one.
  EXPECT_GE(stayed, 8);
  EXPECT_EQ(rescued, stayed);
}

// A flat U-hat stalls every run after stall_generations + 1 generations; each restart doubles the population,
// so the evaluations are 1 + (g + 1) (lambda + 2 lambda + 4 lambda).
TEST(Cmaes, AStalledRunRestartsWithTwiceThePopulationUntilNoRestartsRemain) {
  FunctionObjective flat(BoxSpec(3, 0.0, 1.0), [](std::span<const double>) { return 1.0; });
  CmaesOptions options;
  options.population_size = 6;
  options.stall_generations = 5;
  options.restarts = 2;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, flat, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kConvergence);
  EXPECT_EQ(summary.iterations, 3 * 6);
  EXPECT_EQ(summary.evaluations, 1 + 6 * (6 + 12 + 24));
  EXPECT_THAT(summary.message, HasSubstr("stall_tolerance"));
  EXPECT_THAT(summary.message, HasSubstr("after 2 restarts, population 24"));
  // Without restarts the one run stops at its stall.
  options.restarts = 0;
  Solve(options, flat, &theta, &summary);
  EXPECT_EQ(summary.iterations, 6);
}

// A checkpoint taken after a restart carries the restart count, the run's first iteration, its best values
// and the start, so the resumed run ends as the uninterrupted one, bit for bit.
TEST(Cmaes, ResumedAfterARestartEndsBitIdenticallyToTheUninterruptedRun) {
  auto make = [] { return NegatedRastrigin(BoxSpec(3, 2.0, 5.12)); };
  CmaesOptions options;
  options.seed = 5;
  options.initial_step = 0.5;
  options.stall_generations = 15;
  options.stall_tolerance = 1e-3;
  options.restarts = 3;
  options.max_evaluations = 6000;
  options.checkpoint_every = 1;
  std::vector<json> checkpoints;
  options.on_checkpoint = [&](const json& j) { checkpoints.push_back(j); };
  auto objective = make();
  Theta reference_theta;
  OptimizerSummary reference;
  Solve(options, objective, &reference_theta, &reference);
  ASSERT_THAT(reference.message, HasSubstr("restart")) << reference.FullReport();
  const auto after = std::find_if(checkpoints.begin(), checkpoints.end(), [](const json& c) {
    return c["state"]["restarts"].get<int>() == 1 && c["state"]["run_best"].size() > 3;
  });
  ASSERT_NE(after, checkpoints.end());
  EXPECT_EQ((*after)["state"]["population"], 2 * CmaesPopulationSize(options, 3));
  auto fresh = make();
  options.on_checkpoint = [](const json&) {};
  options.resume_from = *after;
  Theta theta;
  OptimizerSummary resumed;
  Solve(options, fresh, &theta, &resumed);
  std::string difference;
  EXPECT_TRUE(SameOutcome(resumed, reference, &difference)) << difference;
  for (std::size_t i = 0; i < theta.size(); ++i) EXPECT_EQ(Bits(theta[i]), Bits(reference_theta[i]));
  // More restarts than the options allow, or a checkpoint of a run without restarts, is refused.
  options.restarts = 0;
  EXPECT_THAT([&] { Solve(options, fresh, &theta, &resumed); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("state.restarts")));
}

TEST(Cmaes, EvaluatesOnlyInsideTheBoundsAndConvergesToTheCornerBeyondWhichThePeakLies) {
  ParameterSpec spec({{.name = "a", .initial = 0.0, .lower = -1.0, .upper = 1.0},
                      {.name = "b", .initial = 0.0, .lower = -1.0, .upper = 1.0, .scale = 0.5},
                      {.name = "c", .initial = 0.2, .lower = 0.0, .upper = 4.0}});
  auto quadratic = ConcaveQuadratic(spec, {0.5, 3.0, -2.0}, {1.0, 1.0, 1.0});
  std::int64_t outside = 0;
  FunctionObjective checked(spec, [&](std::span<const double> theta) {
    if (!spec.contains(theta)) ++outside;
    return quadratic.evaluate(theta);
  });
  CmaesOptions options;
  options.initial_step = 1.0;  // many early samples fall beyond the bounds
  options.max_evaluations = 3000;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, checked, &theta, &summary);
  EXPECT_EQ(outside, 0);
  EXPECT_EQ(summary.termination_type, TerminationType::kConvergence) << summary.FullReport();
  EXPECT_NEAR(theta[0], 0.5, 1e-6);
  EXPECT_NEAR(theta[1], 1.0, 1e-12);
  EXPECT_NEAR(theta[2], 0.0, 1e-12);
}

TEST(Cmaes, EvaluatesTheStartAloneAndThenEachGenerationInOneBatch) {
  auto inner = NegatedRosenbrock(BoxSpec(6, 0.0, 5.0));
  CountingObjective counting(inner);
  CmaesOptions options;
  options.max_iterations = 25;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, counting, &theta, &summary);
  const int lambda = CmaesPopulationSize(options, 6);
  EXPECT_EQ(lambda, 4 + 5);  // 4 + floor(3 ln 6)
  EXPECT_EQ(counting.evaluate_calls, 1);
  ASSERT_EQ(counting.batch_sizes.size(), 25u);
  for (const std::size_t size : counting.batch_sizes) EXPECT_EQ(size, static_cast<std::size_t>(lambda));
  EXPECT_EQ(summary.evaluations, 1 + 25 * lambda);
  EXPECT_EQ(summary.iterations, 25);
  ASSERT_EQ(summary.history.size(), 25u);
  for (std::size_t k = 1; k < summary.history.size(); ++k)
    EXPECT_GE(summary.history[k].value, summary.history[k - 1].value);
}

TEST(Cmaes, GivesBitIdenticalResultsWhenRunTwiceAndOtherResultsForAnotherSeed) {
  auto run = [](std::uint64_t seed) {
    auto objective = NegatedRosenbrock(BoxSpec(3, 0.5, 5.0));
    CmaesOptions options;
    options.seed = seed;
    options.max_iterations = 60;
    Theta theta;
    OptimizerSummary summary;
    Solve(options, objective, &theta, &summary);
    return summary;
  };
  const OptimizerSummary a = run(7), b = run(7), c = run(8);
  std::string difference;
  EXPECT_TRUE(SameOutcome(a, b, &difference)) << difference;
  EXPECT_FALSE(SameOutcome(a, c));
  EXPECT_NE(Bits(a.best_value), Bits(c.best_value));
}

TEST(Cmaes, ALargeSearchUsesEigensFixedCacheSizesNotTheCpus) {
  // Eigen splits large matrix products and blocked decompositions by cache sizes, which changes the order of
  // the sums and so the last bits. At 300 parameters (an MLP policy's size) the covariance's
  // eigendecomposition and its inverse square root are that large. The library is built so that Eigen never
  // asks the CPU (EIGEN_NO_CPUID): the sizes are Eigen's fixed defaults, and a run under them set by hand is
  // the same run, candidate for candidate. Without that, this machine's own sizes would be used.
#if defined(__x86_64__)
  EXPECT_EQ(Eigen::l1CacheSize(), 32 * 1024);
  EXPECT_EQ(Eigen::l2CacheSize(), 256 * 1024);
  EXPECT_EQ(Eigen::l3CacheSize(), 2 * 1024 * 1024);
#endif
  auto run = [] {
    std::vector<double> candidates;
    FunctionObjective objective(BoxSpec(300, 0.5, 5.0), [&candidates](std::span<const double> theta) {
      candidates.insert(candidates.end(), theta.begin(), theta.end());
      double sum = 0.0;
      for (std::size_t i = 0; i + 1 < theta.size(); ++i) {
        const double a = theta[i + 1] - theta[i] * theta[i];
        sum += 100.0 * a * a + (1.0 - theta[i]) * (1.0 - theta[i]) + 0.1 * theta[i] * theta[i + 1];
      }
      return -sum;
    });
    CmaesOptions options;
    options.max_iterations = 16;
    Theta theta;
    OptimizerSummary summary;
    Solve(options, objective, &theta, &summary);
    candidates.push_back(summary.best_value);
    return candidates;
  };
  const std::ptrdiff_t l1 = Eigen::l1CacheSize(), l2 = Eigen::l2CacheSize(), l3 = Eigen::l3CacheSize();
  const std::vector<double> as_built = run();
  Eigen::setCpuCacheSizes(32 * 1024, 256 * 1024, 2 * 1024 * 1024);
  const std::vector<double> fixed_sizes = run();
  Eigen::setCpuCacheSizes(16 * 1024, 128 * 1024, 1024 * 1024);
  const std::vector<double> smaller_sizes = run();
  Eigen::setCpuCacheSizes(l1, l2, l3);
  ASSERT_EQ(as_built.size(), fixed_sizes.size());
  std::size_t differing = 0, differing_when_smaller = 0;
  for (std::size_t i = 0; i < as_built.size(); ++i) {
    differing += Bits(as_built[i]) != Bits(fixed_sizes[i]);
    differing_when_smaller += Bits(as_built[i]) != Bits(smaller_sizes[i]);
  }
  EXPECT_EQ(differing, 0U) << "of " << as_built.size() << " numbers";
  // The size is large enough for the blocking to matter: other sizes do give another run.
  EXPECT_GT(differing_when_smaller, as_built.size() / 10);
}

TEST(Cmaes, PowerOfTwoScalesGiveTheSameRunBitForBit) {
  // Sampling happens in scaled units: multiplying a parameter's range, start and scale by 4 (exact in
  // binary) multiplies every candidate by 4 and changes nothing else.
  auto make = [](double factor) {
    ParameterSpec spec({{.name = "a", .initial = 0.3, .lower = -2.0, .upper = 2.0},
                        {.name = "b",
                         .initial = -0.1 * factor,
                         .lower = -1.0 * factor,
                         .upper = 1.5 * factor,
                         .scale = factor}});
    return FunctionObjective(spec, [factor](std::span<const double> t) {
      const double b = t[1] / factor;
      return -std::pow(t[0] - 0.4, 2) - 3.0 * std::pow(b - 1.7, 2) - t[0] * b;
    });
  };
  auto plain = make(1.0), scaled = make(4.0);
  CmaesOptions options;
  options.max_iterations = 80;
  Theta theta_plain, theta_scaled;
  OptimizerSummary a, b;
  Solve(options, plain, &theta_plain, &a);
  Solve(options, scaled, &theta_scaled, &b);
  ASSERT_EQ(a.history.size(), b.history.size());
  for (std::size_t k = 0; k < a.history.size(); ++k)
    ASSERT_EQ(Bits(a.history[k].value), Bits(b.history[k].value)) << k;
  EXPECT_EQ(Bits(theta_plain[0]), Bits(theta_scaled[0]));
  EXPECT_EQ(Bits(4.0 * theta_plain[1]), Bits(theta_scaled[1]));
  EXPECT_NEAR(theta_plain[1], 1.5, 1e-12);  // the peak b = 1.7 lies beyond the bound
}

TEST(Cmaes, ResumedFromACheckpointEndsBitIdenticallyToTheUninterruptedRun) {
  auto make = [] { return NegatedRosenbrock(BoxSpec(5, -0.5, 5.0)); };
  CmaesOptions options;
  options.seed = 3;
  options.max_evaluations = 2500;
  std::vector<std::string> checkpoints;
  options.checkpoint_every = 20;
  options.on_checkpoint = [&](const json& j) { checkpoints.push_back(j.dump()); };
  auto objective = make();
  Theta reference_theta;
  OptimizerSummary reference;
  Solve(options, objective, &reference_theta, &reference);
  ASSERT_GE(checkpoints.size(), 5u) << reference.BriefReport();

  const json checkpoint = json::parse(checkpoints[2]);
  EXPECT_EQ(checkpoint["iterations"], 60);
  EXPECT_EQ(checkpoint["method"], "cmaes");
  auto fresh = make();
  CountingObjective counting(fresh);
  options.on_checkpoint = [](const json&) {};
  options.resume_from = checkpoint;
  Theta theta = {9.0};  // ignored on resume
  OptimizerSummary resumed;
  Solve(options, counting, &theta, &resumed);
  std::string difference;
  EXPECT_TRUE(SameOutcome(resumed, reference, &difference)) << difference;
  ASSERT_EQ(theta.size(), reference_theta.size());
  for (std::size_t i = 0; i < theta.size(); ++i) EXPECT_EQ(Bits(theta[i]), Bits(reference_theta[i]));
  EXPECT_EQ(Bits(resumed.final_step), Bits(reference.final_step));
  EXPECT_TRUE(resumed.resumed);
  EXPECT_EQ(counting.thetas_evaluated, reference.evaluations - checkpoint["evaluations"].get<std::int64_t>());
  EXPECT_EQ(counting.evaluate_calls, 0);
}

TEST(Cmaes, ARunEndedByTheFunctionToleranceEndsAtTheSameGenerationWhenResumed) {
  // The function tolerance looks back over recent generations, so the checkpoint must carry them.
  auto make = [] { return ConcaveQuadratic(BoxSpec(3, 2.0, 10.0), {0.5, -1.0, 3.0}, {1.0, 0.3, 2.0}); };
  CmaesOptions options;
  options.x_tolerance = 0.0;
  std::vector<json> checkpoints;
  options.checkpoint_every = 5;
  options.on_checkpoint = [&](const json& j) { checkpoints.push_back(j); };
  auto objective = make();
  Theta reference_theta;
  OptimizerSummary reference;
  Solve(options, objective, &reference_theta, &reference);
  ASSERT_EQ(reference.termination_type, TerminationType::kConvergence);
  ASSERT_THAT(reference.message, HasSubstr("function_tolerance"));
  ASSERT_GE(checkpoints.size(), 2u);

  options.on_checkpoint = [](const json&) {};
  options.resume_from = checkpoints.back();
  auto fresh = make();
  Theta theta;
  OptimizerSummary resumed;
  Solve(options, fresh, &theta, &resumed);
  std::string difference;
  EXPECT_TRUE(SameOutcome(resumed, reference, &difference)) << difference;
}

TEST(Cmaes, RefusesACheckpointOfAnotherPopulationSizeOrAMalformedState) {
  auto objective = NegatedRosenbrock(BoxSpec(3, 0.0, 5.0));
  CmaesOptions options;
  options.max_iterations = 4;
  options.checkpoint_every = 2;
  json saved;
  options.on_checkpoint = [&](const json& j) { saved = j; };
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_EQ(saved["iterations"], 4);

  CmaesOptions resume = options;
  resume.resume_from = saved;
  resume.population_size = 12;
  EXPECT_THAT([&] { Solve(resume, objective, &theta, &summary); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("state.population")));
  resume.population_size = 0;
  (*resume.resume_from)["state"]["C"].erase(0);
  EXPECT_THAT([&] { Solve(resume, objective, &theta, &summary); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("state.C: expected 9 numbers, got 8")));
  resume.resume_from = saved;
  (*resume.resume_from)["state"]["mean"][1] = "inf";
  EXPECT_THAT([&] { Solve(resume, objective, &theta, &summary); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("state.mean")));
}

TEST(Cmaes, StopsAtMaxIterationsAndNeverPassesMaxEvaluations) {
  auto objective = NegatedRastrigin(BoxSpec(4, 2.0, 5.12));
  CmaesOptions options;
  options.max_iterations = 0;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kMaxIterations);
  EXPECT_EQ(summary.evaluations, 1);
  EXPECT_EQ(theta, Theta(4, 2.0));

  options.max_iterations = 1000;
  options.max_evaluations = 100;  // 1 + 12 generations of 8
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.termination_type, TerminationType::kMaxEvaluations);
  EXPECT_EQ(summary.evaluations, 97);
  EXPECT_EQ(summary.iterations, 12);
  EXPECT_THAT(summary.message, HasSubstr("max_evaluations = 100"));
}

TEST(Cmaes, TheDispatcherRunsItAsMethodCmaesWithPrefixedErrors) {
  auto objective = ConcaveQuadratic(BoxSpec(2, 0.0, 3.0), {1.0, -1.0}, {1.0, 2.0});
  OptimizerOptions options;
  options.method = "cmaes";
  options.cmaes.population_size = 1;
  std::string error;
  EXPECT_FALSE(options.IsValid(&error));
  EXPECT_THAT(error, StartsWith("cmaes.population_size:"));
  options.cmaes.population_size = 6;
  std::vector<json> checkpoints;
  options.SetCheckpointing(3, [&](const json& c) { checkpoints.push_back(c); });
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  EXPECT_EQ(summary.method, "cmaes");
  ASSERT_FALSE(checkpoints.empty());
  EXPECT_EQ(CheckpointMethod(checkpoints.front()), "cmaes");
  EXPECT_EQ(checkpoints.front()["state"]["population"], 6);
  EXPECT_NEAR(theta[0], 1.0, 1e-5);
  EXPECT_NEAR(theta[1], -1.0, 1e-5);
}

TEST(CmaesOptions, IsValidRejectsEachBadFieldByName) {
  const std::vector<std::pair<std::string, std::function<void(CmaesOptions&)>>> cases = {
      {"max_iterations", [](CmaesOptions& o) { o.max_iterations = -1; }},
      {"max_evaluations", [](CmaesOptions& o) { o.max_evaluations = 0; }},
      {"population_size", [](CmaesOptions& o) { o.population_size = 1; }},
      {"population_size", [](CmaesOptions& o) { o.population_size = -3; }},
      {"initial_step", [](CmaesOptions& o) { o.initial_step = 0.0; }},
      {"initial_step", [](CmaesOptions& o) { o.initial_step = INFINITY; }},
      {"x_tolerance", [](CmaesOptions& o) { o.x_tolerance = -1e-9; }},
      {"function_tolerance", [](CmaesOptions& o) { o.function_tolerance = NAN; }},
      {"max_condition", [](CmaesOptions& o) { o.max_condition = 1.0; }},
      {"stall_generations", [](CmaesOptions& o) { o.stall_generations = -1; }},
      {"stall_tolerance", [](CmaesOptions& o) { o.stall_tolerance = NAN; }},
      {"restarts", [](CmaesOptions& o) { o.restarts = 21; }},
      {"on_checkpoint", [](CmaesOptions& o) { o.checkpoint_every = 5; }},
  };
  std::string error;
  EXPECT_TRUE(CmaesOptions{}.IsValid(&error)) << error;
  for (const auto& [field, breaks] : cases) {
    CmaesOptions options;
    breaks(options);
    EXPECT_FALSE(options.IsValid(&error)) << field;
    EXPECT_THAT(error, StartsWith(field + ":"));
    auto objective = NegatedRosenbrock(BoxSpec(2, 0.0, 1.0));
    Theta theta;
    OptimizerSummary summary;
    EXPECT_THROW(Solve(options, objective, &theta, &summary), InputError) << field;
  }
}

}  // namespace
}  // namespace pegasus
