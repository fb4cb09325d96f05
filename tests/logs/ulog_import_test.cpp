// ULog import: resampling of hand-built topics to the flight log's grid, the vehicle file's [log] section,
// the errors a user sees; the real sample (../shared/data/px4/sample.ulg) read and cross-checked against
// counts taken from it independently, and `pegasus log import` end to end on it.
#include "pegasus/logs/ulog_import.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <regex>

#include "pegasus/core/error.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/logs/ulog.hpp"
#include "pegasus/vehicle/flight_log.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"
#include "ulog_builder.hpp"

namespace fs = std::filesystem;

namespace {

using namespace pegasus;
using namespace pegasus::logs;
using test_support::Bytes;
using test_support::input_error_message;
using test_support::UlogBuilder;

const fs::path kSample = fs::path(PEGASUS_SOURCE_DIR) / ".." / "shared" / "data" / "px4" / "sample.ulg";
const fs::path kVehicle = fs::path(PEGASUS_SOURCE_DIR) / "experiments" / "vehicles" / "px4-quadrotor.toml";

VehicleLogSpec test_spec() {
  VehicleLogSpec s;
  s.file = "v.toml";
  s.rate_hz = 50;
  s.position = {"pos", {"x", "y", "z"}};
  s.velocity = {"pos", {"vx", "vy", "vz"}};
  s.attitude = {"att", {"q[0]", "q[1]", "q[2]", "q[3]"}};
  s.rates = {"att", {"p", "q_rate", "r"}};
  s.controls = {ControlChannel{"ctl", "c[1]"}, ControlChannel{"ctl", "c[0]"},
                ControlChannel{"ctl", "c[3]", 2, -1}, ControlChannel{"ctl", "c[2]"}};
  return s;
}

// Position at 10 Hz moving at (2, -1, 0.5) m/s; attitude at 100 Hz turning about z at 0.1 rad/s; controls
// at 40 Hz stepping every record. Time in us from 1 s; `skip_pos` drops position records in (2 s, 2.6 s).
std::vector<std::uint8_t> synthetic_ulog(bool skip_pos = false, std::uint8_t pos_instance = 0) {
  UlogBuilder b;
  b.format("pos:uint64_t timestamp;float x;float y;float z;float vx;float vy;float vz;");
  b.format("att:uint64_t timestamp;float p;float q_rate;float r;float[4] q;");
  b.format("ctl:uint64_t timestamp;float[4] c;");
  b.subscribe(pos_instance, 0, "pos").subscribe(0, 1, "att").subscribe(0, 2, "ctl");
  for (int k = 0; k <= 300; ++k) {  // 1 s .. 4 s in 10 ms steps
    const std::uint64_t t_us = 1000000 + 10000 * static_cast<std::uint64_t>(k);
    const double t = static_cast<double>(t_us) * 1e-6;
    if (k % 10 == 0 && !(skip_pos && t > 2.0 && t < 2.6))
      b.data(0, Bytes()
                    .put(t_us)
                    .put(float(2 * t))
                    .put(float(-t))
                    .put(float(0.5 * t))
                    .put(2.0f)
                    .put(-1.0f)
                    .put(0.5f));
    const double psi = 0.1 * t;
    b.data(1, Bytes()
                  .put(t_us)
                  .put(0.0f)
                  .put(0.0f)
                  .put(0.1f)
                  .put(float(std::cos(psi / 2)))
                  .put(0.0f)
                  .put(0.0f)
                  .put(float(std::sin(psi / 2))));
    if (k % 25 == 0)  // 40 Hz
      b.data(2, Bytes().put(t_us).put(float(0.001 * k)).put(-0.5f).put(0.25f).put(0.75f));
  }
  return b.bytes();
}

TEST(UlogImport, ResamplesTopicsOntoOneConstantRateGrid) {
  const UlogFile u = parse_ulog(synthetic_ulog(), "s.ulg");
  ImportProvenance prov;
  const sysid::FlightLog log = import_ulog(u, test_spec(), "s.ulg", {}, &prov);
  ASSERT_EQ(log.rows(), 151u);  // 1 s .. 4 s at 50 Hz
  EXPECT_NEAR(log.dt(), 0.02, 1e-12);
  for (std::size_t k = 0; k < log.rows(); k += 7) {
    const double t = 1 + 0.02 * static_cast<double>(k);
    const auto& s = log.states[k];
    EXPECT_NEAR(s[0], 2 * t, 1e-5) << k;  // linear in time: interpolation is exact up to float storage
    EXPECT_NEAR(s[1], -t, 1e-5);
    EXPECT_NEAR(s[2], 0.5 * t, 1e-5);
    EXPECT_NEAR(s[3], 0, 1e-6);
    EXPECT_NEAR(s[4], 0, 1e-6);
    EXPECT_NEAR(s[5], 0.1 * t, 1e-6);  // yaw from the quaternion
    EXPECT_NEAR(s[6], 2, 1e-6);
    EXPECT_NEAR(s[11], 0.1, 1e-6);  // level: Euler yaw rate = body r
    // Controls are held from the last record at or before t (40 Hz records at 1 + 0.25 j s).
    const int j = static_cast<int>(std::floor((t - 1) / 0.25 + 1e-9));
    EXPECT_NEAR(log.controls[k][0], -0.5, 1e-7);                 // a1 = c[1]
    EXPECT_NEAR(log.controls[k][1], 0.001 * 25 * j, 1e-6) << k;  // a2 = c[0]
    EXPECT_NEAR(log.controls[k][2], 0.5, 1e-7);                  // a3 = 2 c[3] - 1
    EXPECT_NEAR(log.controls[k][3], 0.25, 1e-7);                 // a4 = c[2]
  }
  EXPECT_EQ(prov.json["rows"], 151);
  EXPECT_EQ(prov.json["topics"].size(), 3u);
  EXPECT_NEAR(prov.json["topics"][0]["largest_gap_s"].get<double>(), 0.1, 1e-9);
  // The CSV written from it reads back under the flight-log checks.
  const sysid::FlightLog back = sysid::parse_flight_log(sysid::flight_log_csv(log), "log.csv",
                                                        {.min_rows = 10, .rate_tolerance = 0.01});
  EXPECT_EQ(back.rows(), log.rows());
}

// The import reads a vehicle file's conventions (issue 53) as the CSV reader does (Vehicle::state_of): the
// same topics described as a ROS aircraft's (ENU, FLU, quaternion x, y, z, w, rates in deg/s) give the states
// that state_of gives of the same fields.
TEST(UlogImport, TopicsInAnotherConventionReadAsTheCsvReaderReadsThem) {
  const UlogFile u = parse_ulog(synthetic_ulog(), "s.ulg");
  const sysid::FlightLog own = import_ulog(u, test_spec(), "s.ulg", {});
  Vehicle ros;
  ros.log = test_spec();
  ros.log.world_frame = "ENU";
  ros.log.body_frame = "FLU";
  ros.log.quaternion_order = "xyzw";
  ros.log.rates_unit = "deg/s";
  const sysid::FlightLog read = import_ulog(u, ros.log, "s.ulg", {});
  ASSERT_EQ(read.rows(), own.rows());
  for (std::size_t k = 0; k < own.rows(); ++k) {
    // The topics' fields at this row, from the import in the pipeline's conventions.
    const auto& s = own.states[k];
    const heli::Euler e{s[3], s[4], s[5]};
    const auto q = heli::quaternion_from_euler(e);
    const heli::Vec3 w = heli::body_rates_from_euler_rates(e, heli::Vec3(s[9], s[10], s[11]));
    const std::vector<double> fields{s[0], s[1], s[2], s[6],  s[7],  s[8], q[0],
                                     q[1], q[2], q[3], w.x(), w.y(), w.z()};
    const heli::LoggedState expected = ros.state_of(fields);
    for (std::size_t j = 0; j < 12; ++j) {
      const double d = read.states[k][j] - expected[j];
      EXPECT_LE(std::abs(j >= 3 && j < 6 ? heli::wrap_angle(d) : d), 1e-9) << k << " " << j;
    }
    EXPECT_EQ(read.controls[k], own.controls[k]);
  }
  // Not the same states: the conventions were read.
  EXPECT_NE(read.states[10][0], own.states[10][0]);
}

TEST(UlogImport, BodyFrameInputsAreRotatedIntoTheLogFrames) {
  // Turned 90 degrees in yaw: body forward is world east; body rates (p, q, r) = (0, 0.2, 0) while rolled 0.
  UlogBuilder b;
  b.format(
      "s:uint64_t timestamp;float x;float y;float z;float u;float v;float w;float r0;float p0;float y0;"
      "float p;float q;float r;float[4] c;");
  b.subscribe(0, 0, "s");
  for (int k = 0; k <= 20; ++k)
    b.data(0, Bytes()
                  .put(std::uint64_t(100000 * k))
                  .put(0.0f)
                  .put(0.0f)
                  .put(-5.0f)
                  .put(3.0f)
                  .put(0.0f)
                  .put(0.0f)
                  .put(0.0f)
                  .put(0.0f)
                  .put(float(std::numbers::pi / 2))
                  .put(0.0f)
                  .put(0.2f)
                  .put(0.0f)
                  .put(0.0f)
                  .put(0.0f)
                  .put(0.0f)
                  .put(0.0f));
  VehicleLogSpec s;
  s.rate_hz = 10;
  s.attitude_form = "euler";
  s.velocity_frame = "body";
  s.position = {"s", {"x", "y", "z"}};
  s.velocity = {"s", {"u", "v", "w"}};
  s.attitude = {"s", {"r0", "p0", "y0"}};
  s.rates = {"s", {"p", "q", "r"}};
  s.controls = {ControlChannel{"s", "c[0]"}, ControlChannel{"s", "c[1]"}, ControlChannel{"s", "c[2]"},
                ControlChannel{"s", "c[3]"}};
  const sysid::FlightLog log = import_ulog(parse_ulog(b.bytes(), "b.ulg"), s, "b.ulg");
  ASSERT_EQ(log.rows(), 21u);
  EXPECT_NEAR(log.states[5][6], 0, 1e-6);  // xdot (north)
  EXPECT_NEAR(log.states[5][7], 3, 1e-6);  // ydot (east)
  EXPECT_NEAR(log.states[5][10], 0.2, 1e-6);
}

// Euler angles in degrees are interpolated in radians across the wrap (175 to -175 deg is 10 deg, not 350),
// then turned from ENU/FLU into the pipeline's: yaw = pi/2 - yaw', Euler rates in deg/s.
TEST(UlogImport, EulerAnglesInDegreesInterpolateAcrossTheWrapInAnyConvention) {
  UlogBuilder b;
  b.format(
      "s:uint64_t timestamp;float x;float y;float z;float r0;float p0;float y0;float dr;float dp;float dy;");
  b.format("c:uint64_t timestamp;float[4] c;");
  b.subscribe(0, 0, "s").subscribe(0, 1, "c");
  for (int k = 0; k <= 10; ++k) {  // 5 Hz: yaw' = 175 + 25 t deg, written in (-180, 180]
    const double t = 0.2 * k, yaw = 175 + 25 * t;
    const std::uint64_t t_us = 200000 * static_cast<std::uint64_t>(k);
    b.data(0, Bytes()
                  .put(t_us)
                  .put(1.0f)
                  .put(2.0f)
                  .put(3.0f)
                  .put(0.0f)
                  .put(0.0f)
                  .put(float(yaw > 180 ? yaw - 360 : yaw))
                  .put(0.0f)
                  .put(0.0f)
                  .put(25.0f));
    b.data(1, Bytes().put(t_us).put(0.0f).put(0.0f).put(0.0f).put(0.0f));
  }
  VehicleLogSpec s;
  s.rate_hz = 10;
  s.attitude_form = "euler";
  s.rates_form = "euler";
  s.world_frame = "ENU";
  s.body_frame = "FLU";
  s.attitude_unit = "deg";
  s.rates_unit = "deg/s";
  s.position = {"s", {"x", "y", "z"}};
  s.velocity = {"s", {"x", "y", "z"}};  // any three fields: only the attitude is checked
  s.attitude = {"s", {"r0", "p0", "y0"}};
  s.rates = {"s", {"dr", "dp", "dy"}};
  s.controls = {ControlChannel{"c", "c[0]"}, ControlChannel{"c", "c[1]"}, ControlChannel{"c", "c[2]"},
                ControlChannel{"c", "c[3]"}};
  const sysid::FlightLog log = import_ulog(parse_ulog(b.bytes(), "e.ulg"), s, "e.ulg");
  ASSERT_EQ(log.rows(), 21u);
  constexpr double kDeg = std::numbers::pi / 180;
  for (std::size_t k = 0; k < log.rows(); ++k) {
    const double t = 0.1 * static_cast<double>(k);
    EXPECT_NEAR(log.states[k][0], 2, 1e-6);  // ENU (1, 2, 3) is NED (2, 1, -3)
    EXPECT_NEAR(log.states[k][2], -3, 1e-6);
    EXPECT_NEAR(std::abs(heli::wrap_angle(log.states[k][5] - (std::numbers::pi / 2 - (175 + 25 * t) * kDeg))),
                0, 1e-6)
        << k;
    EXPECT_NEAR(log.states[k][11], -25 * kDeg, 1e-9);
  }
}

TEST(UlogImport, ErrorsNameTheFileTopicAndWhatWasExpected) {
  const UlogFile u = parse_ulog(synthetic_ulog(), "s.ulg");
  VehicleLogSpec s = test_spec();
  s.position.topic = "vehicle_gps";
  s.velocity.topic = "vehicle_gps";
  EXPECT_EQ(input_error_message([&] { import_ulog(u, s, "s.ulg"); }),
            "s.ulg: topic vehicle_gps is not in the log");
  s = test_spec();
  s.rates.fields[2] = "yawspeed";
  EXPECT_NE(
      input_error_message([&] { import_ulog(u, s, "s.ulg"); })
          .find("s.ulg: topic att (instance 0) has no field 'yawspeed'; its fields: timestamp, p, q_rate, r, "
                "q[0]"),
      std::string::npos);
  s = test_spec();
  s.controls[2].scale = 3;  // 3 * 0.75 - 1 = 1.25
  // Each value's error names the byte of the record it came from: one of that topic's data messages.
  const auto record_byte = [](const std::string& message, const std::string& before) {
    std::smatch m;
    EXPECT_TRUE(std::regex_search(message, m, std::regex("^" + before + ": byte ([0-9]+): "))) << message;
    return m.size() > 1 ? std::stoull(m[1].str()) : 0ull;
  };
  const auto is_record_of = [](const UlogFile& f, const std::string& topic, std::size_t byte) {
    const auto& offsets = f.topic(topic, 0)->offsets;
    return std::find(offsets.begin(), offsets.end(), byte) != offsets.end();
  };
  const std::string control = input_error_message([&] { import_ulog(u, s, "s.ulg"); });
  EXPECT_NE(control.find("ctl.c[3] = 0.75 at t = 1.000 s gives a3 = 1.25; expected [-1, 1]"),
            std::string::npos)
      << control;
  EXPECT_TRUE(is_record_of(u, "ctl", record_byte(control, "s\\.ulg"))) << control;
  const UlogFile gap = parse_ulog(synthetic_ulog(/*skip_pos=*/true), "g.ulg");
  const std::string gap_message = input_error_message([&] { import_ulog(gap, test_spec(), "g.ulg"); });
  EXPECT_NE(
      gap_message.find("topic pos: no record for 0.600 s after this one's t = 2.000 s; expected gaps of "
                       "at most log.max_gap_s = 0.5 s"),
      std::string::npos)
      << gap_message;
  EXPECT_TRUE(is_record_of(gap, "pos", record_byte(gap_message, "g\\.ulg"))) << gap_message;
  // A record whose timestamp goes back (a flipped bit): both records are named by their bytes.
  std::vector<std::uint8_t> back = synthetic_ulog();
  const std::size_t third = parse_ulog(back, "b.ulg").topic("pos", 0)->offsets[3];
  std::fill_n(back.begin() + static_cast<std::ptrdiff_t>(third + 3 + 2), 8,
              std::uint8_t{0});  // its timestamp
  const UlogFile went_back = parse_ulog(back, "b.ulg");
  const auto& pos_offsets = went_back.topic("pos", 0)->offsets;
  EXPECT_EQ(
      input_error_message([&] { import_ulog(went_back, test_spec(), "b.ulg"); }),
      fmt::format("b.ulg: byte {}: topic pos: record 3 has timestamp 0 us, before the previous record's "
                  "{} us (byte {}); expected timestamps that never go back",
                  third, went_back.topic("pos", 0)->timestamps[2], pos_offsets[2]));
  const UlogFile other = parse_ulog(synthetic_ulog(false, /*pos_instance=*/1), "i.ulg");
  EXPECT_EQ(input_error_message([&] { import_ulog(other, test_spec(), "i.ulg"); }),
            "i.ulg: topic pos has no records for instance 0 (instances logged: 1)");
  s = test_spec();
  s.instance = 1;
  s.attitude.topic = s.rates.topic = s.controls[0].topic = "pos";  // (any topic logged as instance 1)
  EXPECT_NE(input_error_message([&] { import_ulog(other, s, "i.ulg"); }).find("i.ulg: topic pos"),
            std::string::npos);
  EXPECT_NE(input_error_message([&] {
              import_ulog(u, test_spec(), "s.ulg", {.start_s = 10, .end_s = 0});
            }).find("share no time range"),
            std::string::npos);
}

class VehicleFile : public test_support::TempDirTest {
 protected:
  fs::path write(const std::string& text) const {
    fs::path p = dir_ / "v.toml";
    std::ofstream(p) << text;
    return p;
  }
};

TEST_F(VehicleFile, TheShippedQuadrotorFileReads) {
  const VehicleLogSpec s = read_vehicle_log_spec(kVehicle);
  EXPECT_EQ(s.vehicle, "px4-quadrotor");
  EXPECT_EQ(s.rate_hz, 50);
  EXPECT_EQ(s.model_rate_hz, 10);
  EXPECT_EQ(s.attitude.fields.size(), 4u);
  EXPECT_EQ(s.controls[2].field, "control[3]");
  EXPECT_EQ(s.controls[2].scale, 2);
  EXPECT_EQ(s.controls[2].offset, -1);
  EXPECT_EQ(s.topic_names(),
            (std::vector<std::string>{"vehicle_local_position", "vehicle_attitude", "actuator_controls_0"}));
}

TEST_F(VehicleFile, BadEntriesNameTheLineAndKey) {
  std::string text = test_support::read_text(kVehicle);
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = text;
    t.replace(t.find(from), from.size(), to);
    return write(t);
  };
  EXPECT_NE(input_error_message([&] {
              read_vehicle_log_spec(replaced("fields = [\"x\", \"y\", \"z\"]", "fields = [\"x\"]"));
            }).find(":19: log.position.fields: expected a list of 3 field (or CSV column) names"),
            std::string::npos);
  EXPECT_NE(input_error_message([&] {
              read_vehicle_log_spec(replaced("model_rate_hz = 10", "model_rate_hz = 15"));
            }).find(":11: log.model_rate_hz: expected a rate that divides log.rate_hz = 50 Hz, got 15 Hz"),
            std::string::npos);
  // The identification rate takes identify's bounds (rate_hz in [1, 50] Hz), which a log import's and a
  // pipeline's identification would refuse later, naming identify's option instead of the file's field.
  const std::string faster = test_support::read_text(kVehicle);
  std::string at_100 = faster;
  at_100.replace(at_100.find("rate_hz = 50"), 12, "rate_hz = 200");
  at_100.replace(at_100.find("model_rate_hz = 10"), 18, "model_rate_hz = 100");
  EXPECT_NE(input_error_message([&] {
              read_vehicle_log_spec(write(at_100));
            }).find(":11: log.model_rate_hz: expected a number in [1, 50]"),
            std::string::npos)
      << input_error_message([&] { read_vehicle_log_spec(write(at_100)); });
  EXPECT_NE(input_error_message([&] {
              read_vehicle_log_spec(replaced("model_rate_hz = 10", "model_rate_hz = 0.5"));
            }).find(":11: log.model_rate_hz: expected a number in [1, 50]"),
            std::string::npos);
  EXPECT_NE(input_error_message([&] {
              read_vehicle_log_spec(replaced("form = \"quaternion\"", "form = \"matrix\""));
            }).find("log.attitude.form: expected 'quaternion' or 'euler', got 'matrix'"),
            std::string::npos);
  EXPECT_NE(input_error_message([&] {
              read_vehicle_log_spec(write("[vehicle]\nname = \"x\"\n"));
            }).find("expected a [log] section"),
            std::string::npos);
}

