// Vehicle files (heli/vehicle_file.hpp): the shipped X-Cell file says what the `heli` commands assume; an
// outside aircraft's logs (quaternions, body frames, its own channels) read back to the pipeline's layout;
// its control lines are served in its own terms; every malformed file is refused naming its line and key.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <numbers>

#include "outside_aircraft.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "support/input_error.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::logs;
using test_support::input_error_message;

const std::filesystem::path kVehicles =
    std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "vehicles";

// A hover-like flight in the pipeline's layout at 50 Hz: every state and control moves, yaw crosses +-pi.
sysid::FlightLog synthetic_log(std::size_t rows) {
  sysid::FlightLog log;
  for (std::size_t i = 0; i < rows; ++i) {
    const double t = 0.02 * static_cast<double>(i);
    log.time.push_back(t);
    log.states.push_back({0.3 * std::sin(t), -0.2 * std::cos(0.7 * t), -10 + 0.1 * t, 0.2 * std::sin(1.3 * t),
                          -0.15 * std::cos(0.9 * t), heli::wrap_angle(3.0 + 0.05 * t), 1.5 * std::cos(t),
                          -0.5 * std::sin(0.3 * t), 0.2 * std::sin(2 * t), 0.4 * std::cos(1.1 * t),
                          -0.3 * std::sin(0.8 * t), 0.1 * std::cos(0.5 * t)});
    log.controls.push_back(
        {0.5 * std::sin(0.9 * t), -0.4 * std::cos(1.7 * t), 0.2 + 0.1 * std::sin(t), std::sin(0.4 * t)});
  }
  return log;
}

TEST(Vehicles, TheShippedXCellFileIsWhatTheHeliCommandsAssume) {
  const Vehicle file = read_vehicle(kVehicles / "xcell60.toml");
  const Vehicle builtin = xcell_vehicle();
  EXPECT_EQ(file.name(), builtin.name());
  EXPECT_EQ(file.log.rate_hz, builtin.log.rate_hz);
  EXPECT_EQ(file.log.model_rate_hz, builtin.log.model_rate_hz);
  EXPECT_EQ(file.log.attitude_form, builtin.log.attitude_form);
  EXPECT_EQ(file.log.velocity_frame, builtin.log.velocity_frame);
  EXPECT_EQ(file.log.rates_form, builtin.log.rates_form);
  EXPECT_EQ(file.state_fields(), builtin.state_fields());
  for (std::size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(file.log.controls[c].field, builtin.log.controls[c].field);
    EXPECT_EQ(file.log.controls[c].column(c), builtin.log.controls[c].column(c));
    EXPECT_EQ(file.log.controls[c].scale, 1.0);
    EXPECT_EQ(file.log.controls[c].offset, 0.0);
  }
  EXPECT_EQ(file.xcell_latent_states, builtin.xcell_latent_states);
  EXPECT_EQ(file.kinematic_templates, builtin.kinematic_templates);
  EXPECT_EQ(file.simulator, builtin.simulator);
  EXPECT_EQ(file.control_rate_hz, builtin.control_rate_hz);
  EXPECT_EQ(file.target, builtin.target);
  EXPECT_EQ(file.starting_gains, builtin.starting_gains);
  EXPECT_EQ(file.max_tilt_rad, builtin.max_tilt_rad);
  // The pipeline's own CSV read through the X-Cell file is the log read_flight_log gives, bit for bit.
  const std::string csv = sysid::flight_log_csv(synthetic_log(200));
  const sysid::FlightLog own = sysid::parse_flight_log(csv, "own.csv");
  const sysid::FlightLog through = parse_vehicle_log(csv, "own.csv", file);
  EXPECT_EQ(through.time, own.time);
  EXPECT_EQ(through.states, own.states);
  EXPECT_EQ(through.controls, own.controls);
}

