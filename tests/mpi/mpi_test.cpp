// Distributed evaluation (include/pegasus/parallel/mpi.hpp): the ownership arithmetic in process, and the CLI
// under `mpirun -np N` against the single-process run, bit for bit.
//
// The mpirun tests skip, saying why, when this build has no MPI or mpirun is not on PATH. They set, for
// themselves and the ranks they start:
//   OMPI_ALLOW_RUN_AS_ROOT=1, OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1   CI runs as root; Open MPI refuses root
//   without
//                                                                 both
//   OMPI_MCA_btl_vader_single_copy_mechanism=none                 containers often forbid the cross-memory
//                                                                 attach Open MPI's shared-memory transport
//                                                                 uses; plain copies work everywhere
//   OMPI_MCA_rmaps_base_oversubscribe=1                           more ranks than cores on a small CI machine
// Under the sanitizers (PEGASUS_SANITIZED=1) the mpirun tests skip, saying why: LeakSanitizer reports what
// Open MPI itself keeps allocated at exit, in plugins it has unloaded by then, so no suppression can name
// them. Linking Open MPI without starting it (every other test) leaks nothing.
#include "pegasus/parallel/mpi.hpp"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numeric>
#include <string>
#include <vector>

#include "pegasus/envs/pendulum.hpp"
#include "pegasus/envs/pendulum_policy.hpp"
#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/parallel/job_transport.hpp"
#include "pegasus/runs/run_directory.hpp"
#include "support/cli_runner.hpp"

namespace fs = std::filesystem;

namespace {

using pegasus::mpi::Share;
using pegasus::test_support::CliResult;
using pegasus::test_support::read_text;
using pegasus::test_support::run_shell;

// ---- In process: ownership and the one-rank path --------------------------------------------------------

TEST(MpiShare, EveryItemHasExactlyOneOwner) {
  for (int size : {1, 2, 3, 7}) {
    for (std::size_t n : {0u, 1u, 2u, 5u, 64u, 1001u}) {
      std::vector<int> owners(n, 0);
      std::size_t total = 0;
      for (int rank = 0; rank < size; ++rank) {
        const Share share{rank, size};
        total += share.count(n);
        for (std::size_t j = 0; j < share.count(n); ++j) {
          ASSERT_LT(share.item(j), n);
          ++owners[share.item(j)];
        }
      }
      EXPECT_EQ(total, n);
      for (std::size_t k = 0; k < n; ++k)
        EXPECT_EQ(owners[k], 1) << "item " << k << " of " << n << ", " << size << " ranks";
    }
  }
}

TEST(MpiShare, OneProcessIsOneRankAndFillsEverything) {
  EXPECT_EQ(pegasus::mpi::size(), 1);
  EXPECT_TRUE(pegasus::mpi::is_root());
  const Share whole = pegasus::mpi::collective_share(pegasus::mpi::Communicator::job());
  EXPECT_EQ(whole.size, 1);
  pegasus::ThreadPool pool(3);
  std::vector<double> values(100, -1.0);
  pegasus::mpi::distributed_fill(std::span<double>(values), &pool,
                                 [](std::size_t k) { return 0.5 * static_cast<double>(k); });
  for (std::size_t k = 0; k < values.size(); ++k) EXPECT_EQ(values[k], 0.5 * static_cast<double>(k));
  EXPECT_EQ(pegasus::mpi::comm_stats().calls, 0);
  // Inside a parallel_for body the calling thread may not start a collective, whatever the rank count (the
  // workers never may: they are not the main thread).
  pegasus::ThreadPool caller_only(1);
  caller_only.parallel_for(
      4, [](std::size_t) { EXPECT_TRUE(pegasus::ThreadPool::inside_parallel_for()); }, 1);
  EXPECT_FALSE(pegasus::ThreadPool::inside_parallel_for());
}

// ---- The CLI under mpirun -----------------------------------------------------------------------------

std::string find_mpirun() {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const fs::path candidate = fs::path(dirs.substr(start, end - start)) / "mpirun";
    std::error_code ec;
    if (end > start && fs::exists(candidate, ec)) return candidate.string();
    start = end + 1;
  }
  return {};
}

int count_lines_with(const std::string& text, const std::string& needle) {
  int count = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    if (text.substr(start, end - start).find(needle) != std::string::npos) ++count;
    start = end + 1;
  }
  return count;
}

