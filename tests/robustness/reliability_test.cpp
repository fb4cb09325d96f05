// Issue 51, the library's side: each finding of the hostile-user campaign at 5e4e694 as a regression test
// (resume without the input check, a controller serving a misread state, endless input, a vehicle file valid
// only to some commands, Ctrl-C in a long call).
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/training.hpp"
#include "pegasus/parallel/interrupt.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/runs/run_directory.hpp"
#include "support/scratch_dir.hpp"

namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class Reliability : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = pegasus::test_support::fresh_test_dir("pegasus_reliability_"); }
  void TearDown() override { fs::remove_all(dir_); }
  static void write(const fs::path& file, const std::string& text) { std::ofstream(file) << text; }
  fs::path dir_;
};

// A config naming one input file, as `export --policy` does.
pegasus::ConfigSchema schema_with_input(const fs::path& input) {
  pegasus::ConfigSchema s;
  s.add_string("policy", input.string(), "the input file").input_file();
  s.add_int("steps", 3, "steps");
  return s;
}

// Item 1: a kill after config.toml and before inputs.json (or a DIR.partial made by hand with a copied
// config.toml) was resumed on changed inputs with no check at all. Now inputs.json is written first, and a
// DIR.partial with a config.toml but no record of its inputs is refused.
TEST_F(Reliability, AResumeWithoutTheRecordOfItsInputsIsRefused) {
  const fs::path input = dir_ / "a.json";
  write(input, "{\"v\": 1}");
  const pegasus::ConfigSchema schema = schema_with_input(input);
  {
    pegasus::RunDirectory run = pegasus::RunDirectory::open(dir_ / "o", schema);
    EXPECT_TRUE(fs::exists(dir_ / "o.partial" / "inputs.json"));
    run.commit();
  }
  fs::create_directory(dir_ / "o2.partial");
  fs::copy_file(dir_ / "o" / "config.toml", dir_ / "o2.partial" / "config.toml");
  write(input, "{\"v\": 2}");  // the input changed: nothing may continue as if it had not
  try {
    (void)pegasus::RunDirectory::open(dir_ / "o2", schema, {.resume = true});
    FAIL() << "resumed without the input check";
  } catch (const pegasus::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no record of the input files"));
    EXPECT_THAT(e.what(), HasSubstr("--policy"));
    EXPECT_THAT(e.what(), HasSubstr("--force"));
  }
  EXPECT_FALSE(fs::exists(dir_ / "o2"));
  EXPECT_TRUE(fs::exists(dir_ / "o2.partial" / "config.toml"));  // the user's folder is left as it was
  // With the record, a changed input is named, as before.
  {
    pegasus::RunDirectory run = pegasus::RunDirectory::open(dir_ / "o4", schema);
    (void)run;  // killed here: DIR.partial with inputs.json and config.toml
  }
  write(input, "{\"v\": 3}");
  EXPECT_THROW((void)pegasus::RunDirectory::open(dir_ / "o4", schema, {.resume = true}), pegasus::InputError);
}

// A run killed between its inputs.json and its config.toml left nothing to continue: --resume starts it over
// (and never trusts a folder without config.toml that holds anything else).
TEST_F(Reliability, AResumeOfARunKilledWhileStartingStartsItOver) {
  const fs::path input = dir_ / "a.json";
  write(input, "{}");
  const pegasus::ConfigSchema schema = schema_with_input(input);
  fs::create_directory(dir_ / "o.partial");
  write(dir_ / "o.partial" / "inputs.json", "{\"stale\": 1}");
  {
    pegasus::RunDirectory run = pegasus::RunDirectory::open(dir_ / "o", schema, {.resume = true});
    EXPECT_FALSE(run.resumed());
    EXPECT_TRUE(fs::exists(dir_ / "o.partial" / "config.toml"));
    EXPECT_EQ(pegasus::read_file(dir_ / "o.partial" / "inputs.json").find("stale"), std::string::npos);
    run.commit();
  }
  fs::create_directory(dir_ / "p.partial");
  write(dir_ / "p.partial" / "checkpoint.json", "{\"next\": 99}");
  try {
    (void)pegasus::RunDirectory::open(dir_ / "p", schema, {.resume = true});
    FAIL() << "a checkpoint without its config.toml was trusted";
  } catch (const pegasus::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("holds no config.toml"));
  }
}

