// The C export's wrapper of a helicopter class in an aircraft's own terms (a vehicle file): the vehicle's
// fields into the pipeline's 12 states, the class's action into the vehicle's channels.
#include <fmt/format.h>

#include <array>
#include <numbers>
#include <string>
#include <vector>

#include "c_policy_text.hpp"
#include "pegasus/heli/vehicle_file.hpp"

namespace pegasus::codegen::detail {
namespace {

// ---- A helicopter class in an aircraft's own terms (a vehicle file) ------------------------------------

// vehicle/vehicle.cpp Vehicle::state_of and Vehicle::native_of, operation for operation (and
// vehicle/frames.cpp).
constexpr const char* kVehicleCode = R"(
/* ---- In the aircraft's own terms: vehicle file @VEHICLE_FILE@ ("@VEHICLE@") ---- */
static const int kChannelAxis[4] = {@AXES@}; /* the action a1..a4 each channel drives */
@CHANNEL_TABLES@
/* vehicle/vehicle.cpp Vehicle::state_of: the 12 states of the observation above from the vehicle's fields. */
static void vehicle_state(const double* v, double* s) {
  double roll, pitch, yaw;
@ATTITUDE@@POSITION@  s[3] = roll;
  s[4] = pitch;
  s[5] = yaw;
@VELOCITY@@RATES@}

int @NAME@_act_vehicle(@ACT_PARAMETERS@) {
  double own[13], axes[4];
  int c, result;
  own[0] = observation[0];
  vehicle_state(observation + 1, own + 1);
  result = @NAME@_act(@MEMORY_ARGUMENT@own, axes);
  for (c = 0; c < 4; ++c) action[c] = (axes[kChannelAxis[c]] - kChannelOffset[c]) / kChannelScale[c];
  return result;
}
)";

// heli::euler_from_any_quaternion, operation for operation: scaled by the largest component (no overflow of
// the norm), then normalised.
constexpr const char* kQuaternionAttitude = R"(  {
    double w = @QW@, x = @QX@, y = @QY@, z = @QZ@, largest = fabs(w), norm;
    if (fabs(x) > largest) largest = fabs(x);
    if (fabs(y) > largest) largest = fabs(y);
    if (fabs(z) > largest) largest = fabs(z);
    if (!(isfinite(w) && isfinite(x) && isfinite(y) && isfinite(z)) || !(largest > 0)) {
      roll = pitch = yaw = NAN;
    } else {
      w /= largest, x /= largest, y /= largest, z /= largest;
      norm = sqrt(w * w + x * x + y * y + z * z);
      w /= norm, x /= norm, y /= norm, z /= norm;
      roll = atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
      pitch = asin(clamp(2 * (w * y - z * x), -1.0, 1.0));
      yaw = atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
    }
  }
)";

constexpr const char* kBodyVelocity = R"(  {
    const double cf = cos(roll), sf = sin(roll), ct = cos(pitch), st = sin(pitch), cp = cos(yaw), sp = sin(yaw);
    s[6] = ct * cp * @V0@ + (sf * st * cp - cf * sp) * @V1@ + (cf * st * cp + sf * sp) * @V2@;
    s[7] = ct * sp * @V0@ + (sf * st * sp + cf * cp) * @V1@ + (cf * st * sp - sf * cp) * @V2@;
    s[8] = -st * @V0@ + (sf * ct * @V1@ + cf * ct * @V2@); /* Eigen's order for the third row */
  }
)";

constexpr const char* kBodyRates = R"(  {
    const double cf = cos(roll), sf = sin(roll), ct = cos(pitch), tt = tan(pitch);
    const double qr = @R1@ * sf + @R2@ * cf;
    s[9] = @R0@ + qr * tt;
    s[10] = @R1@ * cf - @R2@ * sf;
    s[11] = qr / ct;
  }
)";

// The vehicle's field i of the observation (after its time).
std::string vehicle_field(std::size_t i) { return fmt::format("v[{}]", i); }
std::string negated(const std::string& e) { return "(-" + e + ")"; }

// roll, pitch and yaw in the pipeline's NED/FRD radians from the file's attitude fields: quaternion (in its
// order and direction) or Euler angles (in their unit).
std::string vehicle_attitude_code(const logs::VehicleLogSpec& log) {
  const bool enu = log.world_frame == "ENU", flu = log.body_frame == "FLU";
  std::string attitude;
  if (log.attitude_form == "quaternion") {
    const bool xyzw = log.quaternion_order == "xyzw", conjugate = log.quaternion_direction == "world_to_body";
    std::array<std::string, 4> q;  // w, x, y, z
    for (std::size_t c = 0; c < 4; ++c) q[c] = vehicle_field(6 + (xyzw ? (c + 3) % 4 : c));
    if (conjugate)
      for (std::size_t c = 1; c < 4; ++c) q[c] = "-" + q[c];
    attitude = fill(kQuaternionAttitude, {{"QW", q[0]}, {"QX", q[1]}, {"QY", q[2]}, {"QZ", q[3]}});
  } else if (log.attitude_unit != "rad") {
    const std::string k = c_double(logs::radians_per_attitude_unit(log));
    attitude = fmt::format("  roll = v[6] * {0};\n  pitch = v[7] * {0};\n  yaw = v[8] * {0};\n", k);
  } else {
    attitude = "  roll = v[6];\n  pitch = v[7];\n  yaw = v[8];\n";
  }
  if (enu != flu) attitude += fmt::format("  roll = wrap_angle(roll + {});\n", c_double(std::numbers::pi));
  if (enu)
    attitude +=
        fmt::format("  pitch = -pitch;\n  yaw = wrap_angle({} - yaw);\n", c_double(std::numbers::pi / 2));
  return attitude;
}