class MpiCli : public pegasus::test_support::TempDirTest {
 protected:
  void SetUp() override {
    TempDirTest::SetUp();
    if (!pegasus::mpi::links_a_transport())
      GTEST_SKIP() << "this build has no MPI (PEGASUS_MPI=OFF): nothing to distribute";
    mpirun_ = find_mpirun();
    if (mpirun_.empty())
      GTEST_SKIP() << "mpirun is not on PATH (Debian: openmpi-bin): the MPI tests cannot run";
    setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
    setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
    setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 1);
    setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 1);
    if (std::getenv("PEGASUS_SANITIZED")) {
      // LeakSanitizer reports what Open MPI keeps allocated until exit, from plugins it has unloaded (frames
      // of "<unknown module>", which no suppression can name). The code under test is the single-process code
      // that every other test folder runs under the sanitizers; the in-process tests above run here too.
      GTEST_SKIP()
          << "sanitizer build: the mpirun tests run in the Release build only (LeakSanitizer reports "
             "Open MPI's own allocations from its unloaded plugins)";
    }
  }

  CliResult single(const std::string& args) const {
    return run_shell(std::string(PEGASUS_CLI_PATH) + " " + args);
  }
  // mpirun -np n pegasus args, with TMPDIR (Open MPI's session files, the ranks' scratch folders) in
  // dir_/tmp.
  CliResult ranks(int n, const std::string& args, const std::string& env = "") const {
    fs::create_directories(dir_ / "tmp");
    return run_shell("TMPDIR=" + (dir_ / "tmp").string() + " " + env + " " + mpirun_ + " -np " +
                     std::to_string(n) + " --oversubscribe " + PEGASUS_CLI_PATH + " " + args);
  }
  std::string out(const std::string& name) const { return " --out " + (dir_ / name).string(); }
  // The result files of a run directory that must match bit for bit (run.json holds wall time and argv).
  void expect_same_results(const std::string& reference, const std::string& other,
                           const std::vector<std::string>& files) const {
    for (const auto& f : files) {
      ASSERT_TRUE(fs::exists(dir_ / reference / f)) << f;
      EXPECT_EQ(read_text(dir_ / other / f), read_text(dir_ / reference / f))
          << other << "/" << f << " differs";
    }
  }
  nlohmann::json run_json(const std::string& name) const {
    return nlohmann::json::parse(read_text(dir_ / name / "run.json"));
  }

  // Runs this test binary's disabled suite `suite` under `mpirun -np 2`, with $PEGASUS_MPI_INNER_OUT = out
  // and a private TMPDIR (dir_/tmp).
  CliResult run_inner(const std::string& suite, const fs::path& out) const {
    fs::create_directories(dir_ / "tmp");
    return run_shell("TMPDIR=" + (dir_ / "tmp").string() + " PEGASUS_MPI_INNER_OUT=" + out.string() + " " +
                     mpirun_ + " -np 2 --oversubscribe " + fs::read_symlink("/proc/self/exe").string() +
                     " --gtest_also_run_disabled_tests --gtest_filter=" + suite + ".*");
  }

  std::string mpirun_;
};

// ---- The library under mpirun: an evaluator's ranks are its execution context's ---------------------------

// MPI for a test that another test runs under `mpirun -np 2` (MpiCli::run_inner), as main starts it.
class InnerSession {
 public:
  InnerSession() : session_(&argc_, &argv_, pegasus::mpi::linked_transport()) {}

 private:
  int argc_ = 1;
  char name_[9] = "test_mpi";
  char* args_[2] = {name_, nullptr};
  char** argv_ = args_;
  pegasus::mpi::Session session_;
};

using PendulumEvaluator = pegasus::PegasusEvaluator<pegasus::Pendulum, pegasus::PendulumSwingUpPolicy>;

PendulumEvaluator small_pendulum_evaluator() {
  return PendulumEvaluator(
      pegasus::Pendulum{}, pegasus::PendulumSwingUpPolicy(false),
      pegasus::ScenarioSet({.seed = 4, .count = 24, .horizon = 60, .noise_dim = 0, .initial_noise_dim = 2}),
      pegasus::Discounting{.gamma = 1.0, .horizon = 60});
}

// Policy k of a small sweep: the class's initial gains scaled by 1 + k / 10.
pegasus::Theta sweep_theta(const PendulumEvaluator& evaluator, std::size_t k) {
  pegasus::Theta theta = evaluator.policy().parameters().initial();
  for (double& x : theta) x *= 1.0 + 0.1 * static_cast<double>(k);
  return theta;
}