// Item 3: endless input (/dev/zero) grew memory at 100 MB/s forever. Devices are refused before any read,
// a pipe past the limit within the limit's bytes, a regular file past it by its size.
TEST_F(Reliability, ReadersRefuseDevicesAndInputPastTheirLimitAtOnce) {
  const auto start = std::chrono::steady_clock::now();
  try {
    (void)pegasus::read_file("/dev/zero");
    FAIL() << "/dev/zero was read";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("/dev/zero: expected a regular file, got a device"));
  }
  // Every TOML reader (configs, vehicle, task files) has the settings limit: 16 MiB, checked by size.
  const fs::path big = dir_ / "big.toml";
  write(big, "");
  fs::resize_file(big, pegasus::kMaxSettingsFileBytes + 1);  // sparse: nothing is written
  try {
    (void)pegasus::logs::read_vehicle(big);
    FAIL() << "a file past the limit was read";
  } catch (const pegasus::InputError& e) {
    EXPECT_THAT(e.what(),
                HasSubstr("big.toml: expected a readable vehicle file, got larger than the 16 MiB"));
  }
  EXPECT_THROW((void)pegasus::logs::read_vehicle("/dev/zero"), pegasus::InputError);
  pegasus::ConfigSchema schema;
  EXPECT_THROW(schema.load_toml_file("/dev/zero"), pegasus::InputError);
  // A pipe that never ends: refused after the limit's bytes.
  const fs::path fifo = dir_ / "endless";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::atomic<bool> stop{false};
  // The writer's next write after the reader gave up fails (EPIPE) instead of ending the test process.
  const auto previous_pipe = std::signal(SIGPIPE, SIG_IGN);
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    const std::string chunk(1 << 16, 'x');
    while (!stop && ::write(fd, chunk.data(), chunk.size()) > 0) {
    }
    ::close(fd);
  });
  try {
    (void)pegasus::read_file(fifo, std::uint64_t{1} << 20);
    ADD_FAILURE() << "an endless pipe was read to its end";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("larger than the 1 MiB limit of an input file"));
  }
  stop = true;
  {
    const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);  // unblocks a writer waiting for a reader
    ::close(fd);
  }
  writer.join();
  std::signal(SIGPIPE, previous_pipe);
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

// A controller that counts how often it was asked: a refused header must never reach it.
class CountingController : public pegasus::heli::HeliController {
 public:
  using pegasus::heli::HeliController::act;
  pegasus::heli::Controls act(const pegasus::heli::LoggedState& s, double,
                              pegasus::heli::ControllerMemory&) const override {
    ++calls;
    return {s[0], s[1], s[2], 0.5};
  }
  pegasus::heli::SetPoint target(double) const override { return {}; }
  mutable int calls = 0;
};

struct Served {
  pegasus::heli::ControlLoopStats stats;
  std::vector<std::string> answers;
  std::string errors;
  int calls = 0;
};

Served serve(std::string input) {
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  char *out_text = nullptr, *err_text = nullptr;
  std::size_t out_size = 0, err_size = 0;
  std::FILE* out = open_memstream(&out_text, &out_size);
  std::FILE* err = open_memstream(&err_text, &err_size);
  const CountingController controller;
  Served s;
  s.stats = pegasus::heli::run_control_loop(controller, {0.1, 0.2, 0.3, 0.4}, in, out, err);
  std::fclose(in);
  std::fclose(out);
  std::fclose(err);
  const std::string answers(out_text, out_size);
  s.errors.assign(err_text, err_size);
  std::free(out_text);
  std::free(err_text);
  for (std::size_t start = 0; start < answers.size();) {
    const std::size_t nl = answers.find('\n', start);
    s.answers.push_back(answers.substr(start, nl - start));
    start = nl + 1;
  }
  s.calls = controller.calls;
  return s;
}

const std::string kRow = "0,5,0,-2,0,0,0,0,0,0,0,0,0\n";  // time, x = 5 (y = 0), z = -2, the rest 0

