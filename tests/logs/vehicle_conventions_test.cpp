// A vehicle file's conventions (issue 53): world NED or ENU, body FRD or FLU, a quaternion's order and
// direction, angles in rad or deg and rates in rad/s or deg/s. Every combination is checked against an
// independent conversion through rotation matrices and quaternion products, a ROS-convention aircraft against
// values worked by hand, and logs written in any convention read back to the same pipeline states.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "outside_aircraft.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "support/input_error.hpp"

namespace pegasus::logs::conventions_test {
namespace {

using heli::Euler;
using heli::Mat3;
using heli::Vec3;
constexpr double kPi = std::numbers::pi;
constexpr double kDeg = std::numbers::pi / 180;

// R_NED,ENU (ENU vectors into NED) and R_FLU,FRD (FRD vectors into FLU), each its own inverse.
Mat3 world_change(bool enu) {
  Mat3 a = Mat3::Identity();
  if (enu) a << 0, 1, 0, 1, 0, 0, 0, 0, -1;
  return a;
}
Mat3 body_change(bool flu) {
  Mat3 b = Mat3::Identity();
  if (flu) b.diagonal() << 1, -1, -1;
  return b;
}

// Z-Y-X Euler angles of a rotation matrix, as a textbook gives them (pitch inside +-pi/2).
Euler euler_of_matrix(const Mat3& r) {
  return {std::atan2(r(2, 1), r(2, 2)), -std::asin(std::clamp(r(2, 0), -1.0, 1.0)),
          std::atan2(r(1, 0), r(0, 0))};
}

double angle_difference(double a, double b) { return std::abs(heli::wrap_angle(a - b)); }

// Eigen's quaternion of (w, x, y, z).
Eigen::Quaterniond quaternion(const std::array<double, 4>& wxyz) {
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}

struct Frames {
  bool enu, flu;
  std::string name() const { return fmt::format("{}/{}", enu ? "ENU" : "NED", flu ? "FLU" : "FRD"); }
};
constexpr std::array<Frames, 4> kAllFrames{{{false, false}, {true, true}, {true, false}, {false, true}}};

VehicleLogSpec spec_of(const Frames& f) {
  VehicleLogSpec s;
  s.world_frame = f.enu ? "ENU" : "NED";
  s.body_frame = f.flu ? "FLU" : "FRD";
  return s;
}

Euler random_attitude(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> angle(-kPi, kPi), pitch(-1.5, 1.5);
  return {angle(rng), pitch(rng), angle(rng)};
}

// The closed forms of heli/vehicle_file.hpp (pitch' = -pitch, yaw' = pi/2 - yaw, roll' = roll + pi with one
// frame flipped) give the rotation R' = R_world',W R_WB R_B,body' of the log's frames, and back.
TEST(VehicleConventions, EulerAnglesInEveryPairOfFramesAreTheRotationOfTheMatrices) {
  std::mt19937_64 rng(53);
  for (const Frames& f : kAllFrames) {
    const VehicleLogSpec spec = spec_of(f);
    for (int i = 0; i < 2000; ++i) {
      const Euler e = random_attitude(rng);
      const Mat3 native = world_change(f.enu) * heli::rotation_world_from_body(e) * body_change(f.flu);
      const Euler n = native_euler(spec, e);
      ASSERT_LE((heli::rotation_world_from_body(n) - native).cwiseAbs().maxCoeff(), 1e-14)
          << f.name() << " " << i;
      const Euler expected = euler_of_matrix(native);
      EXPECT_LE(angle_difference(n.roll, expected.roll), 1e-9) << f.name();
      EXPECT_LE(angle_difference(n.yaw, expected.yaw), 1e-9) << f.name();
      EXPECT_NEAR(n.pitch, expected.pitch, 1e-9) << f.name();
      const Euler back = euler_of(spec, n);
      EXPECT_LE(angle_difference(back.roll, e.roll), 1e-14) << f.name();
      EXPECT_EQ(back.pitch, e.pitch) << f.name();
      EXPECT_LE(angle_difference(back.yaw, e.yaw), 1e-14) << f.name();
    }
  }
}

// A body-FLU-to-world-ENU quaternion q is the pipeline's q_NED,ENU * q * q_FLU,FRD (issue 53), in either
// order of components and either direction.
TEST(VehicleConventions, QuaternionsInEveryOrderDirectionAndFrameAreTheQuaternionProducts) {
  std::mt19937_64 rng(5);
  const Eigen::Quaterniond q_ned_enu(0, std::sqrt(0.5), std::sqrt(0.5), 0), q_flu_frd(0, 1, 0, 0);
  for (const Frames& f : kAllFrames)
    for (const std::string order : {"wxyz", "xyzw"})
      for (const std::string direction : {"body_to_world", "world_to_body"}) {
        VehicleLogSpec spec = spec_of(f);
        spec.quaternion_order = order;
        spec.quaternion_direction = direction;
        const std::string where = f.name() + " " + order + " " + direction;
        for (int i = 0; i < 500; ++i) {
          const Euler e = random_attitude(rng);
          const Eigen::Quaterniond q = quaternion(heli::quaternion_from_euler(e));  // FRD to NED
          // The log's quaternion: q' with q = A q' B, so q' = A^-1 q B^-1 (A, B half turns: their own
          // inverses up to sign); world to body is its inverse; xyzw puts w last. Any length: scaled by 3.
          Eigen::Quaterniond native = q;
          if (f.enu) native = q_ned_enu.conjugate() * native;
          if (f.flu) native = native * q_flu_frd.conjugate();
          if (direction == "world_to_body") native = native.conjugate();
          std::array<double, 4> fields{native.w(), native.x(), native.y(), native.z()};
          if (order == "xyzw") fields = {native.x(), native.y(), native.z(), native.w()};
          for (double& c : fields) c *= 3;
          const Euler read = euler_of(spec, native_euler_of_quaternion(spec, fields.data()));
          ASSERT_LE((heli::rotation_world_from_body(read) - heli::rotation_world_from_body(e))
                        .cwiseAbs()
                        .maxCoeff(),
                    1e-12)
              << where << " " << i;
          // And what the writer gives is the same rotation (q and -q are one).
          const auto written = native_quaternion(spec, native_euler(spec, e));
          double dot = 0;
          for (std::size_t c = 0; c < 4; ++c) dot += written[c] * fields[c] / 3;
          EXPECT_NEAR(std::abs(dot), 1, 1e-12) << where << " " << i;
        }
      }
}

// The same physical motion in two conventions: nose up, roll right, a turn to the left, a climb, flying
// east, all read from a ROS (REP 103: ENU, FLU) aircraft, are the pipeline's nose up, roll right, turn left,
// climb, east.
TEST(VehicleConventions, AMotionInRosTermsIsTheSameMotionInThePipelines) {
  VehicleLogSpec ros = spec_of({true, true});
  // Level, facing north: in ENU the nose is along y, yaw' = 90 deg.
  const Euler north = euler_of(ros, Euler{0, 0, kPi / 2});
  EXPECT_NEAR(north.yaw, 0, 1e-15);
  // Nose up 10 deg: in FLU (y left) a rotation about +y takes the nose down, so pitch' = -10 deg.
  const Euler nose_up = euler_of(ros, Euler{0, -10 * kDeg, kPi / 2});
  const Vec3 nose_W = heli::world_from_body(nose_up, Vec3(1, 0, 0));
  EXPECT_LT(nose_W.z(), 0);  // up, in NED
  EXPECT_NEAR(nose_up.pitch, 10 * kDeg, 1e-15);
  // Roll right 20 deg: about the forward axis in both, the left side up; the pipeline's roll +.
  const Euler right = euler_of(ros, Euler{20 * kDeg, 0, kPi / 2});
  EXPECT_NEAR(right.roll, 20 * kDeg, 1e-15);
  EXPECT_GT(heli::world_from_body(right, Vec3(0, 1, 0)).z(), 0);  // the right side down
  // Turning left (yaw' growing, counter-clockwise seen from above) is the pipeline's yaw falling.
  const Euler left = euler_of(ros, Euler{0, 0, kPi / 2 + 0.3});
  EXPECT_NEAR(left.yaw, -0.3, 1e-15);
  EXPECT_EQ(euler_rates_of(ros, Vec3(0, 0, 0.3)), Vec3(0, 0, -0.3));
  // Climbing 2 m/s east: ENU (2, 0, 1) is NED (0, 2, -1).
  EXPECT_EQ(world_vector_of(ros, Vec3(2, 0, 1)), Vec3(0, 2, -1));
  // A yaw-left body rate r' > 0 about FLU's up axis is the FRD body rate r < 0.
  EXPECT_EQ(body_vector_of(ros, Vec3(0.1, 0.2, 0.3)), Vec3(0.1, -0.2, -0.3));
}

// A ROS-convention multirotor: ENU, FLU, a quaternion x, y, z, w, rates in deg/s, world velocity.
constexpr const char* kRosVehicle = R"([vehicle]
name = "ros"

[log]
rate_hz = 50
model_rate_hz = 10
world_frame = "ENU"
body_frame = "FLU"

[log.position]
fields = ["px", "py", "pz"]
unit = "m"

[log.velocity]
fields = ["vx", "vy", "vz"]
frame = "world"
unit = "m/s"

[log.attitude]
fields = ["qx", "qy", "qz", "qw"]
form = "quaternion"
order = "xyzw"
unit = "deg"

[log.rates]
fields = ["wx", "wy", "wz"]
form = "body"
unit = "deg/s"

[[log.controls]]
field = "roll_sp"
axis = "roll"
range = [-30, 30]
unit = "deg"

[[log.controls]]
field = "pitch_sp"
axis = "pitch"
range = [-30, 30]
unit = "deg"

[[log.controls]]
field = "yaw_rate_sp"
axis = "yaw"
range = [-90, 90]
sign = -1
unit = "deg/s"

[[log.controls]]
field = "thrust"
axis = "thrust"
range = [0, 1]
unit = "1"

[hover]
target = [1, 2, 10, 90]

[envelope]
max_tilt = 45
)";

// A row worked by hand: ENU position (1, 2, 3) is NED (2, 1, -3); the quaternion x, y, z, w of a level
// aircraft facing north (yaw' = 90 deg about up) is (0, 0, sin 45, cos 45); FLU body rates (10, 20, 30) deg/s
// are FRD (10, -20, -30) deg/s, and at level the Euler rates are the body rates.
TEST(VehicleConventions, ARosRowReadsAsWorkedByHand) {
  const Vehicle v = parse_vehicle(kRosVehicle, "ros.toml");
  const double h = std::sqrt(0.5);
  const std::vector<double> row{1, 2, 3, 4, 5, 6, 0, 0, h, h, 10, 20, 30};
  const heli::LoggedState s = v.state_of(row);
  const heli::LoggedState expected{2, 1, -3, 0, 0, 0, 5, 4, -6, 10 * kDeg, -20 * kDeg, -30 * kDeg};
  for (std::size_t k = 0; k < 12; ++k) EXPECT_NEAR(s[k], expected[k], 1e-15) << k;
  const std::vector<double> back = v.native_state(s);
  ASSERT_EQ(back.size(), row.size());
  for (std::size_t k = 0; k < row.size(); ++k) EXPECT_NEAR(back[k], row[k], 1e-12) << k;
  // [hover] in the file's terms: ENU (1, 2, 10) m, yaw 90 deg (north) is NED (2, 1, -10), yaw 0.
  EXPECT_EQ(v.target[0], 2);
  EXPECT_EQ(v.target[1], 1);
  EXPECT_EQ(v.target[2], -10);
  EXPECT_NEAR(v.target[3], 0, 1e-15);
  EXPECT_NEAR(v.max_tilt_rad, kPi / 4, 1e-15);
  EXPECT_EQ(v.log.controls[0].unit, "deg");
  EXPECT_EQ(v.log.controls[2].unit, "deg/s");
  // A channel's unit changes no number: 15 deg of a [-30, 30] deg range is half the roll axis.
  EXPECT_EQ(v.axes_of(std::vector<double>{15, 0, 0, 0.5})[1], 0.5);
  EXPECT_FALSE(logs_in_pipeline_layout(v));
  EXPECT_FALSE(v.log.pipeline_conventions());
}

struct Combination {
  Frames frames;
  std::string attitude;  // "euler rad", "euler deg", "quaternion wxyz body_to_world", ...
  std::string velocity, rates_form, rates_unit;
  std::string name() const {
    return fmt::format("{} {} velocity {} rates {} {}", frames.name(), attitude, velocity, rates_form,
                       rates_unit);
  }
};

std::vector<Combination> all_combinations() {
  std::vector<Combination> out;
  for (const Frames& f : kAllFrames)
    for (const std::string attitude :
         {"euler rad", "euler deg", "quaternion wxyz body_to_world", "quaternion xyzw body_to_world",
          "quaternion wxyz world_to_body", "quaternion xyzw world_to_body"})
      for (const std::string velocity : {"world", "body"})
        for (const std::string rates : {"body", "euler"})
          for (const std::string unit : {"rad/s", "deg/s"})
            out.push_back({f, attitude, velocity, rates, unit});
  return out;
}

std::string vehicle_text(const Combination& c) {
  std::string t = fmt::format(
      "[vehicle]\nname = \"c\"\n[log]\nrate_hz = 50\nmodel_rate_hz = 10\nworld_frame = \"{}\"\nbody_frame = "
      "\"{}\"\n[log.position]\nfields = [\"px\", \"py\", \"pz\"]\n[log.velocity]\nfields = [\"vx\", \"vy\", "
      "\"vz\"]\nframe = \"{}\"\n",
      c.frames.enu ? "ENU" : "NED", c.frames.flu ? "FLU" : "FRD", c.velocity);
  if (c.attitude.starts_with("euler"))
    t += fmt::format("[log.attitude]\nfields = [\"a0\", \"a1\", \"a2\"]\nform = \"euler\"\nunit = \"{}\"\n",
                     c.attitude.substr(6));
  else
    t += fmt::format(
        "[log.attitude]\nfields = [\"q0\", \"q1\", \"q2\", \"q3\"]\nform = \"quaternion\"\norder = \"{}\"\n"
        "direction = \"{}\"\n",
        c.attitude.substr(11, 4), c.attitude.substr(16));
  t += fmt::format("[log.rates]\nfields = [\"w0\", \"w1\", \"w2\"]\nform = \"{}\"\nunit = \"{}\"\n",
                   c.rates_form, c.rates_unit);
  for (int k = 0; k < 4; ++k) t += fmt::format("[[log.controls]]\nfield = \"c{}\"\n", k);
  return t;
}

// The log's values of the pipeline's state, by the matrices and the quaternion products, not by the library's
// closed forms.
std::vector<double> independent_native(const Combination& c, const heli::LoggedState& s) {
  const Mat3 a = world_change(c.frames.enu), b = body_change(c.frames.flu);
  const Euler e{s[3], s[4], s[5]};
  const Mat3 r = heli::rotation_world_from_body(e);
  const Mat3 native_r = a * r * b;
  const Euler n = euler_of_matrix(native_r);
  const Vec3 p = a * Vec3(s[0], s[1], s[2]), v_W(s[6], s[7], s[8]);
  const Vec3 v = c.velocity == "world" ? Vec3(a * v_W) : Vec3(b * r.transpose() * v_W);
  const Vec3 w_B = heli::body_rates_from_euler_rates(e, Vec3(s[9], s[10], s[11]));
  const Vec3 w_native_body = b * w_B;  // the body rate in the log's body frame
  // Euler-angle rates of the log's own angles: the Z-Y-X kinematics hold in any right-handed pair of frames.
  Vec3 w = c.rates_form == "body" ? w_native_body : heli::euler_rates_from_body_rates(n, w_native_body);
  if (c.rates_unit == "deg/s") w /= kDeg;
  std::vector<double> out{p.x(), p.y(), p.z(), v.x(), v.y(), v.z()};
  if (c.attitude.starts_with("euler")) {
    const double k = c.attitude == "euler deg" ? kDeg : 1;
    out.insert(out.end(), {n.roll / k, n.pitch / k, n.yaw / k});
  } else {
    Eigen::Quaterniond q(native_r);
    if (c.attitude.ends_with("world_to_body")) q = q.conjugate();
    if (c.attitude.find("xyzw") != std::string::npos)
      out.insert(out.end(), {q.x(), q.y(), q.z(), q.w()});
    else
      out.insert(out.end(), {q.w(), q.x(), q.y(), q.z()});
  }
  out.insert(out.end(), {w.x(), w.y(), w.z()});
  return out;
}

// A hover-like flight at 50 Hz: every state moves, yaw crosses +-pi.
sysid::FlightLog convention_flight(std::size_t rows) {
  sysid::FlightLog log;
  for (std::size_t i = 0; i < rows; ++i) {
    const double t = 0.02 * static_cast<double>(i);
    log.time.push_back(t);
    log.states.push_back({0.3 * std::sin(t), -0.2 * std::cos(0.7 * t), -10 + 0.1 * t, 0.2 * std::sin(1.3 * t),
                          -0.15 * std::cos(0.9 * t), heli::wrap_angle(3.0 + 0.5 * t), 1.5 * std::cos(t),
                          -0.5 * std::sin(0.3 * t), 0.2 * std::sin(2 * t), 0.4 * std::cos(1.1 * t),
                          -0.3 * std::sin(0.8 * t), 0.1 * std::cos(0.5 * t)});
    log.controls.push_back(
        {0.5 * std::sin(0.9 * t), -0.4 * std::cos(1.7 * t), 0.2 + 0.1 * std::sin(t), std::sin(0.4 * t)});
  }
  return log;
}

// Every combination of frames, attitude form, order, direction and unit, velocity frame, rates form and unit:
// the library's values are the independent conversion's (a quaternion up to its sign), they read back to the
// pipeline's state, and a log vehicle_log_csv writes reads back through parse_vehicle_log to the same states.
TEST(VehicleConventions, EveryCombinationMatchesTheIndependentConversionAndReadsBack) {
  const sysid::FlightLog flight = convention_flight(150);
  for (const Combination& c : all_combinations()) {
    const Vehicle v = parse_vehicle(vehicle_text(c), "c.toml");
    const bool quaternion = c.attitude.starts_with("quaternion");
    for (std::size_t i = 0; i < flight.rows(); i += 7) {
      const heli::LoggedState& s = flight.states[i];
      const std::vector<double> expected = independent_native(c, s), native = v.native_state(s);
      ASSERT_EQ(native.size(), expected.size()) << c.name();
      double sign = 1;
      if (quaternion) {
        double dot = 0;
        for (std::size_t k = 6; k < 10; ++k) dot += native[k] * expected[k];
        sign = dot < 0 ? -1 : 1;
      }
      for (std::size_t k = 0; k < native.size(); ++k) {
        const bool angle = !quaternion && k >= 6 && k < 9;
        const double period = c.attitude == "euler deg" ? 360 : 2 * kPi;
        const bool in_quaternion = quaternion && k >= 6 && k < 10;
        const double d = in_quaternion ? native[k] - sign * expected[k] : native[k] - expected[k];
        const double difference = angle ? std::remainder(d, period) : d;
        EXPECT_LE(std::abs(difference), 1e-9 * std::max(1.0, std::abs(expected[k])))
            << c.name() << " row " << i << " field " << k << ": " << native[k] << ", expected "
            << expected[k];
      }
      const heli::LoggedState back = v.state_of(expected);
      for (std::size_t k = 0; k < 12; ++k) {
        const double d = back[k] - s[k];
        EXPECT_LE(std::abs(k >= 3 && k < 6 ? heli::wrap_angle(d) : d), 1e-9)
            << c.name() << " row " << i << " " << k;
      }
    }
    const sysid::FlightLog read = parse_vehicle_log(vehicle_log_csv(flight, v), "c.csv", v);
    EXPECT_EQ(test_support::log_difference(read, flight), "") << c.name();
  }
}

// One flight written by a PX4-convention (NED, FRD) and a ROS-convention (ENU, FLU) vehicle: different
// numbers in the files, the same pipeline states read back.
TEST(VehicleConventions, OneFlightWrittenInTwoConventionsReadsBackTheSame) {
  const sysid::FlightLog flight = convention_flight(300);
  Combination ned{{false, false}, "quaternion wxyz body_to_world", "world", "body", "rad/s"};
  Combination ros{{true, true}, "quaternion xyzw body_to_world", "world", "body", "deg/s"};
  const Vehicle a = parse_vehicle(vehicle_text(ned), "ned.toml"),
                b = parse_vehicle(vehicle_text(ros), "ros.toml");
  const std::string csv_a = vehicle_log_csv(flight, a), csv_b = vehicle_log_csv(flight, b);
  EXPECT_NE(csv_a, csv_b);
  const sysid::FlightLog read_a = parse_vehicle_log(csv_a, "a.csv", a),
                         read_b = parse_vehicle_log(csv_b, "b.csv", b);
  EXPECT_EQ(test_support::log_difference(read_a, read_b), "");
  // The files differ as the conventions say: ROS's px is PX4's py, its pz is -z.
  const std::size_t row = 17;
  const std::vector<double> na = a.native_state(flight.states[row]), nb = b.native_state(flight.states[row]);
  EXPECT_EQ(nb[0], na[1]);
  EXPECT_EQ(nb[1], na[0]);
  EXPECT_EQ(nb[2], -na[2]);
}

// Without the new keys nothing changes: the shipped files and the outside aircraft keep the pipeline's
// conventions, and their rows go through no arithmetic (bit for bit what they always read).
TEST(VehicleConventions, FilesWithoutConventionKeysKeepThePipelinesAndReadBitForBit) {
  const std::filesystem::path vehicles =
      std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "vehicles";
  for (const char* shipped : {"xcell60.toml", "crazyflie2.toml", "px4-quadrotor.toml", "template.toml"})
    EXPECT_TRUE(read_vehicle(vehicles / shipped).log.pipeline_conventions()) << shipped;
  const Vehicle outside = parse_vehicle(test_support::kOutsideVehicle, "outside.toml");
  EXPECT_TRUE(outside.log.pipeline_conventions());
  const Vehicle euler =
      parse_vehicle(vehicle_text({{false, false}, "euler rad", "world", "euler", "rad/s"}), "e.toml");
  const std::vector<double> row{1.5, -2.25, -10.125, 0.1, 0.2, 0.3, 0.4, -0.5, 4.0, 0.01, 0.02, 0.03};
  const heli::LoggedState s = euler.state_of(row);
  // The fields are position, velocity, attitude, rates; the pipeline's states position, attitude, velocity,
  // rates.
  const heli::LoggedState expected{row[0], row[1], row[2], row[6], row[7],  row[8],
                                   row[3], row[4], row[5], row[9], row[10], row[11]};
  EXPECT_EQ(s, expected);  // bit for bit, not even a wrap of the yaw
  EXPECT_EQ(euler.target, Vehicle{}.target);
}

// The shipped ROS example says REP 103's conventions, and its set point is 2 m up facing north.
TEST(VehicleConventions, TheShippedRosQuadrotorIsInRosConventions) {
  const Vehicle v = read_vehicle(std::filesystem::path(PEGASUS_SOURCE_DIR) / "experiments" / "vehicles" /
                                 "ros-quadrotor.toml");
  EXPECT_EQ(v.log.world_frame, "ENU");
  EXPECT_EQ(v.log.body_frame, "FLU");
  EXPECT_EQ(v.log.quaternion_order, "xyzw");
  EXPECT_EQ(v.log.quaternion_direction, "body_to_world");
  EXPECT_EQ(v.log.attitude_unit, "deg");
  EXPECT_EQ(v.log.rates_unit, "deg/s");
  EXPECT_EQ(v.target[2], -2);
  EXPECT_NEAR(v.target[3], 0, 1e-15);
  EXPECT_NEAR(v.max_tilt_rad, kPi / 4, 1e-15);
  // Its log written and read back: the same states.
  const sysid::FlightLog flight = convention_flight(150);
  const sysid::FlightLog read = parse_vehicle_log(vehicle_log_csv(flight, v), "ros.csv", v);
  EXPECT_EQ(test_support::log_difference(read, flight), "");
}

TEST(VehicleConventions, BadConventionsAreRefusedNamingLineAndKey) {
  using test_support::replaced;
  const std::string ros = kRosVehicle;
  auto message = [](const std::string& text) {
    return test_support::input_error_message([&] { (void)parse_vehicle(text, "v.toml"); });
  };
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {replaced(ros, "world_frame = \"ENU\"", "world_frame = \"NWU\""),
       "v.toml:7: log.world_frame: expected 'NED' or 'ENU', got 'NWU'"},
      {replaced(ros, "body_frame = \"FLU\"", "body_frame = \"flu\""),
       "log.body_frame: expected 'FRD' or 'FLU'"},
      {replaced(ros, "order = \"xyzw\"", "order = \"wxyz \""),
       "log.attitude.order: expected 'wxyz' or 'xyzw'"},
      {replaced(ros, "order = \"xyzw\"", "direction = \"body\""),
       "log.attitude.direction: expected 'body_to_world' or 'world_to_body'"},
      {replaced(ros, "unit = \"deg/s\"", "unit = \"rpm\""), "log.rates.unit: expected 'rad/s' or 'deg/s'"},
      {replaced(ros, "unit = \"m\"", "unit = \"ft\""), "log.position.unit: expected 'm', got 'ft'"},
      {replaced(replaced(ros, "fields = [\"qx\", \"qy\", \"qz\", \"qw\"]", "fields = [\"r\", \"p\", \"y\"]"),
                "form = \"quaternion\"", "form = \"euler\""),
       "v.toml:22: log.attitude.order: applies to a quaternion"},
      {replaced(ros, "unit = \"1\"", "unit = \"deg\""),
       "log.controls[3].unit: 'deg' is an angle or angular rate, but the channel drives the thrust axis"},
      {replaced(ros, "unit = \"1\"", "unit = \"furlong\""),
       "log.controls[3].unit: expected 'rad' or 'deg' or"},
      {replaced(ros, "max_tilt = 45", "max_tilt = 45\nmax_tilt_rad = 0.5"),
       "envelope.max_tilt: expected either max_tilt (in the attitude unit) or max_tilt_rad, not both"},
      {replaced(ros, "max_tilt = 45", "max_tilt = 90"), "envelope.max_tilt: expected a number in"},
      {replaced(ros, "world_frame = \"ENU\"", "world = \"ENU\""), "log.world: unknown key"},
  };
  for (const auto& c : cases) {
    const std::string m = message(c.text);
    EXPECT_NE(m.find(c.expected), std::string::npos) << "expected '" << c.expected << "' in: " << m;
  }
}

