// Checkpoint/resume: a run stopped after any checkpoint and resumed from it ends bit-identically to one
// that never stopped (wall-clock seconds aside), for every method.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <thread>

#include "pegasus/core/error.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "support/bits.hpp"
#include "support/test_problems.hpp"

namespace pegasus {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

using test_support::Bits;

TEST(CheckpointJson, DoublesRoundTripBitForBitThroughJsonText) {
  std::vector<double> values = {0.1,
                                1.0 / 3.0,
                                -0.0,
                                0.0,
                                5e-324,
                                2.2250738585072014e-308,
                                std::numeric_limits<double>::max(),
                                -std::numeric_limits<double>::max(),
                                std::nextafter(1.0, 2.0),
                                123456789.123456789,
                                -50000.0,
                                std::numeric_limits<double>::infinity(),
                                -std::numeric_limits<double>::infinity()};
  // And 20000 random bit patterns (finite ones), mostly far from round decimal numbers.
  CounterRng rng(2024);
  for (std::uint32_t k = 0; values.size() < 20013; ++k) {
    const double x = std::bit_cast<double>(rng.bits64(RngDomain::kStream, k, 0, 77));
    if (std::isfinite(x)) values.push_back(x);
  }
  const json written = VectorToJson(values);
  const std::vector<double> read = VectorFromJson(json::parse(written.dump()), "values");
  ASSERT_EQ(read.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) ASSERT_EQ(Bits(read[i]), Bits(values[i])) << values[i];

  EXPECT_TRUE(std::isnan(DoubleFromJson(json::parse(DoubleToJson(std::nan("")).dump()), "x")));
  EXPECT_THROW(DoubleFromJson(json("Infinity"), "x"), InputError);
}

// A problem for one method: its objective and options small enough to run many times.
struct MethodCase {
  std::string method;
  std::function<FunctionObjective()> make_objective;
  std::function<void(OptimizerOptions&)> configure;
  std::int64_t checkpoint_every;
};

std::vector<MethodCase> EveryMethod() {
  auto rosenbrock = [] { return NegatedRosenbrock(RosenbrockSpec()); };
  auto rastrigin = [] { return NegatedRastrigin(RastriginSpec()); };
  return {
      {"exhaustive",
       [] {
         return FunctionObjective(
             ParameterSpec({{.name = "a", .lower = 0, .upper = 3, .integer = true},
                            {.name = "b", .lower = 0, .upper = 4, .integer = true},
                            {.name = "c", .lower = -2, .upper = 2, .integer = true}}),
             [](std::span<const double> t) { return std::sin(1.3 * t[0] + 0.7 * t[1] * t[2]); });
       },
       [](OptimizerOptions& o) {
         o.exhaustive.block_size = 7;
         o.exhaustive.keep_all_values = true;
       },
       2},
      {"gradient", rosenbrock, [](OptimizerOptions& o) { o.gradient.max_iterations = 60; }, 7},
      {"hill-climb", rosenbrock,
       [](OptimizerOptions& o) {
         o.hill_climbing.max_iterations = 150;
         o.hill_climbing.proposals_per_iteration = 3;
         o.hill_climbing.seed = 5;
       },
       13},
      {"bobyqa", rosenbrock, [](OptimizerOptions&) {}, 10},
      {"sbplx", rosenbrock, [](OptimizerOptions& o) { o.nlopt.max_evaluations = 400; }, 25},
      {"crs2", rastrigin,
       [](OptimizerOptions& o) {
         o.nlopt.max_evaluations = 600;
         o.nlopt.seed = 3;
       },
       50},
      {"esch", rastrigin,
       [](OptimizerOptions& o) {
         o.nlopt.max_evaluations = 600;
         o.nlopt.seed = 3;
       },
       50},
      {"cmaes", rosenbrock,
       [](OptimizerOptions& o) {
         o.cmaes.max_iterations = 120;
         o.cmaes.seed = 2;
       },
       11},
      {"ars", rosenbrock,
       [](OptimizerOptions& o) {
         o.ars.max_iterations = 40;
         o.ars.directions = 3;
         o.ars.top_directions = 2;
         o.ars.seed = 5;
       },
       9},
  };
}

// A checkpoint with every wall-clock number zeroed, for comparing checkpoints of two runs.
json WithoutSeconds(json checkpoint) {
  checkpoint["elapsed_seconds"] = 0.0;
  for (auto& row : checkpoint["history"]) row[3] = 0.0;
  if (checkpoint["state"].contains("log"))
    for (auto& row : checkpoint["state"]["log"]) row[2] = 0.0;
  return checkpoint;
}

TEST(CheckpointJson, AFinishedSummaryRoundTripsThroughJsonText) {
  ParameterSpec spec;
  spec.add({.name = "x", .initial = -1.0, .lower = -3.0, .upper = 3.0, .scale = 0.5});
  spec.add({.name = "y", .initial = 2.0, .lower = -3.0, .upper = 3.0, .scale = 0.5});
  auto objective = ConcaveQuadratic(spec, {0.3, -0.7}, {1.0, 2.0});
  OptimizerOptions options;
  options.method = "hill-climb";
  options.hill_climbing.max_iterations = 25;
  options.hill_climbing.proposals_per_iteration = 3;
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_EQ(summary.history.size(), 25u);
  const OptimizerSummary read = SummaryFromJson(json::parse(SummaryToJson(summary).dump()), "stage");
  std::string difference;
  EXPECT_TRUE(SameOutcome(read, summary, &difference)) << difference;
  EXPECT_EQ(read.wall_seconds, summary.wall_seconds);
  json bad = SummaryToJson(summary);
  bad["best_value"] = "many";
  EXPECT_THAT([&] { SummaryFromJson(bad, "stage"); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("stage.best_value")));
}

TEST(CheckpointResume, EveryMethodEndsBitIdenticallyWhenResumedFromAnyOfSeveralCheckpoints) {
  for (const auto& c : EveryMethod()) {
    SCOPED_TRACE(c.method);
    // The uninterrupted run, keeping every checkpoint as the text a file would hold.
    auto objective = c.make_objective();
    OptimizerOptions options;
    options.method = c.method;
    c.configure(options);
    std::vector<std::string> checkpoints;
    options.SetCheckpointing(c.checkpoint_every, [&](const json& j) { checkpoints.push_back(j.dump()); });
    Theta reference_theta;
    OptimizerSummary reference;
    Solve(options, objective, &reference_theta, &reference);
    ASSERT_GE(checkpoints.size(), 3u) << reference.BriefReport();

    for (const std::size_t k : {std::size_t{0}, checkpoints.size() / 2, checkpoints.size() - 1}) {
      SCOPED_TRACE("resumed from checkpoint " + std::to_string(k));
      const json checkpoint = json::parse(checkpoints[k]);
      auto fresh = c.make_objective();
      CountingObjective counting(fresh);
      std::vector<std::string> later;
      options.SetCheckpointing(
          c.checkpoint_every, [&](const json& j) { later.push_back(j.dump()); }, checkpoint);
      Theta theta = {0.5, 0.5};  // ignored on resume
      OptimizerSummary resumed;
      Solve(options, counting, &theta, &resumed);

      std::string difference;
      EXPECT_TRUE(SameOutcome(resumed, reference, &difference)) << difference;
      EXPECT_EQ(theta, reference_theta);
      for (std::size_t i = 0; i < theta.size(); ++i) EXPECT_EQ(Bits(theta[i]), Bits(reference_theta[i]));
      EXPECT_TRUE(resumed.resumed);
      // Nothing before the checkpoint is evaluated again (NLopt answers it from the log).
      EXPECT_EQ(counting.thetas_evaluated,
                reference.evaluations - checkpoint["evaluations"].get<std::int64_t>());
      // The resumed run writes the same later checkpoints as the uninterrupted one.
      ASSERT_EQ(later.size(), checkpoints.size() - k - 1);
      for (std::size_t j = 0; j < later.size(); ++j)
        EXPECT_EQ(WithoutSeconds(json::parse(later[j])), WithoutSeconds(json::parse(checkpoints[k + 1 + j])))
            << "later checkpoint " << j;
    }
  }
}

TEST(CheckpointResume, RefusesACheckpointOfAnotherParameterSet) {
  auto objective = NegatedRosenbrock(RosenbrockSpec());
  GradientAscentOptions options;
  options.max_iterations = 3;
  options.checkpoint_every = 1;
  json saved;
  options.on_checkpoint = [&](const json& j) { saved = j; };
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);

