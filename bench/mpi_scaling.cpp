// Distributed evaluation of the hover problem (thesis §5.3) under mpirun: the measurements behind
// docs/scaling.md. Not a Google Benchmark (its adaptive iteration counts would differ between ranks and
// break the collectives); every rank runs the same fixed sequence and rank 0 writes one JSON file.
//
//   mpirun -np N pegasus_mpi_bench [--threads T] [--scenarios 30] [--seconds 35] [--repeats 3]
//                                  [--iteration-seconds 1] [--out FILE.json]
//
// Workload: the learned helicopter model identified from the default 339 s pilot log (as `heli identify`
// does; every rank identifies it, untimed), the hover task and policy class (34 weights, the starting weights
// from the log), m scenarios.
//   uhat          U-hat(theta_0) on m scenarios of `seconds` s: `repeats` timed calls, median.
//   iteration     one gradient-ascent iteration (2n probes in one batch, then the uphill line search) on m
//                 scenarios of `iteration_seconds` s (short flights keep it quick: less computation per
//                 byte sent, so its communication share is an upper bound for the real 35 s flights).
//                 Split into: serial (optimizer bookkeeping, the reductions and rank 0's checkpoint: wall
//                 time outside the objective; the checkpoint's share also apart), compute (rollouts on this
//                 rank), wait (the barrier before each allgather: the slowest rank's lag) and comm (the
//                 allgather itself, measured after that barrier).
//   allgather     MPI_Allgatherv of the real message sizes (one U-hat: m doubles; a gradient batch: 2n m),
//                 after a barrier, `allgather_repeats` times each; median and mean seconds per call.
// Keys of the JSON are described in docs/scaling.md.
#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pegasus/evaluators/pegasus_evaluator.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/optimizers/optimizer.hpp"
#include "pegasus/parallel/job_transport.hpp"
#include "pegasus/parallel/mpi.hpp"
#include "pegasus/sysid/identify.hpp"

namespace {

using namespace pegasus;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// CPU seconds of this process (all its threads): on a busy machine, the work done, apart from the waiting.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void barrier() { (void)mpi::allgather_int(0); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Times every call to the objective it wraps.
class TimedObjective final : public Objective {
 public:
  explicit TimedObjective(Objective& inner) : inner_(inner) {}
  const ParameterSpec& parameters() const override { return inner_.parameters(); }
  double evaluate(std::span<const double> theta) override {
    const auto t = Clock::now();
    const double v = inner_.evaluate(theta);
    single_seconds.push_back(since(t));
    seconds += single_seconds.back();
    return v;
  }
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override {
    const auto t = Clock::now();
    inner_.evaluate_batch(thetas, values);
    seconds += since(t);
    ++batches;
    batch_thetas += static_cast<std::int64_t>(thetas.size());
  }
  double seconds = 0.0;
  std::vector<double> single_seconds;
  std::int64_t batches = 0, batch_thetas = 0;

 private:
  Objective& inner_;
};

struct Args {
  int threads = 1, scenarios = 30, repeats = 3, allgather_repeats = 2000;
  double seconds = 35, iteration_seconds = 1;
  std::string out;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) throw std::runtime_error(k + ": expected a value");
      return argv[++i];
    };
    if (k == "--threads")
      a.threads = std::stoi(value());
    else if (k == "--scenarios")
      a.scenarios = std::stoi(value());
    else if (k == "--repeats")
      a.repeats = std::stoi(value());
    else if (k == "--allgather-repeats")
      a.allgather_repeats = std::stoi(value());
    else if (k == "--seconds")
      a.seconds = std::stod(value());
    else if (k == "--iteration-seconds")
      a.iteration_seconds = std::stod(value());
    else if (k == "--out")
      a.out = value();
    else
      throw std::runtime_error("unknown option " + k);
  }
  return a;
}

constexpr const char* kProblem = "hover (learned model, hover policy, PEGASUS U-hat)";
using Task = heli::HoverTask<sysid::LearnedHeliModel>;
using Policy = heli::HoverPolicy;