// `pegasus control --vehicle` reads a ROS aircraft's lines in its own terms and answers in its channels.
TEST(VehicleConventions, ControlLinesOfARosAircraftAreReadInItsTerms) {
  const Vehicle v = parse_vehicle(kRosVehicle, "ros.toml");
  const heli::ControlLineFormat f = control_line_format(v);
  EXPECT_EQ(f.state_fields, v.state_fields());
  heli::LoggedState parsed{};
  bool has_time = false;
  double time = 0;
  std::string why;
  ASSERT_TRUE(heli::parse_state_line("0.5,1,2,3,4,5,6,0,0,0.7071067811865476,0.7071067811865476,10,20,30", f,
                                     {}, &parsed, &has_time, &time, &why))
      << why;
  EXPECT_EQ(parsed[0], 2);
  EXPECT_EQ(parsed[2], -3);
  EXPECT_NEAR(parsed[5], 0, 1e-15);
  EXPECT_NEAR(parsed[10], -20 * kDeg, 1e-15);
  // The answer: the yaw-rate set point for a4 = 0.5 (yaw right) is -45 deg/s (FLU's + is yaw left).
  EXPECT_EQ(f.controls_of(heli::Controls{0, 0, 0, 0.5})[2], -45);
}

}  // namespace
}  // namespace pegasus::logs::conventions_test