// ------------------------------------------------------------------ the real sample

bool have_sample() { return fs::exists(kSample); }
#define REQUIRE_SAMPLE()                                                        \
  if (!have_sample())                                                           \
  GTEST_SKIP() << "the PX4 sample log is absent: expected " << kSample.string() \
               << " (the shared data folder beside the repository)"

// Counts taken from the sample by a separate 20-line scan of its message headers (not this reader).
TEST(UlogSample, ReaderAgreesWithAnIndependentScan) {
  REQUIRE_SAMPLE();
  const UlogFile f = read_ulog(kSample);
  EXPECT_EQ(f.version, 0);
  EXPECT_EQ(f.start_us, 112500176u);
  EXPECT_EQ(f.topics.size(), 43u);
  EXPECT_EQ(f.formats.size(), 103u);
  EXPECT_EQ(f.data_messages, 64542u);
  EXPECT_EQ(f.topic("vehicle_attitude")->rows(), 6461u);
  EXPECT_EQ(f.topic("sensor_combined")->rows(), 17070u);
  EXPECT_EQ(f.topic("actuator_controls_0")->rows(), 3269u);
  EXPECT_EQ(f.topic("vehicle_local_position")->rows(), 678u);
  EXPECT_EQ(f.instances("distance_sensor"), (std::vector<int>{0, 1, 2}));
  std::vector<int> dropouts;
  for (const auto& d : f.dropouts) dropouts.push_back(d.duration_ms);
  EXPECT_EQ(dropouts, (std::vector<int>{0, 26, 31, 62}));
  EXPECT_EQ(f.info.at("ver_hw").raw, "AUAV_X21");
  EXPECT_EQ(f.log_lines.size(), 4u);
  EXPECT_FALSE(f.truncated_at.has_value());
  // Unit quaternions: a wrong offset or type would not give norm 1.
  const UlogTopic* att = f.topic("vehicle_attitude");
  for (std::size_t r = 0; r < att->rows(); r += 97) {
    double n = 0;
    for (int c = 0; c < 4; ++c) n += std::pow(att->value(*att->find("q[" + std::to_string(c) + "]"), r), 2);
    EXPECT_NEAR(n, 1, 1e-5);
  }
}

