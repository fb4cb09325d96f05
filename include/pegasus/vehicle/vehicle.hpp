#pragma once
// Vehicle files: everything the helicopter pipeline used to assume about the one airframe it was written
// around, said in one TOML file per aircraft (issue 15), so that `pegasus identify`, `hover`, `fly` and
// `control` work on any rigid aircraft with four control axes. The README's "Vehicle files" documents every
// key; experiments/vehicles/ ships the X-Cell 60 (the `heli` commands' default) and a PX4 quadrotor.
//
// The pipeline's own layout (vehicle/flight_log.hpp) stays one: 12 states (world NED position and velocity,
// Z-Y-X Euler angles, Euler-angle rates) and four controls a1..a4 in [-1, 1], one per axis:
//   a1 pitch   +: nose down, accelerate forward (a helicopter's longitudinal cyclic)
//   a2 roll    +: roll right (lateral cyclic)
//   a3 thrust  +: more thrust along -z_B, climb (main collective)
//   a4 yaw     +: yaw right, clockwise seen from above (tail collective)
// A vehicle file maps its aircraft onto it: how its logs give attitude (Euler or quaternion), velocity
// (world or body) and rates (Euler-angle or body), at which rates; each control channel's name, order,
// range and sign and the axis it drives; whether the X-Cell's flapping and gyro states are modelled; the
// hover task's set point and starting gains; the tilt that counts as a crash.
//
// This header is the vehicle layer's: the typed description and its conventions, which every layer above
// reads (heli/, sysid/, the commands). Reading a file into it, with the checks that need the pipeline's
// registries, is heli/vehicle_file.hpp's.
#include <array>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pegasus/vehicle/disturbance.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "pegasus/vehicle/state.hpp"

namespace pegasus::logs {

// Fields of one topic that make one vector quantity. A CSV log has no topics: the fields are its columns.
struct TopicFields {
  std::string topic;
  std::vector<std::string> fields;
};

using heli::kControlAxisNames;

// The units a control channel may say: angles, angular rates, speed, force, fraction, servo pulse.
inline constexpr std::array<const char*, 9> kChannelUnits = {"rad", "deg", "rad/s", "deg/s", "m/s",
                                                             "N",   "1",   "%",     "us"};

// One control channel of the aircraft: the axis it drives is a_axis = scale * value + offset, in [-1, 1].
struct ControlChannel {
  std::string topic;  // ULog topic; empty for a CSV log
  std::string field;  // ULog field, or the CSV column
  double scale = 1;   // never 0
  double offset = 0;
  int axis = -1;       // 0..3 for a1..a4; -1: the channel's position in the list (files without `axis` keys)
  std::string name{};  // the aircraft's name for it (`pegasus control`'s output header); empty: the field
  // The unit of the channel's values (in its logs and in `pegasus control`'s answer) and of its range or
  // offset: "" (none said) or one of kChannelUnits. A channel maps linearly onto its axis, so the unit
  // changes no number: it documents the range, and an angle or angular-rate unit is refused on the thrust
  // axis (a set point of attitude or rate drives pitch, roll or yaw).
  std::string unit{};