// A world vector of fields i, i + 1, i + 2 in the pipeline's NED, into s[to], s[to + 1], s[to + 2].
std::string world_vector_code(std::size_t i, std::size_t to, bool enu) {
  if (!enu)
    return fmt::format("  s[{}] = v[{}];\n  s[{}] = v[{}];\n  s[{}] = v[{}];\n", to, i, to + 1, i + 1, to + 2,
                       i + 2);
  return fmt::format("  s[{}] = v[{}];\n  s[{}] = v[{}];\n  s[{}] = -v[{}];\n", to, i + 1, to + 1, i, to + 2,
                     i + 2);
}

std::string vehicle_velocity_code(const logs::VehicleLogSpec& log) {
  const bool enu = log.world_frame == "ENU", flu = log.body_frame == "FLU";
  if (log.velocity_frame == "body")
    return fill(kBodyVelocity, {{"V0", vehicle_field(3)},
                                {"V1", flu ? negated(vehicle_field(4)) : vehicle_field(4)},
                                {"V2", flu ? negated(vehicle_field(5)) : vehicle_field(5)}});
  return world_vector_code(3, 6, enu);
}

// The rates' fields in rad/s, then in FRD (body rates) or in the NED Euler angles' rates.
std::string vehicle_rates_code(const logs::VehicleLogSpec& log) {
  const bool enu = log.world_frame == "ENU", flu = log.body_frame == "FLU";
  const std::size_t rates = log.attitude_form == "quaternion" ? 10 : 9;
  std::array<std::string, 3> w;
  for (std::size_t c = 0; c < 3; ++c) {
    w[c] = vehicle_field(rates + c);
    if (log.rates_unit != "rad/s")
      w[c] = fmt::format("({} * {})", w[c], c_double(logs::radians_per_rates_unit(log)));
    if (c > 0 && (log.rates_form == "body" ? flu : enu)) w[c] = negated(w[c]);
  }
  return log.rates_form == "body"
             ? fill(kBodyRates, {{"R0", w[0]}, {"R1", w[1]}, {"R2", w[2]}})
             : fmt::format("  s[9] = {};\n  s[10] = {};\n  s[11] = {};\n", w[0], w[1], w[2]);
}

// The header's declaration of PREFIX_act_vehicle, and its columns' names into `names`.
void declare_act_vehicle(ClassText& t, const logs::Vehicle& vehicle, const std::string& vehicle_file,
                         const std::vector<std::string>& labels, CPolicyCode* names) {
  names->vehicle_observation_names = {"time"};
  for (const auto& f : vehicle.state_fields()) names->vehicle_observation_names.push_back(f);
  names->vehicle_action_names = labels;
  std::string observation, action;
  for (const auto& n : names->vehicle_observation_names)
    observation += (observation.empty() ? "" : ", ") + comment_text(n);
  for (const auto& n : labels) action += (action.empty() ? "" : ", ") + comment_text(n);
  t.extra_declarations += fmt::format(
      "\n/* The controller in the terms of the aircraft \"{}\" (vehicle file {}): observation ({} doubles) "
      "{};\n"
      " * action (4 doubles) its channels {}, in its ranges and signs. As `pegasus control --vehicle` "
      "converts a\n"
      " * line: quaternion or Euler attitude, body or world velocity, body or Euler rates, in the frames, "
      "order\n * and units the file says.\n"
      " * Returns what @NAME@_act returns (1 and the trim in the channels' terms for a non-finite value). "
      "*/\n"
      "#define @MACRO@_VEHICLE_OBSERVATION_SIZE {}\n"
      "int @NAME@_act_vehicle({});\n",
      comment_text(vehicle.name()), vehicle_file, names->vehicle_observation_names.size(), observation,
      action, names->vehicle_observation_names.size(), act_parameters(t));
}

}  // namespace

void add_vehicle(ClassText& t, const logs::Vehicle& vehicle, CPolicyCode* names) {
  const logs::VehicleLogSpec& log = vehicle.log;
  std::vector<double> scale, offset;
  std::vector<std::string> labels;
  std::string axes;
  for (std::size_t c = 0; c < 4; ++c) {
    scale.push_back(log.controls[c].scale);
    offset.push_back(log.controls[c].offset);
    labels.push_back(log.controls[c].label());
    axes += fmt::format("{}{}", c ? ", " : "", log.controls[c].column(c));
  }
  // The log's conventions (vehicle/vehicle.cpp: the ENU/FLU, quaternion order and direction, and unit steps
  // of Vehicle::state_of), each written only where the file leaves the pipeline's own: the C of a vehicle in
  // the pipeline's conventions is what it always was.
  const std::string vehicle_file = comment_text(log.file.empty() ? std::string("(built in)") : log.file);
  t.body += fill(kVehicleCode, {{"VEHICLE_FILE", vehicle_file},
                                {"VEHICLE", comment_text(vehicle.name())},
                                {"AXES", axes},
                                {"CHANNEL_TABLES", c_table("kChannelScale", scale, labels) +
                                                       c_table("kChannelOffset", offset, labels)},
                                {"ATTITUDE", vehicle_attitude_code(log)},
                                {"POSITION", world_vector_code(0, 0, log.world_frame == "ENU")},
                                {"VELOCITY", vehicle_velocity_code(log)},
                                {"RATES", vehicle_rates_code(log)},
                                {"ACT_PARAMETERS", act_parameters(t)},
                                {"MEMORY_ARGUMENT", t.has_memory ? "memory, " : ""}});
  declare_act_vehicle(t, vehicle, vehicle_file, labels, names);
}

}  // namespace pegasus::codegen::detail