class LogImportCli : public test_support::TempDirTest {};

TEST_F(LogImportCli, ImportsIdentifiesAndReportsPredictionErrorsOnTheSample) {
  REQUIRE_SAMPLE();
  const fs::path out = dir_ / "run";
  const auto r =
      test_support::run_pegasus("log import " + kSample.string() + " --vehicle " + kVehicle.string() +
                                " --out " + out.string() + " --quiet --threads 2");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: a3 is constant"), std::string::npos) << r.output;
  const auto summary = nlohmann::json::parse(test_support::read_text(out / "summary.json"));
  EXPECT_EQ(summary["source"]["sha256"], "81952e6059bc095717e7911c010e07f85749d6b04d332a5ffc51575a3fd0a558");
  EXPECT_EQ(summary["source"]["bytes"], 4053364);
  EXPECT_EQ(summary["dropouts"], 4);
  EXPECT_EQ(summary["dropout_total_ms"], 119);
  EXPECT_EQ(summary["constant_controls"], nlohmann::json::array({"a3"}));
  const sysid::FlightLog log = sysid::read_flight_log(out / "log.csv");
  EXPECT_EQ(log.rows(), summary["rows"].get<std::size_t>());
  EXPECT_NEAR(log.dt(), 0.02, 1e-9);
  EXPECT_GT(log.seconds(), 68);
  const auto& p = summary["prediction"];
  // Starts every 0.5 s (25 rows) on the hold-out rows while a 2 s prediction (100 rows) still fits.
  const auto rows = summary["rows"].get<long>();
  const long test_rows = rows - std::lround(0.7 * static_cast<double>(rows));
  const long starts = (test_rows - 100 - 1) / 25 + 1;
  ASSERT_GT(starts, 30);
  for (const char* model : {"identified", "global_linear", "constant_velocity"})
    for (const char* h : {"0.5", "1", "2"}) {
      if (!p["rmse"][model].contains(h)) continue;  // the fit turned singular before h in every rollout
      for (const auto& [var, e] : p["rmse"][model][h].items())
        EXPECT_TRUE(std::isfinite(e.get<double>()) && e.get<double>() >= 0)
            << model << " " << h << " " << var;
      EXPECT_GT(p["rollouts"][model][h].get<long>(), 0);
      EXPECT_LE(p["rollouts"][model][h].get<long>(), starts);
    }
  // The baseline never stops early: every start reaches every horizon.
  for (const char* h : {"0.5", "1", "2"})
    EXPECT_EQ(p["rollouts"]["constant_velocity"][h].get<long>(), starts) << h;
  EXPECT_EQ(p["rollouts"]["identified"]["0.5"].get<long>(), starts);
  // The bench log (see the README): holding still beats any regression on its resting hold-out part, and
  // its position error grows with the horizon (the estimator's velocity bias, integrated).
  for (const char* model : {"identified", "global_linear"})
    EXPECT_LT(p["rmse"]["constant_velocity"]["0.5"]["roll_rate"].get<double>(),
              p["rmse"][model]["0.5"]["roll_rate"].get<double>())
        << model;
  EXPECT_GT(p["rmse"]["constant_velocity"]["2"]["z"].get<double>(),
            p["rmse"]["constant_velocity"]["0.5"]["z"].get<double>());
  EXPECT_NE(p["structure"].get<std::string>().find("constant in the data (left out): a3"), std::string::npos);
  const auto prov = nlohmann::json::parse(test_support::read_text(out / "provenance.json"));
  EXPECT_EQ(prov["ulog"]["ver_hw"], "AUAV_X21");
  EXPECT_TRUE(fs::exists(out / "mse_vs_horizon.csv"));
  EXPECT_TRUE(fs::exists(out / "model.json"));
}