// Run by the test below under `mpirun -np 2` (gtest's --gtest_also_run_disabled_tests), never on its own: the
// same evaluation on the job's ranks and on this process alone, and a sweep whose items are split among the
// job's ranks while each item's evaluation runs on its owner alone. Rank 0 writes what it saw as JSON to
// $PEGASUS_MPI_INNER_OUT.
TEST(MpiRanksInner, DISABLED_EvaluatorsSplitAmongTheRanksOfTheirContext) {
  const InnerSession session;
  using pegasus::mpi::Communicator;
  const PendulumEvaluator evaluator = small_pendulum_evaluator();
  const pegasus::Theta theta = sweep_theta(evaluator, 0);
  pegasus::mpi::reset_comm_stats();
  const double on_job = evaluator.evaluate(theta, {nullptr, Communicator::job()});
  const std::int64_t job_calls = pegasus::mpi::comm_stats().calls;
  const double alone = evaluator.evaluate(theta, {nullptr, Communicator::this_process()});
  const std::int64_t alone_calls = pegasus::mpi::comm_stats().calls - job_calls;
  std::vector<double> sweep(5);
  pegasus::mpi::distributed_fill(
      std::span<double>(sweep), {nullptr, Communicator::job()}, [&](std::size_t k) {
        return evaluator.evaluate(sweep_theta(evaluator, k), {nullptr, Communicator::this_process()});
      });
  if (pegasus::mpi::is_root())
    std::ofstream(std::getenv("PEGASUS_MPI_INNER_OUT"))
        << nlohmann::json{{"ranks", Communicator::job().size()},
                          {"on_job", on_job},
                          {"job_calls", job_calls},
                          {"alone", alone},
                          {"alone_calls", alone_calls},
                          {"sweep", sweep}}
               .dump();
}

TEST_F(MpiCli, AnEvaluatorSplitsItsWorkAmongTheRanksItIsGivenAndNoOthers) {
  const fs::path result = dir_ / "inner.json";
  const auto r = run_inner("MpiRanksInner", result);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto seen = nlohmann::json::parse(read_text(result));
  EXPECT_EQ(seen.at("ranks"), 2);
  // On the job's ranks one allgather; on this process alone none, and the same bits.
  const PendulumEvaluator evaluator = small_pendulum_evaluator();
  const double single = evaluator.evaluate(sweep_theta(evaluator, 0));
  EXPECT_EQ(seen.at("job_calls"), 1);
  EXPECT_EQ(seen.at("alone_calls"), 0);
  EXPECT_EQ(seen.at("on_job").get<double>(), single);
  EXPECT_EQ(seen.at("alone").get<double>(), single);
  // The sweep: item k computed by its owner alone, gathered to every rank, equals the single process's value.
  for (std::size_t k = 0; k < 5; ++k)
    EXPECT_EQ(seen.at("sweep").at(k).get<double>(), evaluator.evaluate(sweep_theta(evaluator, k))) << k;
}

// Run by the test below under `mpirun -np 2`, never on its own: a directory opened among the job's ranks (the
// first writes it, the other is a shadow that reads the first's checkpoint) and one opened by each rank for
// itself alone (each writes its own, and reads its own checkpoint without a collective). Under
// $PEGASUS_MPI_INNER_OUT.
TEST(MpiRunDirectoryInner, DISABLED_ADirectoryBelongsToTheRanksItIsOpenedAmong) {
  const InnerSession session;
  using pegasus::mpi::Communicator;
  const fs::path root = std::getenv("PEGASUS_MPI_INNER_OUT");
  const int rank = Communicator::job().rank();
  pegasus::ConfigSchema schema;
  schema.add_int("seed", 1, "seed");

  pegasus::RunDirectory shared = pegasus::RunDirectory::open(root / "job", schema);
  shared.write_text("written_by.txt", std::to_string(rank));
  shared.save_checkpoint({{"rank", rank}});
  const nlohmann::json job_checkpoint = shared.load_checkpoint().value();
  shared.commit();

  pegasus::RunDirectory own = pegasus::RunDirectory::open(root / ("rank" + std::to_string(rank)), schema,
                                                          {.ranks = Communicator::this_process()});
  own.save_checkpoint({{"rank", rank}});
  own.write_json("seen.json", {{"rank", rank},
                               {"job_checkpoint", job_checkpoint.at("rank")},
                               {"own_checkpoint", own.load_checkpoint().value().at("rank")},
                               {"own_ranks", own.ranks().size()},
                               {"job_ranks", shared.ranks().size()}});
  own.commit();
}