// The template users copy reads, and describes the same aircraft as the tests' outside helicopter.
TEST(Vehicles, TheShippedTemplateReadsAsTheOutsideHelicopter) {
  const Vehicle t = read_vehicle(kVehicles / "template.toml");
  const Vehicle o = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  EXPECT_EQ(t.state_fields(), o.state_fields());
  EXPECT_EQ(t.log.rate_hz, o.log.rate_hz);
  EXPECT_EQ(t.control_rate_hz, o.control_rate_hz);
  for (const heli::Controls a : {heli::Controls{0.5, -0.25, 1, -1}, heli::Controls{0, 0, 0, 0}})
    EXPECT_EQ(t.native_of(a), o.native_of(a));
  EXPECT_EQ(t.reward.size(), 6u);
  EXPECT_FALSE(t.xcell_latent_states);
  EXPECT_TRUE(t.kinematic_templates);
}

// Thesis 5.2.2's templates unless the file says otherwise: the quadrotor, whose controls are attitude set
// points its onboard loop follows within a model step, regresses every coefficient.
TEST(Vehicles, KinematicTemplatesUnlessTheFileSaysNone) {
  EXPECT_TRUE(parse_vehicle(test_support::kOutsideVehicle, "outside.toml").kinematic_templates);
  EXPECT_TRUE(xcell_vehicle().kinematic_templates);
  EXPECT_FALSE(read_vehicle(kVehicles / "crazyflie2.toml").kinematic_templates);
  EXPECT_FALSE(parse_vehicle(std::string(test_support::kOutsideVehicle) + "\n[model]\ntemplates = \"none\"\n",
                             "v.toml")
                   .kinematic_templates);
}

TEST(Vehicles, PresentDefaultsAreNoLatentStatesLqrGainsAndFiftyHertz) {
  const Vehicle v = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  EXPECT_EQ(v.name(), "outside-heli");
  EXPECT_FALSE(v.xcell_latent_states);  // latent states only when the file names them
  EXPECT_EQ(v.simulator, "none");
  EXPECT_EQ(v.starting_gains, "lqr");
  EXPECT_EQ(v.control_rate_hz, 10);
  EXPECT_EQ(v.log.rate_hz, 10);
  EXPECT_EQ(v.log.controls[3].label(), "rudder_us");
  EXPECT_EQ(v.log.controls[0].label(), "thr");
}

TEST(Vehicles, TheHoverRewardMatchesTheCostTheAircraftIsJudgedBy) {
  const Vehicle v = parse_vehicle(std::string(test_support::kOutsideVehicle) +
                                      "\n[hover.reward]\nposition_m = 0.3\nattitude_rad = 0.2\naction = 0\n",
                                  "v.toml");
  EXPECT_EQ(v.reward, (std::vector<std::pair<std::string, double>>{
                          {"position_m", 0.3}, {"action", 0.0}, {"attitude_rad", 0.2}}));
  EXPECT_TRUE(parse_vehicle(test_support::kOutsideVehicle, "v.toml").reward.empty());
  const std::string bad = input_error_message([] {
    (void)parse_vehicle(std::string(test_support::kOutsideVehicle) + "\n[hover.reward]\nyaw_rad = 0\n",
                        "v.toml");
  });
  EXPECT_NE(bad.find("v.toml:51: hover.reward.yaw_rad: expected a typical size of at least 1e-06, got 0"),
            std::string::npos)
      << bad;
  const std::string unknown = input_error_message([] {
    (void)parse_vehicle(std::string(test_support::kOutsideVehicle) + "\n[hover.reward]\nroll_rad = 1\n",
                        "v.toml");
  });
  EXPECT_NE(unknown.find("hover.reward.roll_rad: unknown key"), std::string::npos) << unknown;
}

TEST(Vehicles, AnOutsideAircraftsLogReadsBackToThePipelinesLayout) {
  const Vehicle v = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  const sysid::FlightLog own = test_support::every_nth_row(synthetic_log(2000), 5);  // 10 Hz
  const sysid::FlightLog read = parse_vehicle_log(test_support::outside_log_csv(own), "outside.csv", v);
  EXPECT_EQ(test_support::log_difference(read, own), "");
}