TEST_F(LogImportCli, CorruptFileIsOneLineNamingTheByteAndExitTwo) {
  REQUIRE_SAMPLE();
  std::ifstream in(kSample, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  bytes.resize(200000);
  const fs::path bad = dir_ / "bad.ulg";
  // The first data message at or after byte 100000 (walking the headers) gets msg_id 999, never subscribed.
  std::size_t pos = 16;
  while (pos < 100000 || bytes[pos + 2] != 'D')
    pos += 3 + (static_cast<unsigned char>(bytes[pos]) | (static_cast<unsigned char>(bytes[pos + 1]) << 8));
  bytes[pos + 3] = static_cast<char>(0xe7);
  bytes[pos + 4] = 0x03;
  std::ofstream(bad, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const fs::path out = dir_ / "run";
  const auto r = test_support::run_pegasus("log import " + bad.string() + " --vehicle " + kVehicle.string() +
                                           " --out " + out.string() + " --quiet");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_EQ(r.output, "pegasus: " + bad.string() + ": byte " + std::to_string(pos) +
                          ": expected a subscription ('A') of msg_id 999 before its data\n");
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(out.string() + ".partial"));
}

TEST_F(LogImportCli, CutFileIsReadToItsLastWholeMessageOrRefusedOnRequest) {
  REQUIRE_SAMPLE();
  std::ifstream in(kSample, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // Cut 2 bytes into the first message that starts after 3 MB.
  std::size_t pos = 16;
  while (pos < 3000000)
    pos += 3 + (static_cast<unsigned char>(bytes[pos]) | (static_cast<unsigned char>(bytes[pos + 1]) << 8));
  bytes.resize(pos + 2);
  const fs::path cut = dir_ / "cut.ulg";
  std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const std::string args =
      "log import " + cut.string() + " --vehicle " + kVehicle.string() + " --identify=false --quiet";
  const auto r = test_support::run_pegasus(args + " --out " + (dir_ / "run").string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: the file ends inside the message at byte " + std::to_string(pos)),
            std::string::npos)
      << r.output;
  const auto summary = nlohmann::json::parse(test_support::read_text(dir_ / "run" / "summary.json"));
  EXPECT_EQ(summary["truncated_at_byte"], pos);
  const auto strict =
      test_support::run_pegasus(args + " --truncated-tail error --out " + (dir_ / "strict").string());
  EXPECT_EQ(strict.code, 2);
  EXPECT_EQ(strict.output,
            "pegasus: " + cut.string() + ": byte " + std::to_string(pos) +
                ": the file ends inside a message: expected a 3-byte message header, found 2 bytes "
                "before the end of the file\n");
  EXPECT_FALSE(fs::exists(dir_ / "strict"));

  // Cut inside the definitions, before any topic's first record: the missing topic is blamed on the cut.
  bytes.resize(5000);
  std::ofstream(cut, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const auto early = test_support::run_pegasus(args + " --out " + (dir_ / "early").string());
  EXPECT_EQ(early.code, 2);
  EXPECT_NE(early.output.find(" before the file ends inside a message at byte "), std::string::npos)
      << early.output;
  EXPECT_EQ(std::count(early.output.begin(), early.output.end(), '\n'), 1) << early.output;
  EXPECT_FALSE(fs::exists(dir_ / "early"));
}

#undef REQUIRE_SAMPLE  // a unity build compiles the next file in this unit
}  // namespace