  auto other = NegatedRosenbrock(ParameterSpec({{.name = "x"}, {.name = "z"}}));
  options.resume_from = saved;
  try {
    Solve(options, other, &theta, &summary);
    ADD_FAILURE() << "resumed a checkpoint of another parameter set";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("checkpoint parameters"));
  }
}

TEST(CheckpointResume, NloptRefusesALogThatNloptDoesNotRetrace) {
  auto objective = NegatedRastrigin(RastriginSpec());
  NloptOptions options;
  options.algorithm = NloptAlgorithm::kCrs2;
  options.max_evaluations = 300;
  options.checkpoint_every = 100;
  json saved;
  options.on_checkpoint = [&](const json& j) {
    if (j["evaluations"] == 200) saved = j;
  };
  Theta theta;
  OptimizerSummary summary;
  Solve(options, objective, &theta, &summary);
  ASSERT_EQ(saved["evaluations"], 200);

  NloptOptions resume = options;
  resume.resume_from = saved;
  (*resume.resume_from)["state"]["log"][57][0][1] =
      std::nextafter(saved["state"]["log"][57][0][1].get<double>(), 9.0);
  try {
    Solve(resume, objective, &theta, &summary);
    ADD_FAILURE() << "accepted a log NLopt does not retrace";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("evaluation 58"));
  }

  resume = options;
  resume.seed = 4;
  resume.resume_from = saved;
  EXPECT_THROW(Solve(resume, objective, &theta, &summary), InputError);
}