// What a pilot on the project's ground truth writes for the vehicle (vehicle_log_csv) reads back through the
// vehicle file to the same rows; the shipped files read the pipeline's own layout as it is.
TEST(Vehicles, ALogWrittenInTheVehiclesLayoutReadsBackToThePipelinesLayout) {
  const Vehicle v = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  const sysid::FlightLog log = synthetic_log(2000);
  const sysid::FlightLog own = test_support::every_nth_row(log, 5);
  const sysid::FlightLog read = parse_vehicle_log(vehicle_log_csv(log, v, 5), "outside.csv", v);
  EXPECT_EQ(test_support::log_difference(read, own), "");
  EXPECT_FALSE(logs_in_pipeline_layout(v));
  for (const char* shipped : {"xcell60.toml", "crazyflie2.toml"})
    EXPECT_TRUE(logs_in_pipeline_layout(read_vehicle(kVehicles / shipped))) << shipped;
  EXPECT_TRUE(logs_in_pipeline_layout(xcell_vehicle()));
}

TEST(Vehicles, ControlsMapBothWaysForEveryWayOfWritingAChannel) {
  const Vehicle v = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  for (const heli::Controls a :
       {heli::Controls{0, 0, 0, 0}, heli::Controls{1, -1, 0.5, -0.25}, heli::Controls{-0.3, 0.7, -1, 1}}) {
    const auto native = v.native_of(a);
    const auto expected = test_support::outside_controls(a);
    for (std::size_t c = 0; c < 4; ++c) EXPECT_NEAR(native[c], expected[c], 1e-12) << c;
    const heli::Controls back = v.axes_of(native);
    for (std::size_t c = 0; c < 4; ++c) EXPECT_NEAR(back[c], a[c], 1e-12) << c;
  }
}

// A controller that answers a fixed function of the state it sees, in the pipeline's layout.
class StateEcho : public heli::HeliController {
 public:
  using heli::HeliController::act;
  heli::Controls act(const heli::LoggedState& s, double time, heli::ControllerMemory&) const override {
    return {s[4] + s[9], -s[3] + 0.1 * time, s[2] / 20 + s[8], std::sin(s[5]) + s[11]};
  }
  heli::SetPoint target(double) const override { return {}; }
};

TEST(Vehicles, ControlLinesAreServedInTheAircraftsOwnTerms) {
  const Vehicle v = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  const sysid::FlightLog own = test_support::every_nth_row(synthetic_log(500), 5);
  // The aircraft's own log as the input, header and all (its columns in its order, an extra column).
  std::string input = test_support::outside_log_csv(own);
  // Then lines without a header's help would be read in the documented order: the same file's rows give the
  // same answers only through the header, which the first line is.
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  char* out_text = nullptr;
  std::size_t out_size = 0;
  std::FILE* out = open_memstream(&out_text, &out_size);
  std::FILE* err = std::tmpfile();
  const StateEcho controller;
  const auto stats =
      heli::run_control_loop(controller, {0, 0, 0, 0}, in, out, err, 0.1, control_line_format(v));
  std::fclose(in);
  std::fclose(out);
  std::fclose(err);
  const std::string answers(out_text, out_size);
  std::free(out_text);
  EXPECT_EQ(stats.malformed, 0);
  EXPECT_EQ(stats.lines, static_cast<std::int64_t>(own.rows() + 1));
  std::vector<std::string> lines;
  for (std::size_t start = 0; start < answers.size();) {
    const std::size_t nl = answers.find('\n', start);
    lines.push_back(answers.substr(start, nl - start));
    start = nl + 1;
  }
  ASSERT_EQ(lines.size(), own.rows() + 1);
  EXPECT_EQ(lines[0], "thr,ail,ele,rudder_us");
  for (std::size_t i = 0; i < own.rows(); ++i) {
    const auto expected = test_support::outside_controls(controller.act(own.states[i], own.time[i]));
    const auto fields = parse_csv(lines[i + 1]);
    ASSERT_EQ(fields.size(), 1u);
    ASSERT_EQ(fields[0].size(), 4u) << lines[i + 1];
    for (std::size_t c = 0; c < 4; ++c)
      EXPECT_NEAR(std::stod(fields[0][c]), expected[c], 1e-9 * (c == 3 ? 1000 : 1))
          << "line " << i << " " << c;
  }
  // Without a header: the documented order (position, velocity, attitude, rates), time first when 14 fields.
  const auto s = test_support::outside_state(own.states[7]);
  std::string line = format_double(own.time[7]);
  for (double x : s) line += "," + format_double(x);
  heli::LoggedState parsed{};
  bool has_time = false;
  double time = 0;
  std::string why;
  ASSERT_TRUE(heli::parse_state_line(line, control_line_format(v), {}, &parsed, &has_time, &time, &why))
      << why;
  EXPECT_TRUE(has_time);
  EXPECT_EQ(time, own.time[7]);
  for (std::size_t k = 0; k < 12; ++k) EXPECT_NEAR(parsed[k], own.states[7][k], 1e-12) << k;
  EXPECT_FALSE(heli::parse_state_line("1,2,3", control_line_format(v), {}, &parsed, &has_time, &time, &why));
  EXPECT_EQ(why, "expected 13, 14 or 18 fields, got 3");
  EXPECT_FALSE(heli::parse_state_line("0,0,-10,0,0,0,0,0,0,0,0,0,0,0", control_line_format(v), {}, &parsed,
                                      &has_time, &time, &why));  // an all-zero quaternion
  EXPECT_NE(why.find("quaternion"), std::string::npos) << why;
}