TEST_F(MpiCli, ARunDirectoryIsWrittenByTheFirstOfTheRanksItIsOpenedAmong) {
  const auto r = run_inner("MpiRunDirectoryInner", dir_);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(read_text(dir_ / "job" / "written_by.txt"), "0");
  for (int rank = 0; rank < 2; ++rank) {
    const fs::path own = dir_ / ("rank" + std::to_string(rank));
    ASSERT_TRUE(fs::exists(own / "config.toml")) << own;
    const auto seen = nlohmann::json::parse(read_text(own / "seen.json"));
    EXPECT_EQ(seen.at("rank"), rank);
    EXPECT_EQ(seen.at("job_checkpoint"), 0) << "every rank of the job reads the first rank's checkpoint";
    EXPECT_EQ(seen.at("own_checkpoint"), rank) << "a directory of one rank reads its own";
    EXPECT_EQ(seen.at("own_ranks"), 1);
    EXPECT_EQ(seen.at("job_ranks"), 2);
  }
  // The shadow's scratch folder is gone.
  for (const auto& entry : fs::directory_iterator(dir_ / "tmp"))
    EXPECT_FALSE(entry.path().filename().string().starts_with("pegasus-rank")) << entry.path();
}

// Bicycle training on small settings: 6 scenarios of 1 s, hill climbing (one batch of 16 proposals per
// iteration, so the run cannot stop early) for 12 iterations; a checkpoint every 5 iterations.
const std::string kTrain =
    "bicycle train --scenarios 6 --horizon 100 --optimizer.method hill-climb "
    "--optimizer.hill-climbing.max-iterations 12 --rides 3 --max-km 1 "
    "--goal-km 0.3 --quiet --seed 3";
const std::vector<std::string> kTrainFiles = {"summary.json", "policy.json", "learning_curve.csv",
                                              "rides.csv"};

TEST_F(MpiCli, TrainingGivesTheSameFilesOnAnyNumberOfRanksAndThreads) {
  const auto one = single(kTrain + " --threads 1" + out("single"));
  ASSERT_EQ(one.code, 0) << one.output;
  struct Case {
    int ranks;
    int threads;
  };
  for (const Case c : {Case{1, 2}, Case{2, 2}, Case{3, 1}}) {
    const std::string name = "np" + std::to_string(c.ranks) + "t" + std::to_string(c.threads);
    const auto r = ranks(c.ranks, kTrain + " --threads " + std::to_string(c.threads) + out(name));
    ASSERT_EQ(r.code, 0) << r.output;
    expect_same_results("single", name, kTrainFiles);
    const auto provenance = run_json(name);
    EXPECT_EQ(provenance.at("ranks").get<int>(), c.ranks);
    // The work was split: every evaluation batch is one allgather.
    if (c.ranks > 1) {
      EXPECT_GT(provenance.at("allgathers").get<int>(), 12);
    }
    // Only rank 0 printed the result line.
    EXPECT_EQ(count_lines_with(r.output, "hill-climb: MAX_ITERATIONS"), 1) << r.output;
    // Ranks other than 0 wrote nothing, and removed their scratch folders (they live in TMPDIR).
    for (const auto& entry : fs::directory_iterator(dir_ / "tmp"))
      EXPECT_NE(entry.path().filename().string().rfind("pegasus-rank", 0), 0u) << entry.path();
  }
}

#ifdef PEGASUS_HAVE_MUJOCO
// MuJoCo cart-pole by ARS with observation normalisation (experiments/mujoco/): the normaliser's rollouts run
// on every rank, the perturbations' rollouts are split; step and crash counts are summed over ranks.
TEST_F(MpiCli, MujocoTrainingGivesTheSameFilesOnOneTwoAndThreeRanks) {
  const std::string exp = std::string(PEGASUS_SOURCE_DIR) + "/experiments/mujoco/";
  const std::string args =
      "mujoco train --model " + exp + "cartpole.xml --task " + exp +
      "cartpole_swingup.toml --policy mlp --hidden 4 --scenarios 5 --optimizer.ars.max-iterations 2 "
      "--optimizer.ars.directions 3 --optimizer.ars.top-directions 2 --evaluation-episodes 4 --quiet --seed "
      "4";
  const auto one = single(args + " --threads 1" + out("single"));
  ASSERT_EQ(one.code, 0) << one.output;
  for (const int n : {1, 2, 3}) {
    const std::string name = "np" + std::to_string(n);
    const auto r = ranks(n, args + " --threads 1" + out(name));
    ASSERT_EQ(r.code, 0) << r.output;
    expect_same_results("single", name, {"summary.json", "policy.json", "evaluation.csv"});
  }
}
#endif