// Item 2: a header with a misspelt column ("yawrate") was taken as a header that names too little, and the
// lines were read by position under it: y = 5 was served as x. Now such a header is refused, every line is
// answered with the trim controls and an error line, and the controller never sees a state.
TEST(ControlLoopHeader, AHeaderThatDoesNotPlaceEveryStateIsRefusedAndNothingIsServedFromIt) {
  const Served misspelt =
      serve("time,y,x,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yawrate\n" + kRow + kRow);
  EXPECT_THAT(misspelt.stats.header_refused, HasSubstr("no column for the state field(s) yaw_rate"));
  EXPECT_THAT(misspelt.stats.header_refused, HasSubstr("'yawrate'"));
  EXPECT_EQ(misspelt.calls, 0);
  EXPECT_EQ(misspelt.stats.malformed, 2);
  ASSERT_EQ(misspelt.answers.size(), 3u);
  EXPECT_EQ(misspelt.answers[0], "a1,a2,a3,a4");
  EXPECT_EQ(misspelt.answers[1], "0.1,0.2,0.3,0.4");
  EXPECT_EQ(misspelt.answers[2], "0.1,0.2,0.3,0.4");
  EXPECT_THAT(misspelt.errors, HasSubstr("stdin:1: header: no column for the state field(s) yaw_rate"));
  EXPECT_THAT(misspelt.errors, HasSubstr("stdin:3: the header (line 1) was refused"));

  const Served short_header = serve("time,x,y\n" + kRow);
  EXPECT_THAT(short_header.stats.header_refused, HasSubstr("z, roll, pitch, yaw, xdot"));
  EXPECT_EQ(short_header.calls, 0);

  const Served twice = serve("time,x,x,y,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate\n");
  EXPECT_THAT(twice.stats.header_refused, HasSubstr("'x' is named twice"));

  // A header in another order, with a column of its own, places every state: served by name.
  const Served named = serve(
      "battery,time,y,x,z,roll,pitch,yaw,xdot,ydot,zdot,roll_rate,pitch_rate,yaw_rate\n"
      "12.6," +
      kRow);
  EXPECT_EQ(named.stats.header_refused, "");
  EXPECT_EQ(named.calls, 1);
  ASSERT_EQ(named.answers.size(), 2u);
  EXPECT_EQ(named.answers[1], "0,5,-2,0.5");  // x = 0 and y = 5 as the header says
  EXPECT_THAT(named.errors, HasSubstr("stdin:1: header: columns not of this layout, ignored: 1 'battery'"));
}

// A line without end (stdin from /dev/zero) keeps memory bounded: it is cut at 64 KiB and answered once.
TEST(ControlLoopHeader, ALineLongerThanTheLimitIsAnsweredWithTheTrimControls) {
  const Served long_line = serve(std::string(200000, '1') + "\n" + kRow);
  EXPECT_EQ(long_line.stats.lines, 2);
  EXPECT_EQ(long_line.stats.malformed, 1);
  EXPECT_EQ(long_line.calls, 1);
  ASSERT_EQ(long_line.answers.size(), 2u);
  EXPECT_EQ(long_line.answers[0], "0.1,0.2,0.3,0.4");
  EXPECT_THAT(long_line.errors, HasSubstr("stdin:1: expected a line of at most 65536 bytes"));
}

// The limit is exact, whatever the blocks the reader gathers characters in: a state line padded to 65536
// bytes is served, one byte more is not.
TEST(ControlLoopHeader, ALineOfExactlyTheLimitIsServedAndOneByteMoreIsNot) {
  const std::string row = kRow.substr(0, kRow.size() - 1);
  for (const std::size_t bytes : {std::size_t{65535}, std::size_t{65536}, std::size_t{65537}}) {
    SCOPED_TRACE(bytes);
    const Served served = serve(row + std::string(bytes - row.size(), ' ') + "\n" + kRow);
    const bool within = bytes <= 65536;
    EXPECT_EQ(served.stats.lines, 2);
    EXPECT_EQ(served.stats.malformed, within ? 0 : 1);
    EXPECT_EQ(served.calls, within ? 2 : 1);
    EXPECT_EQ(served.errors.find("expected a line of at most 65536 bytes") != std::string::npos, !within)
        << served.errors;
  }
}