// The hover objective on m scenarios of `seconds` s, on the model every training command of the hover issue
// uses (identified from the default 339 s pilot log); every rank builds the same one.
struct Problem {
  std::shared_ptr<const sysid::IdentifiedModel> model;
  explicit Problem(ThreadPool& pool) {
    const heli::Aircraft aircraft;
    const sysid::FlightLog log = heli::fly_pilot(aircraft, heli::PilotOptions{}, 339, 1).log;
    model =
        std::make_shared<const sysid::IdentifiedModel>(sysid::identify(log, sysid::IdentifyOptions{}, pool));
  }
  std::unique_ptr<Objective> objective(int scenarios, double seconds,
                                       std::shared_ptr<ThreadPool> pool) const {
    heli::HoverTrainingOptions o;
    o.scenarios = scenarios;
    o.seconds = seconds;
    return heli::hover_objective(model, o, std::move(pool));
  }
  static OptimizerOptions optimizer() { return heli::HoverTrainingOptions::default_optimizer(); }
};

int run(const Args& a) {
  const auto start = Clock::now();
  auto pool = std::make_shared<ThreadPool>(a.threads);
  const Problem problem(*pool);
  const double setup_seconds = since(start);
  auto objective = problem.objective(a.scenarios, a.seconds, pool);
  const Theta theta = StartingTheta(objective->parameters(), {});
  const std::size_t n = theta.size();

  // U-hat: one warm-up call, then the timed ones.
  double uhat = objective->evaluate(theta);
  std::vector<double> uhat_times, uhat_cpu;
  mpi::reset_comm_stats();
  for (int r = 0; r < a.repeats; ++r) {
    barrier();
    const auto t = Clock::now();
    const double c = cpu_seconds();
    const double v = objective->evaluate(theta);
    uhat_times.push_back(since(t));
    uhat_cpu.push_back(cpu_seconds() - c);
    if (v != uhat) throw std::runtime_error("U-hat changed between calls");
  }
  const mpi::CommStats uhat_comm = mpi::comm_stats();
  // The slowest rank's CPU seconds: what the wall time would be on idle cores (less the communication).
  double uhat_cpu_max = 0.0;
  {
    std::vector<double> mine(static_cast<std::size_t>(mpi::size()), 0.0);
    mine[static_cast<std::size_t>(mpi::rank())] = median(uhat_cpu);
    const mpi::Share share{mpi::rank(), mpi::size()};
    mpi::allgather_shares(mine, share.size > 1 ? share : mpi::Share{});
    for (double c : mine) uhat_cpu_max = std::max(uhat_cpu_max, c);
  }
  // CPU seconds of each scenario's rollout (one process, one thread): how uneven the pairs are.
  std::vector<double> pair_cpu;
  if (mpi::size() == 1) {
    if (auto* pegasus = dynamic_cast<PegasusObjective<Task, Policy>*>(objective.get())) {
      for (int i = 0; i < a.scenarios; ++i) {
        const double c = cpu_seconds();
        (void)pegasus->evaluator().scenario_value(theta, i);
        pair_cpu.push_back(cpu_seconds() - c);
      }
    }
  }

  // One gradient iteration on short flights, with the wait before each allgather measured apart.
  auto iteration_objective = problem.objective(a.scenarios, a.iteration_seconds, pool);
  (void)iteration_objective->evaluate(theta);  // warm-up
  OptimizerOptions opt = Problem::optimizer();
  opt.method = "gradient";
  opt.gradient.max_iterations = 1;
  // A checkpoint after the iteration, as the hover training writes one every iteration (rank 0 only).
  const std::string checkpoint_file = a.out.empty() ? std::string() : a.out + ".checkpoint.json";
  double checkpoint_seconds = 0.0;
  opt.SetCheckpointing(1, [&](const nlohmann::json& c) {
    const auto t = Clock::now();
    if (mpi::is_root() && !checkpoint_file.empty()) write_file_atomic(checkpoint_file, json_text(c));
    checkpoint_seconds += since(t);
  });
  TimedObjective timed(*iteration_objective);
  mpi::set_measure_wait(true);
  mpi::reset_comm_stats();
  barrier();
  const auto t1 = Clock::now();
  Theta x = theta;
  OptimizerSummary summary;
  Solve(opt, timed, &x, &summary);
  const double total = since(t1);
  const mpi::CommStats it_comm = mpi::comm_stats();  // includes the start's one small allgather
  // Solve first evaluates the start; the iteration is everything after that call.
  const double start_seconds = timed.single_seconds.at(0);
  const double iteration_seconds = total - start_seconds;
  const double evaluate_seconds = timed.seconds - start_seconds;
  nlohmann::json iteration = {
      {"seconds", iteration_seconds},
      {"serial_seconds", std::max(0.0, iteration_seconds - evaluate_seconds)},
      {"checkpoint_seconds", checkpoint_seconds},
      {"comm_seconds", it_comm.seconds},
      {"wait_seconds", it_comm.wait_seconds},
      {"compute_seconds", std::max(0.0, evaluate_seconds - it_comm.seconds - it_comm.wait_seconds)},
      {"comm_fraction", it_comm.seconds / iteration_seconds},
      {"allgathers", it_comm.calls},
      {"bytes", it_comm.bytes},
      {"batch_pairs", timed.batch_thetas * a.scenarios},
      {"line_search_evaluations", static_cast<std::int64_t>(timed.single_seconds.size()) - 1},
      {"flight_seconds", a.iteration_seconds},
      {"start_value", summary.initial_value},
      {"value", summary.best_value},
  };

  // Allgather of the real message sizes, each call timed after a barrier; the median resists a busy
  // machine's descheduling better than the mean.
  nlohmann::json allgather = nlohmann::json::array();
  for (const std::size_t doubles :
       {static_cast<std::size_t>(a.scenarios), 2 * n * static_cast<std::size_t>(a.scenarios)}) {
    std::vector<double> values(doubles, 1.0), per_call;
    const mpi::Share share{mpi::rank(), mpi::size()};
    for (int r = 0; r < a.allgather_repeats && share.size > 1; ++r) {
      mpi::reset_comm_stats();
      mpi::allgather_shares(values, share);
      per_call.push_back(mpi::comm_stats().seconds);
    }
    double mean = 0.0;
    for (double t : per_call) mean += t / static_cast<double>(per_call.size());
    allgather.push_back({{"doubles", doubles},
                         {"bytes", doubles * sizeof(double)},
                         {"calls", per_call.size()},
                         {"seconds_per_call", per_call.empty() ? 0.0 : median(per_call)},
                         {"mean_seconds_per_call", mean}});
  }
  mpi::set_measure_wait(false);
  if (!checkpoint_file.empty() && mpi::is_root()) std::filesystem::remove(checkpoint_file);

  if (!mpi::is_root()) return 0;
  const nlohmann::json result = {
      {"benchmark", "mpi_scaling"},
      {"problem", kProblem},
      {"ranks", mpi::size()},
      {"threads", a.threads},
      {"scenarios", a.scenarios},
      {"parameters", n},
      {"flight_seconds", a.seconds},
      {"setup_seconds", setup_seconds},
      {"uhat", uhat},
      {"uhat_seconds", median(uhat_times)},
      {"uhat_seconds_all", uhat_times},
      {"uhat_cpu_seconds", median(uhat_cpu)},
      {"uhat_cpu_seconds_slowest_rank", uhat_cpu_max},
      {"pair_cpu_seconds", pair_cpu},
      {"uhat_comm_seconds", uhat_comm.seconds / std::max(1, a.repeats)},
      {"iteration", iteration},
      {"allgather", allgather},
  };
  const std::string text = result.dump(2) + "\n";
  if (a.out.empty()) {
    std::cout << text;
  } else {
    std::ofstream(a.out) << text;
    std::cout << fmt::format(
        "mpi_scaling: {} rank(s) x {} thread(s): U-hat {:.3f} s, iteration {:.3f} s (comm {:.2f}%) -> {}\n",
        mpi::size(), a.threads, median(uhat_times), iteration_seconds,
        100.0 * it_comm.seconds / iteration_seconds, a.out);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const mpi::Session session(&argc, &argv, mpi::linked_transport());
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::cerr << "pegasus_mpi_bench: " << e.what() << std::endl;
    if (mpi::size() > 1) mpi::abort_job(1);
    return 1;
  }
}