// The bicycle experiment trains with PEGASUS, with the progress bonus and with naive Monte Carlo (whose
// rollouts are split too), then rides each policy.
TEST_F(MpiCli, ExperimentWithNaiveMonteCarloGivesTheSameFiles) {
  const std::string args =
      "bicycle experiment --trials 1 --lesson-trials 1 --scenarios 4 --horizon 100 "
      "--optimizer.gradient.max-iterations 2 --rides 2 "
      "--max-km 1 --goal-km 0.3 --quiet --seed 5 --threads 1";
  const auto one = single(args + out("single"));
  ASSERT_EQ(one.code, 0) << one.output;
  const auto three = ranks(3, args + out("np3"));
  ASSERT_EQ(three.code, 0) << three.output;
  expect_same_results(
      "single", "np3",
      {"summary.json", "trials.csv", "learning_curves.csv", "rides.csv", "policies/trial-0.json"});
  EXPECT_GT(run_json("np3").at("allgathers").get<int>(), 0);
}

// The gridworld's shared-trajectory search is not split (it takes milliseconds): every rank runs it whole,
// and the results are still those of one process. Its naive Monte Carlo batches are split.
TEST_F(MpiCli, CommandsThatRunWholeOnEveryRankGiveTheSameResults) {
  const std::string args =
      "pomdp-gridworld --scenarios 1,2 --trials 2 --montecarlo-max-m 2 --horizon 20 --quiet --threads 1";
  const auto one = single(args + out("single"));
  ASSERT_EQ(one.code, 0) << one.output;
  const auto two = ranks(2, args + out("np2"));
  ASSERT_EQ(two.code, 0) << two.output;
  expect_same_results("single", "np2", {"summary.json", "results.csv", "trials.csv"});
  EXPECT_GT(run_json("np2").at("allgathers").get<int>(), 0);
}

TEST_F(MpiCli, ADeadRankFailsTheJobAndResumingWithOtherRanksMatches) {
  const auto one = single(kTrain + " --threads 1" + out("single"));
  ASSERT_EQ(one.code, 0) << one.output;
  // Rank 1 is killed (SIGKILL) on entering its 9th allgather: after the checkpoint at iteration 5.
  const auto killed = ranks(2, kTrain + " --threads 1" + out("run"), "PEGASUS_TEST_MPI_KILL=1:9");
  EXPECT_NE(killed.code, 0) << killed.output;
  EXPECT_NE(killed.output.find("partial results kept in"), std::string::npos) << killed.output;
  EXPECT_NE(killed.output.find("rerun with --resume"), std::string::npos) << killed.output;
  EXPECT_FALSE(fs::exists(dir_ / "run"));
  ASSERT_TRUE(fs::exists(dir_ / "run.partial" / "checkpoint.json")) << killed.output;
  const auto checkpoint = nlohmann::json::parse(read_text(dir_ / "run.partial" / "checkpoint.json"));
  const std::int64_t done = pegasus::TrainingCheckpointIterations(checkpoint.at("optimizer"));
  EXPECT_GT(done, 0);
  EXPECT_LT(done, 12);
  // Resumed on three ranks: the same files as the uninterrupted single process.
  const auto resumed = ranks(3, kTrain + " --threads 1 --resume" + out("run"));
  ASSERT_EQ(resumed.code, 0) << resumed.output;
  expect_same_results("single", "run", kTrainFiles);
  EXPECT_TRUE(run_json("run").at("resumed").get<bool>());
}

TEST_F(MpiCli, BadInputIsReportedOnceWithExitCode2AndNoRunDirectory) {
  // Found while setting up (an option): every rank agrees and exits 2.
  const auto bad = ranks(2, kTrain + " --gamma 1.5" + out("a"));
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_EQ(count_lines_with(bad.output, "pegasus: "), 1) << bad.output;
  EXPECT_NE(bad.output.find("--gamma"), std::string::npos) << bad.output;
  // Found by the command while running (a missing policy file): rank 0 reports it and ends the job with 2.
  const auto missing =
      ranks(2, "bicycle ride --rides 2 --quiet --policy " + (dir_ / "absent.json").string() + out("b"));
  EXPECT_EQ(missing.code, 2) << missing.output;
  EXPECT_EQ(count_lines_with(missing.output, "absent.json"), 1) << missing.output;
  // An existing run directory: rank 0's refusal reaches every rank.
  ASSERT_EQ(single(kTrain + " --optimizer.hill-climbing.max-iterations 1 --rides 0" + out("c")).code, 0);
  const auto exists = ranks(2, kTrain + out("c"));
  EXPECT_EQ(exists.code, 2) << exists.output;
  EXPECT_EQ(count_lines_with(exists.output, "already exists"), 1) << exists.output;
  for (const char* name : {"a", "a.partial", "b", "b.partial", "c.partial"})
    EXPECT_FALSE(fs::exists(dir_ / name)) << name;
}

}  // namespace