TEST(Vehicles, AVehicleInThePipelinesLayoutReadsLinesWithoutAHeaderAsHeliControlDoes) {
  const Vehicle xcell = read_vehicle(kVehicles / "xcell60.toml");
  // x, y, z, roll, pitch, yaw, xdot, ydot, zdot and the rates, time first: `heli control`'s 13-field line.
  const std::string line = "0.5,1,2,-10,0.1,-0.2,0.3,4,5,6,0.01,0.02,0.03";
  heli::LoggedState own{}, through_vehicle{};
  bool has_time = false;
  double time = 0;
  std::string why;
  ASSERT_TRUE(heli::parse_state_line(line, &own, &has_time, &time, &why)) << why;
  ASSERT_TRUE(
      heli::parse_state_line(line, control_line_format(xcell), {}, &through_vehicle, &has_time, &time, &why))
      << why;
  EXPECT_EQ(through_vehicle, own);
  EXPECT_EQ(own[heli::logged::roll], 0.1);
  EXPECT_EQ(own[heli::logged::xdot], 4);
}

using test_support::replaced;

TEST(Vehicles, EveryMalformedFileIsRefusedNamingItsLineAndKey) {
  const std::string good = test_support::kOutsideVehicle;
  auto message = [](const std::string& text) {
    return input_error_message([&] { (void)parse_vehicle(text, "v.toml"); });
  };
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {replaced(good, "axis = \"roll\"", "axis = \"thrust\""),
       "v.toml:32: log.controls[1].axis: the thrust axis is already driven by log.controls[0]"},
      {replaced(good, "axis = \"roll\"", "axis = \"sideways\""), "v.toml:32: log.controls[1].axis: expected"},
      {replaced(good, "axis = \"roll\"\n", ""), "log.controls: expected an axis on every channel or on none"},
      {replaced(good, "range = [0, 1]", "range = [1, 0]"),
       "v.toml:28: log.controls[0].range: expected [low, high]"},
      {replaced(good, "range = [0, 1]", "range = [0, 1]\nscale = 2"),
       "log.controls[0]: expected either range and sign, or scale and offset"},
      {replaced(good, "sign = -1\n\n[[log.controls]]", "sign = 0.5\n\n[[log.controls]]"),
       "v.toml:38: log.controls[2].sign: expected 1 or -1, got 0.5"},
      {replaced(good, "sign = -1\n\n[[log.controls]]", "sign = 2\n\n[[log.controls]]"),
       "v.toml:38: log.controls[2].sign: expected 1 or -1, got 2"},
      {replaced(good, "field = \"ail\"", "field = \"thr\""), "channels 0 and 1 have the same name 'thr'"},
      {replaced(good, "frame = \"body\"", "frame = \"body\"\nframes = \"world\""),
       "v.toml:16: log.velocity.frames: unknown key"},
      {replaced(good, "[control]\nrate_hz = 10", "[control]\nrate = 10"),
       "control.rate: unknown key (did you mean 'rate_hz'?); expected one of"},
      {good + "\n[hover]\ntarget = [0, 0]\n", "hover.target: expected a list of 4 numbers"},
      {good + "\n[envelope]\nmax_tilt_rad = 2\n", "envelope.max_tilt_rad: expected a number in [0.01, 1.5]"},
      {replaced(good, "name = \"outside-heli\"", "name = \"outside-heli\"\nlatent_states = \"gyro\""),
       "vehicle.latent_states: expected 'none' or 'xcell', got 'gyro'"},
      {good + "\n[envelope]\nmax_tilt_rad = \"steep\"\n",
       "envelope.max_tilt_rad: expected a number in [0.01, 1.5], got 'steep'"},
      {replaced(good, "[log.rates]\nfields = [\"p\", \"q\", \"r\"]", "[log.rates]"),
       "log.rates.fields: missing; expected a list of 3 field (or CSV column) names"},
      {good + "\n[wind]\nspeed = 3\n",
       "wind: unknown key; expected one of control, cost, envelope, hover, log, model, vehicle"},
      {good + "\n[model]\ntemplates = \"thesis\"\n",
       "model.templates: expected 'kinematic' or 'none', got 'thesis'"},
      {replaced(good, "name = \"outside-heli\"", "name = \"\""),
       "v.toml:3: vehicle.name: expected a non-empty name"},
      {replaced(good, "fields = [\"u\", \"v\", \"w\"]", "fields = [\"u\", \"n\", \"w\"]"),
       "log.velocity: the field 'n' is also in log.position; expected each field once"},
      {replaced(good, "time = \"t\"", "time = \"thr\""),
       "log.controls[0]: the field 'thr' is also in log.time; expected each field once"},
  };
  for (const auto& c : cases) {
    const std::string m = message(c.text);
    EXPECT_NE(m.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
}

TEST(Vehicles, LogsThatDisagreeWithTheFileAreRefusedNamingLineAndColumn) {
  const Vehicle v = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  const sysid::FlightLog own = test_support::every_nth_row(synthetic_log(1000), 5);
  const std::string csv = test_support::outside_log_csv(own);
  auto message = [&](const std::string& text) {
    return input_error_message([&] { (void)parse_vehicle_log(text, "o.csv", v); });
  };
  // A 50 Hz log where the file says 10 Hz.
  EXPECT_NE(message(test_support::outside_log_csv(synthetic_log(1000)))
                .find("rows come at 50 Hz; expected "
                      "log.rate_hz = 10 Hz of outside.toml"),
            std::string::npos);
  // A missing column names the aircraft's column.
  EXPECT_NE(message(replaced(csv, "qw,", "qW,")).find("o.csv:1:qw: required column missing"),
            std::string::npos);
  // A throttle outside its range: line 3 is the second row.
  std::string bad = csv;
  std::size_t thr_at = bad.find('\n', bad.find('\n') + 1) + 1;                 // the second row
  for (int field = 0; field < 5; ++field) thr_at = bad.find(',', thr_at) + 1;  // its sixth field, thr
  bad.replace(thr_at, bad.find(',', thr_at) - thr_at, "1.5");
  EXPECT_NE(message(bad).find("o.csv:3:thr: 1.5 gives thrust (a3) = 2; expected [-1, 1]"), std::string::npos)
      << message(bad);
}

}  // namespace