// Issue 48, item 8: one controller process serves many flights; "reset" clears the memory and the clock.
class Remembering : public pegasus::heli::HeliController {
 public:
  using pegasus::heli::HeliController::act;
  pegasus::heli::Controls act(const pegasus::heli::LoggedState&, double time,
                              pegasus::heli::ControllerMemory& memory) const override {
    memory.integral[0] += 1;
    return {time, memory.integral[0], 0, 0};
  }
  pegasus::heli::SetPoint target(double) const override { return {}; }
};

TEST(ControlLoopHeader, AResetLineStartsANewFlightWithNoMemoryAndTheClockAtZero) {
  const std::string row = "0,0,-2,0,0,0,0,0,0,0,0,0\n";  // 12 states, no time: t = line index / rate
  std::string input = row + row + row + " reset \r\n" + row + row;
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  char* out_text = nullptr;
  std::size_t out_size = 0;
  std::FILE* out = open_memstream(&out_text, &out_size);
  std::FILE* err = std::tmpfile();
  const auto stats = pegasus::heli::run_control_loop(Remembering(), {}, in, out, err, 0.1);
  std::fclose(in);
  std::fclose(out);
  std::fclose(err);
  const std::string answers(out_text, out_size);
  std::free(out_text);
  EXPECT_EQ(stats.resets, 1);
  EXPECT_EQ(stats.malformed, 0);
  EXPECT_EQ(answers, "0,1,0,0\n0.1,2,0,0\n0.2,3,0,0\nreset\n0,1,0,0\n0.1,2,0,0\n");
}

// Items 5 and 7: a vehicle file is valid or not as a whole, whichever command reads it, and each refusal
// names the file and the key.
TEST(VehicleFileAsAWhole, KeysThatNoCommandCouldUseAreRefusedByEveryReader) {
  const std::string head = R"([vehicle]
name = "q"
[log]
rate_hz = 50
[log.position]
fields = ["x", "y", "z"]
[log.velocity]
fields = ["xdot", "ydot", "zdot"]
[log.attitude]
fields = ["roll", "pitch", "yaw"]
form = "euler"
[log.rates]
fields = ["roll_rate", "pitch_rate", "yaw_rate"]
form = "euler"
[[log.controls]]
field = "a1"
[[log.controls]]
field = "a2"
[[log.controls]]
field = "a3"
[[log.controls]]
field = "a4"
)";
  EXPECT_NO_THROW((void)pegasus::logs::parse_vehicle(head, "v.toml"));
  const auto refused = [&](const std::string& tail, const std::string& expected) {
    SCOPED_TRACE(tail);
    try {
      (void)pegasus::logs::parse_vehicle(head + tail, "v.toml");
      ADD_FAILURE() << "accepted";
    } catch (const pegasus::InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr("v.toml:"));
      EXPECT_THAT(e.what(), HasSubstr(expected));
    }
  };
  refused("[control]\nrate_hz = 7\n", "control.rate_hz: expected a rate that log.rate_hz = 50 Hz");
  refused("[hover.reward]\nposition_m = 1e-320\n",
          "hover.reward.position_m: expected a typical size of at least");
  refused("[hover.reward]\naction = 1e-320\n", "hover.reward.action: expected 0 (no term) or a typical size");
  refused("[hover]\nintegral_seconds = 1e-320\n", "hover.integral_seconds: expected 0 (no integral term) or");
  EXPECT_NO_THROW((void)pegasus::logs::parse_vehicle(head + "[control]\nrate_hz = 10\n", "v.toml"));
  EXPECT_NO_THROW((void)pegasus::logs::parse_vehicle(head + "[control]\nrate_hz = 100\n", "v.toml"));
  EXPECT_NO_THROW((void)pegasus::logs::parse_vehicle(head + "[hover.reward]\naction = 0\n", "v.toml"));
}