// An objective that takes its time, so a process can be killed in the middle of a run.
class SlowObjective final : public Objective {
 public:
  explicit SlowObjective(Objective& inner) : inner_(inner) {}
  const ParameterSpec& parameters() const override { return inner_.parameters(); }
  double evaluate(std::span<const double> theta) override { return inner_.evaluate(theta); }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(3));
    inner_.evaluate_batch(thetas, values);
  }

 private:
  Objective& inner_;
};

void WriteAtomically(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  {
    std::ofstream out(temporary, std::ios::trunc);
    out << text;
    out.flush();
    if (!out) _exit(4);
  }
  if (std::rename(temporary.c_str(), path.c_str()) != 0) _exit(5);
}

TEST(CheckpointResume, GradientAscentResumesBitIdenticallyAfterTheProcessIsKilled) {
  const std::string path =
      ::testing::TempDir() + "pegasus_sigkill_checkpoint_" + std::to_string(::getpid()) + ".json";
  std::filesystem::remove(path);
  GradientAscentOptions options;
  options.max_iterations = 80;

  auto objective = NegatedRosenbrock(RosenbrockSpec());
  Theta reference_theta;
  OptimizerSummary reference;
  Solve(options, objective, &reference_theta, &reference);
  ASSERT_EQ(reference.iterations, 80) << reference.BriefReport();

  const pid_t child = ::fork();
  ASSERT_NE(child, -1);
  if (child == 0) {
    // The child: the same run, slowed down, writing each checkpoint to the file atomically.
    SlowObjective slow(objective);
    options.checkpoint_every = 4;
    options.on_checkpoint = [&path](const json& checkpoint) { WriteAtomically(path, checkpoint.dump()); };
    Theta theta;
    OptimizerSummary summary;
    try {
      Solve(options, slow, &theta, &summary);
    } catch (...) {
      _exit(3);
    }
    _exit(0);
  }

  // The parent: kill the child as soon as it has written a checkpoint.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  int status = 0;
  bool exited_early = false;
  while (!std::filesystem::exists(path) && std::chrono::steady_clock::now() < deadline) {
    if (::waitpid(child, &status, WNOHANG) == child) {
      exited_early = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  if (!exited_early) {
    ::kill(child, SIGKILL);
    ASSERT_EQ(::waitpid(child, &status, 0), child);
  }
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "the child was not killed mid-run";

  std::ifstream in(path);
  ASSERT_TRUE(in) << "no checkpoint at " << path;
  std::stringstream text;
  text << in.rdbuf();
  const json checkpoint = json::parse(text.str());
  EXPECT_LT(checkpoint["iterations"].get<std::int64_t>(), 80);

  options.resume_from = checkpoint;
  Theta theta;
  OptimizerSummary resumed;
  Solve(options, objective, &theta, &resumed);
  std::string difference;
  EXPECT_TRUE(SameOutcome(resumed, reference, &difference)) << difference;
  for (std::size_t i = 0; i < theta.size(); ++i) EXPECT_EQ(Bits(theta[i]), Bits(reference_theta[i]));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace pegasus