  int column(std::size_t position) const { return axis >= 0 ? axis : static_cast<int>(position); }
  const std::string& label() const { return name.empty() ? field : name; }
};

// The [log] section of a vehicle file.
struct VehicleLogSpec {
  std::string vehicle;        // [vehicle] name
  std::string file;           // the vehicle file, for messages
  double rate_hz = 50;        // the flight log's constant rate
  double model_rate_hz = 10;  // the identification rate; must divide rate_hz
  int instance = 0;           // multi_id of every topic
  double max_gap_s = 0.5;     // a longer gap between records of a topic inside the range is an error
  std::string time = "time";  // a CSV log's time column, s
  // How the log gives each quantity.
  std::string attitude_form = "quaternion";  // "quaternion" (see quaternion_order, _direction) or "euler"
  std::string velocity_frame = "world";      // "world" (world_frame) or "body" (body_frame)
  std::string rates_form = "body";           // "body" (p, q, r) or "euler" (roll, pitch, yaw rates)
  // The log's conventions (issue 53); each default is the pipeline's own, and under the defaults a value
  // goes through no arithmetic at all (logs in the pipeline's conventions read bit for bit as before).
  std::string world_frame = "NED";  // [log] world_frame: "NED" (x north, y east, z down) or "ENU" (x east,
                                    // y north, z up: ROS REP 103)
  std::string body_frame = "FRD";   // [log] body_frame: "FRD" (x forward, y right, z down) or "FLU" (x
                                    // forward, y left, z up: REP 103)
  // [log.attitude] order: a quaternion's components "wxyz" or "xyzw" (ROS, Eigen's coeffs()); direction:
  // "body_to_world" (it rotates body vectors into the world frame) or "world_to_body".
  std::string quaternion_order = "wxyz";
  std::string quaternion_direction = "body_to_world";
  // [log.attitude] unit: the aircraft's angles in "rad" or "deg": its Euler angles (form = "euler"), and in
  // any form the [hover] target's yaw and the [envelope] max_tilt.
  std::string attitude_unit = "rad";
  std::string rates_unit = "rad/s";  // [log.rates] unit: "rad/s" or "deg/s"
  TopicFields position, velocity, attitude, rates;
  // The aircraft's control channels in its own order; each axis driven by exactly one.
  std::array<ControlChannel, 4> controls;
  // Names of the topics used (each once), for UlogReadOptions::topics.
  std::vector<std::string> topic_names() const;
  // Whether every convention is the pipeline's own (NED, FRD, w x y z body to world, rad, rad/s).
  bool pipeline_conventions() const;
};

// The one place where a log's conventions become the pipeline's and back (monogram names of
// vehicle/frames.hpp: W is the pipeline's world NED, B its body FRD; "native" is the log's own frame, order,
// direction and unit). Each is the identity, without arithmetic, under the default conventions.
//   world vectors:  ENU (e, n, u) <-> NED (n, e, -u)
//   body vectors:   FLU (f, l, u) <-> FRD (f, -l, -u)
//   Z-Y-X Euler angles of the body-to-world rotation R' = R_z(yaw') R_y(pitch') R_x(roll') in the log's
//   frames, R_WB = R_W,world' R' R_body',B: with an ENU world, pitch = -pitch' and yaw = pi/2 - yaw'; with
//   exactly one of world ENU and body FLU, roll = roll' + pi (wrapped to (-pi, pi]); otherwise unchanged.
//   (R_NED,ENU = R_z(pi/2) R_x(pi), R_FLU,FRD = R_x(pi), and R_x(pi) R_z(a) R_y(b) R_x(c) R_x(pi) =
//   R_z(-a) R_y(-b) R_x(c).) Euler-angle rates follow by differentiation; body rates are body vectors.
heli::Vec3 world_vector_of(const VehicleLogSpec& spec, const heli::Vec3& native);
heli::Vec3 native_world_vector(const VehicleLogSpec& spec, const heli::Vec3& v_W);
heli::Vec3 body_vector_of(const VehicleLogSpec& spec, const heli::Vec3& native);
heli::Vec3 native_body_vector(const VehicleLogSpec& spec, const heli::Vec3& v_B);
// Euler angles (rad) in the log's frames to the pipeline's, and back.
heli::Euler euler_of(const VehicleLogSpec& spec, const heli::Euler& native_rad);
heli::Euler native_euler(const VehicleLogSpec& spec, const heli::Euler& e);
// Euler-angle rates (rad/s) in the log's frames to the pipeline's, and back.
heli::Vec3 euler_rates_of(const VehicleLogSpec& spec, const heli::Vec3& native_rad_s);
heli::Vec3 native_euler_rates(const VehicleLogSpec& spec, const heli::Vec3& rates);
// A log's quaternion (4 values in its order and direction, any length) as the Euler angles (rad) of its
// body-to-world rotation in the log's own frames; NaN when it has no direction.
heli::Euler native_euler_of_quaternion(const VehicleLogSpec& spec, const double* q);
// The log's quaternion (its order and direction, unit length, scalar part >= 0) of Euler angles (rad) in
// its own frames.
std::array<double, 4> native_quaternion(const VehicleLogSpec& spec, const heli::Euler& native_rad);
// Radians per unit of the log's Euler angles ([log.attitude] unit) and of its rates ([log.rates] unit).
double radians_per_attitude_unit(const VehicleLogSpec& spec);
double radians_per_rates_unit(const VehicleLogSpec& spec);

// [cost]: the cost the aircraft's controller is judged by, per control step, in the file's own frames and
// units (docs/reference/vehicle-file.md has the mapping with a worked example). When a file states it, it is
// the hover reward, whole: judged_reward() maps it exactly, and no default term stays.
struct JudgedCost {
  std::array<double, 3> position{0, 0, 0};  // per m^2 of the set-point error, the file's world axes
  std::array<double, 3> velocity{0, 0, 0};  // per (m/s)^2 of the world velocity, the file's world axes
  // "none", "euler" (roll and pitch about level and the yaw error, per (attitude unit)^2) or "quaternion"
  // (x, y, z of the vector part of the rotation from the set point's attitude, level at its yaw, to the
  // body's, in the file's body axes, per unit^2).
  std::string attitude = "none";
  std::array<double, 3> attitude_weights{0, 0, 0};
  std::array<double, 3> body_rates{0, 0, 0};         // per (rates unit)^2, the file's body axes
  std::array<double, 4> controls{0, 0, 0, 0};        // per (channel unit)^2, the aircraft's channel order
  bool controls_about_trim = true;                   // about the logs' mean controls, or about controls_about
  std::array<double, 4> controls_about{0, 0, 0, 0};  // the channels' own values, the aircraft's order
  double crash = 50000;                              // one crash's cost
};

// A whole vehicle file.
struct Vehicle {
  VehicleLogSpec log;  // log.vehicle is the name, log.file the file ("" for the built-in X-Cell)
  // [vehicle] latent_states: "xcell" models the X-Cell's flapping and yaw-gyro states (GMF01); "none" (the
  // default) models none, as for any aircraft without them.
  bool xcell_latent_states = false;
  // [model] templates: "kinematic" (the default) fixes the coefficients of thesis §5.2.2: attitude steps by
  // rate x dt, and acts on the velocities through gravity only and on the rates not at all, which holds for
  // an aircraft whose controls move its rotor or surfaces (the X-Cell); "none" regresses every coefficient,
  // for an aircraft whose controls are attitude set points that an onboard controller follows within a model
  // step (a quadrotor's), where attitude acts on the rates and rate x dt is not the step's attitude change.
  bool kinematic_templates = true;
  // [vehicle] simulator: the project's ground truth that `pegasus pilot` and `pegasus fly` fly it on
  // ("xcell", "crazyflie2": heli/simulators.hpp), or "none".
  std::string simulator = "none";
  // [control] rate_hz: the flight computer's controller rate; training steps the learned model at it.
  double control_rate_hz = 50;
  // [hover] target: set point x, y, z (m, NED) and yaw (rad) in the pipeline's terms; the file writes them
  // in the log's world frame and attitude unit. starting_gains: "lqr" (from the identified model, the
  // default) or "constant" (the X-Cell's tuned constants).
  std::array<double, 4> target{0, 0, -10, 0};
  std::string starting_gains = "lqr";
  // [hover] integral_seconds: the hover class's integral term (heli/hover_policy.hpp), its int weights
  // starting at each error gain / this; 0: none (the X-Cell's, as in the thesis). On by default: without it
  // every learned controller holds a steady offset in a steady wind.
  double integral_seconds = 5;
  // [hover.reward]: the typical sizes the hover reward's weights stand for (alpha = 1 / typical^2; `hover
  // --reward.*`), set to match the cost the aircraft is judged by. Only the keys the file gives.
  std::vector<std::pair<std::string, double>> reward;
  // [envelope] max_tilt_rad (rad), or max_tilt (in the log's attitude unit): |roll| or |pitch| of the
  // pipeline's attitude beyond this crashes the learned model.
  double max_tilt_rad = 1.0;
  // The rest of [envelope] (each off unless said): max_position_error (m, the distance from the set point),
  // max_speed (m/s), max_rate (any Euler-angle rate, in the file's rates unit); here in m, m/s, rad/s.
  double max_position_error_m = std::numeric_limits<double>::infinity();
  double max_speed_mps = std::numeric_limits<double>::infinity();
  double max_rate_radps = std::numeric_limits<double>::infinity();
  std::optional<JudgedCost> cost;  // [cost]
  // [hover.wind]: the wind in the hover scenarios (sysid::Disturbance): steady = [x, y, z] in the file's
  // world frame (m/s), sigma, gust_sigma (m/s) and gust_tau_s (s); here in NED. nullopt without the section
  // (hover then trains in heli::default_training_wind); a section's keys left out are calm.
  std::optional<sysid::Disturbance> wind;

  const std::string& name() const { return log.vehicle; }
  // The log's channels in the aircraft's order: axis values a1..a4 of native values, and back.
  heli::Controls axes_of(std::span<const double> native) const;
  std::array<double, 4> native_of(const heli::Controls& axes) const;
  // Field names of a state line in the aircraft's terms, in the order `pegasus control` reads a line
  // without a header: position, velocity, attitude (3 or 4), rates.
  std::vector<std::string> state_fields() const;
  // The pipeline's 12 states from values in state_fields() order, in the log's conventions and units.
  heli::LoggedState state_of(std::span<const double> native) const;
  // And back: the values in state_fields() order (12 or 13) of the pipeline's 12 states.
  std::vector<double> native_state(const heli::LoggedState& s) const;
};

}  // namespace pegasus::logs