TEST(VehicleFileAsAWhole, AULogTopicsTimestampIsNoMeasuredQuantity) {
  const std::string ulog_vehicle = R"([vehicle]
name = "px4"
[log]
rate_hz = 50
[log.position]
topic = "vehicle_local_position"
fields = ["x", "y", "z"]
[log.velocity]
topic = "vehicle_local_position"
fields = ["vx", "vy", "vz"]
[log.attitude]
topic = "vehicle_attitude"
fields = ["timestamp", "q[1]", "q[2]", "q[3]"]
form = "quaternion"
[log.rates]
topic = "vehicle_angular_velocity"
fields = ["xyz[0]", "xyz[1]", "xyz[2]"]
form = "body"
[[log.controls]]
topic = "actuator_controls_0"
field = "control[0]"
[[log.controls]]
topic = "actuator_controls_0"
field = "control[1]"
[[log.controls]]
topic = "actuator_controls_0"
field = "control[2]"
[[log.controls]]
topic = "actuator_controls_0"
field = "control[3]"
)";
  try {
    (void)pegasus::logs::parse_vehicle(ulog_vehicle, "px4.toml");
    FAIL() << "timestamp taken as the quaternion's w";
  } catch (const pegasus::InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("px4.toml:"));
    EXPECT_THAT(e.what(), HasSubstr("log.attitude"));
    EXPECT_THAT(e.what(), HasSubstr("'timestamp' is the records' time"));
  }
}

// Item 5: `--integral-seconds 1e-320` said "parameter a1.int: expected a finite initial value, got -inf".
TEST(HoverOptionsIntegral, AnIntegralTimeBelowOneControlStepIsRefusedByItsName) {
  pegasus::heli::HoverTrainingOptions o;
  std::string why;
  for (const double bad : {1e-320, 1e-9, 0.019}) {
    o.integral_seconds = bad;
    EXPECT_FALSE(o.IsValid(&why)) << bad;
    EXPECT_THAT(why,
                HasSubstr("integral_seconds: expected 0 (no integral term) or a number in [0.02, 3600]"));
  }
  for (const double good : {0.0, 0.02, 5.0}) {
    o.integral_seconds = good;
    EXPECT_TRUE(o.IsValid(&why)) << good << ": " << why;
  }
}

// Item 7: a long call stops soon after an interrupt is requested, on every thread, and a pool runs as ever
// once it is cleared.
TEST(Interrupt, APoolStopsWithinOneItemOfARequestAndRunsAgainOnceCleared) {
  for (const int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    pegasus::ThreadPool pool(threads);
    std::atomic<int> ran{0};
    pegasus::clear_interrupt();
    EXPECT_THROW(pool.parallel_for(
                     100000,
                     [&](std::size_t i) {
                       if (i == 10) pegasus::request_interrupt();
                       ++ran;
                     },
                     1),
                 pegasus::Interrupted);
    EXPECT_LE(ran.load(), 10 + 2 * threads) << "items ran after the request";
    EXPECT_TRUE(pegasus::interrupt_requested());
    pegasus::clear_interrupt();
    ran = 0;
    pool.parallel_for(1000, [&](std::size_t) { ++ran; });
    EXPECT_EQ(ran.load(), 1000);
  }
}

// Item 4: a run whose objective is not finite (a NaN target or time step) trained to "U-hat NaN" and ended
// as a success. Training now refuses to end on a non-finite best U-hat.
TEST(NonFiniteObjective, TrainingNeverEndsOnANonFiniteBestValue) {
  for (const double bad : {std::nan(""), -HUGE_VAL}) {
    SCOPED_TRACE(bad);
    pegasus::FunctionObjective objective(
        pegasus::ParameterSpec({{.name = "x", .initial = 0.5, .lower = -1, .upper = 1}}),
        [bad](std::span<const double>) { return bad; });
    pegasus::TrainingPlan plan;
    pegasus::TrainingStage stage;
    stage.name = "only";
    stage.optimizer.method = "hill-climb";
    stage.optimizer.hill_climbing.max_iterations = 3;
    plan.stages.push_back(stage);
    pegasus::Theta theta;
    pegasus::TrainingSummary summary;
    try {
      pegasus::Train(plan, objective, &theta, &summary);
      ADD_FAILURE() << "trained to " << summary.best_value;
    } catch (const pegasus::NonFiniteObjective& e) {
      EXPECT_THAT(e.what(), HasSubstr("not a finite number"));
    }
  }
}

}  // namespace
