// The helicopter of thesis chapter 5 from Python: the ground-truth aircraft (heli/aircraft.hpp) and the
// identified model (sysid/learned_model.hpp) as batch models over numpy rows. The hover task (§5.3) and its
// U-hat are in heli_hover.cpp, policy files in heli_policy.cpp.
#include <fmt/format.h>

#include <cmath>
#include <functional>
#include <memory>

#include "builtin_problem.hpp"
#include "heli_batch.hpp"
#include "heli_hover.hpp"
#include "heli_policy.hpp"
#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/hover_policy.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/quadrotor.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/sysid/learned_model.hpp"

namespace pegasus::python {

std::shared_ptr<const sysid::IdentifiedModel> identified_model(IdentifiedModelArg model) {
  if (py::isinstance<py::str>(model))
    return std::make_shared<const sysid::IdentifiedModel>(
        sysid::IdentifiedModel::load(model.cast<std::string>()));
  constexpr const char* kExpected = "model: expected a pegasus.IdentifiedModel or the path of a model.json";
  // None casts to an empty pointer, which every caller would dereference.
  if (model.is_none()) throw py::value_error(kExpected);
  try {
    return model.cast<std::shared_ptr<sysid::IdentifiedModel>>();
  } catch (const py::cast_error&) {
    throw py::value_error(kExpected);
  }
}

namespace {

using heli::Aircraft;
using heli::AircraftParams;
using heli::AircraftState;
using heli::Controls;
using heli::HoverPolicy;
using heli::HoverReward;
using heli::LoggedState;
using heli::SetPoint;
using sysid::LearnedHeliModel;
using sysid::LearnedModelOptions;

// ---- State rows ------------------------------------------------------------------------------------------

// The ground truth's state as a row of 36 numbers (every field of AircraftState, frames as there).
constexpr py::ssize_t kAircraftColumns = 36;
std::vector<std::string> aircraft_columns() {
  std::vector<std::string> c = {"p_W.x",    "p_W.y",    "p_W.z",     "v_B.x",    "v_B.y",    "v_B.z",
                                "roll",     "pitch",    "yaw",       "w_B.x",    "w_B.y",    "w_B.z",
                                "flap_lon", "flap_lat", "gyro_rate", "servo.a1", "servo.a2", "servo.a3",
                                "servo.a4", "gust_W.x", "gust_W.y",  "gust_W.z"};
  for (const char* n : heli::kLoggedStateNames) c.push_back(std::string("estimate_error.") + n);
  c.push_back("time");
  c.push_back("crash");
  return c;
}

void write_row(const AircraftState& s, double* x) {
  for (int i = 0; i < 3; ++i)
    x[i] = s.p_W[i], x[3 + i] = s.v_B[i], x[9 + i] = s.w_B[i], x[19 + i] = s.gust_W[i];
  x[6] = s.attitude.roll, x[7] = s.attitude.pitch, x[8] = s.attitude.yaw;
  x[12] = s.flap_lon, x[13] = s.flap_lat, x[14] = s.gyro_rate;
  for (int i = 0; i < 4; ++i) x[15 + i] = s.servo[static_cast<std::size_t>(i)];
  for (int i = 0; i < kLogged; ++i) x[22 + i] = s.estimate_error[static_cast<std::size_t>(i)];
  x[34] = s.time;
  x[35] = static_cast<double>(static_cast<int>(s.crash));
}

AircraftState aircraft_row(const double* x, py::ssize_t row, const char* name) {
  AircraftState s;
  for (int i = 0; i < 3; ++i)
    s.p_W[i] = x[i], s.v_B[i] = x[3 + i], s.w_B[i] = x[9 + i], s.gust_W[i] = x[19 + i];
  s.attitude = {x[6], x[7], x[8]};
  s.flap_lon = x[12], s.flap_lat = x[13], s.gyro_rate = x[14];
  for (int i = 0; i < 4; ++i) s.servo[static_cast<std::size_t>(i)] = x[15 + i];
  for (int i = 0; i < kLogged; ++i) s.estimate_error[static_cast<std::size_t>(i)] = x[22 + i];
  s.time = x[34];
  const double crash = x[35];
  if (!(crash >= 0 && crash <= static_cast<int>(heli::CrashReason::kModelSupport) &&
        crash == std::floor(crash)))
    throw py::value_error(
        fmt::format("{}: expected a crash code in 0..{} in column 35 (crash), got {} at row {}", name,
                    static_cast<int>(heli::CrashReason::kModelSupport), crash, row));
  s.crash = static_cast<heli::CrashReason>(static_cast<int>(crash));
  return s;
}

// The identified model's state as a row of 161 numbers: the 12 world-frame logged states, the three extra
// states, the held regression coefficients (8 x 16), the predictive variance (8), the AR part of the noise
// (8), the step count and the crash flag.
constexpr py::ssize_t kLearnedColumns =
    kLogged + 3 + sysid::kBodyVars * sysid::kInputs + 2 * sysid::kBodyVars + 2;
std::vector<std::string> learned_columns() {
  std::vector<std::string> c(heli::kLoggedStateNames.begin(), heli::kLoggedStateNames.end());
  c.insert(c.end(), {"flap_lon", "flap_lat", "gyro"});
  for (const char* v : sysid::kBodyVarNames)
    for (const char* i : sysid::kInputNames) c.push_back(fmt::format("beta.{}.{}", v, i));
  for (const char* v : sysid::kBodyVarNames) c.push_back(fmt::format("variance.{}", v));
  for (const char* v : sysid::kBodyVarNames) c.push_back(fmt::format("colored.{}", v));
  c.push_back("step");
  c.push_back("crashed");
  return c;
}

void write_row(const LearnedHeliModel::State& s, double* x) {
  std::copy(s.sim.world.begin(), s.sim.world.end(), x);
  x += kLogged;
  *x++ = s.sim.flap_lon, *x++ = s.sim.flap_lat, *x++ = s.sim.gyro;
  for (const auto& b : s.beta)
    for (int i = 0; i < sysid::kInputs; ++i) *x++ = b[i];
  for (int v = 0; v < sysid::kBodyVars; ++v) *x++ = s.variance[v];
  for (int v = 0; v < sysid::kBodyVars; ++v) *x++ = s.colored[v];
  *x++ = s.step;
  *x = s.crashed ? 1.0 : 0.0;
}

LearnedHeliModel::State learned_row(const double* x, py::ssize_t row, const char* name) {
  LearnedHeliModel::State s;
  std::copy(x, x + kLogged, s.sim.world.begin());
  const double* y = x + kLogged;
  s.sim.flap_lon = *y++, s.sim.flap_lat = *y++, s.sim.gyro = *y++;
  for (auto& b : s.beta)
    for (int i = 0; i < sysid::kInputs; ++i) b[i] = *y++;
  for (int v = 0; v < sysid::kBodyVars; ++v) s.variance[v] = *y++;
  for (int v = 0; v < sysid::kBodyVars; ++v) s.colored[v] = *y++;
  const double step = *y++, crashed = *y;
  if (!(step >= 0 && step < 2e9 && step == std::floor(step)))
    throw py::value_error(fmt::format("{}: expected a step count >= 0 in column {} (step), got {} at row {}",
                                      name, kLearnedColumns - 2, step, row));
  if (crashed != 0.0 && crashed != 1.0)
    throw py::value_error(fmt::format("{}: expected 0 or 1 in column {} (crashed), got {} at row {}", name,
                                      kLearnedColumns - 1, crashed, row));
  s.step = static_cast<int>(step);
  s.crashed = crashed == 1.0;
  return s;
}

}  // namespace

// The helicopter's two batch models' rows (heli_batch.hpp).
template <>
struct StateRows<Aircraft> {
  static constexpr py::ssize_t kColumns = kAircraftColumns;
  static void write(const AircraftState& s, double* x) { write_row(s, x); }
  static AircraftState read(const double* x, py::ssize_t r, const char* name) {
    return aircraft_row(x, r, name);
  }
};
template <>
struct StateRows<LearnedHeliModel> {
  static constexpr py::ssize_t kColumns = kLearnedColumns;
  static void write(const LearnedHeliModel::State& s, double* x) { write_row(s, x); }
  static LearnedHeliModel::State read(const double* x, py::ssize_t r, const char* name) {
    return learned_row(x, r, name);
  }
};

namespace {

SetPoint set_point(double x, double y, double z, double yaw) {
  for (const auto& [v, name] : {std::pair{x, "x"}, {y, "y"}, {z, "z"}, {yaw, "yaw"}})
    if (!std::isfinite(v))
      throw py::value_error(fmt::format("{}: expected a finite number, got {}", name, v));
  return {x, y, z, yaw};
}

// Binds each field HoverReward::VisitFields lists, with its one line as the docstring.
struct RewardBinder {
  py::class_<HoverReward>& c;
  void bind(const char* name, double HoverReward::*field, const char* doc) {
    c.def_readwrite(name, field, doc);
  }
  template <std::size_t N>
  void bind(const char* name, std::array<double, N> HoverReward::*field, const char* doc) {
    def_array(c, name, field, doc);
  }
  template <class T>
  void size(const heli::HoverRewardSize& s, T HoverReward::*field, const char* doc) {
    bind(s.field, field, doc);
  }
  template <class T>
  void weight(const char* name, T HoverReward::*field, const char* doc) {
    bind(name, field, doc);
  }
  template <class T>
  void field(const char* name, T HoverReward::*field, const char* doc) {
    bind(name, field, doc);
  }
};

// fly_pilot's doc, naming the registered ground truths (heli/simulators.hpp) as the CLI's help does.
const std::string& fly_pilot_doc() {
  static const std::string doc = fmt::format(
      R"doc(The scripted pilot flies a registered ground truth (simulator: one of {}) as `pegasus pilot --vehicle`
does: a hover, then a frequency sweep in each channel. Returns a dict: "log" (FlightLog of the state estimates and
controls at 50 Hz), "truth" (the true states, rows x 12), "crash" ('none' or why) and "crash_time" (s, -1 without a
crash). gust_sigma < 0 keeps the aircraft's own.)doc",
      heli::ground_truth_list());
  return doc;
}

}  // namespace

void bind_heli(py::module_& m) {
  auto sp = py::class_<SetPoint>(m, "SetPoint",
                                 "Where the helicopter should be: x, y, z in the world frame (NED, m; "
                                 "z < 0 is above the ground) and the heading yaw (rad).");
  sp.def(py::init(&set_point), py::arg("x") = 0.0, py::arg("y") = 0.0, py::arg("z") = -10.0,
         py::arg("yaw") = 0.0)
      .def_readwrite("x", &SetPoint::x, "North, m (world frame, NED).")
      .def_readwrite("y", &SetPoint::y, "East, m (world frame, NED).")
      .def_readwrite("z", &SetPoint::z, "Down, m (z < 0 is above the ground).")
      .def_readwrite("yaw", &SetPoint::yaw, "Heading, rad.");
  set_fields(sp, {"x", "y", "z", "yaw"});

  auto reward = py::class_<HoverReward>(m, "HoverReward", R"doc(
The hover reward of thesis §5.3 (Eqs 5.9-5.10): minus the weighted squared position, velocity and wrapped yaw
errors, minus the weighted squared controls about `centre` (heli/hover_task.hpp).)doc");
  reward.def(py::init<>());
  RewardBinder binder{reward};
  HoverReward::VisitFields(binder);
  reward
      .def_static(
          "from_typical",
          [](double position_m, double velocity_mps, double yaw_rad, double action, ArrayLikeArg centre) {
            const Array c = as_vector(centre, "centre", 4);
            require_finite(c, "centre");
            return HoverReward::from_typical(position_m, velocity_mps, yaw_rad, action,
                                             controls_row(c.data()));
          },
          py::arg("position_m"), py::arg("velocity_mps"), py::arg("yaw_rad"), py::arg("action"),
          py::arg("centre") = std::vector<double>{0, 0, 0, 0}, "alpha = 1 / typical^2 for each term.")
      .def("is_valid", is_valid_method<HoverReward>(), kIsValidDoc);
  set_fields(reward, HoverReward::field_names());

  auto init = py::class_<heli::HoverPolicyInit>(m, "HoverPolicyInit", R"doc(
The hover policy class's starting weights: a linear controller around a trim (heli/hover_policy.hpp).)doc");
  init.def(py::init<>());
  def_array(init, "trim", &heli::HoverPolicyInit::trim, "Controls that hold a hover.");
  init.def_readwrite(
          "trim_roll", &heli::HoverPolicyInit::trim_roll,
          "Roll at that hover, rad: a2.bias starts at trim[1] - k_roll * trim_roll (within [-1, 1]), "
          "so the roll term acts about it.")
      .def_readwrite(
          "trim_pitch", &heli::HoverPolicyInit::trim_pitch,
          "Pitch at that hover, rad: a1.bias starts at trim[0] - k_att * trim_pitch (within [-1, 1]), "
          "so the pitch term acts about it.")
      .def_readwrite("k_pos", &heli::HoverPolicyInit::k_pos,
                     "a1.err: longitudinal cyclic per m of x_B error (position minus set point, rotated into "
                     "the body frame B, forward-right-down).")
      .def_readwrite("k_vel", &heli::HoverPolicyInit::k_vel,
                     "a1.vel: longitudinal cyclic per m/s of xdot_B (forward velocity in B).")
      .def_readwrite("k_att", &heli::HoverPolicyInit::k_att, "a1.att: longitudinal cyclic per rad of pitch.")
      .def_readwrite("k_pos_lat", &heli::HoverPolicyInit::k_pos_lat,
                     "a2.err: lateral cyclic per m of y_B error (right of the set point in B).")
      .def_readwrite("k_vel_lat", &heli::HoverPolicyInit::k_vel_lat,
                     "a2.vel: lateral cyclic per m/s of ydot_B (rightward velocity in B).")
      .def_readwrite("k_roll", &heli::HoverPolicyInit::k_roll, "a2.att: lateral cyclic per rad of roll.")
      .def_readwrite("k_alt", &heli::HoverPolicyInit::k_alt,
                     "a3.err: main collective per m of z_B error (z down: below the set point gives more "
                     "collective).")
      .def_readwrite("k_climb", &heli::HoverPolicyInit::k_climb,
                     "a3.vel: main collective per m/s of zdot_B (downward velocity in B).")
      .def_readwrite("k_yaw", &heli::HoverPolicyInit::k_yaw,
                     "a4.err: tail collective per rad of yaw error, wrap(yaw - yaw*) in (-pi, pi].")
      .def_readwrite("k_yaw_rate", &heli::HoverPolicyInit::k_yaw_rate,
                     "a4.vel: tail collective per rad/s of yaw rate.")
      .def_readwrite("integral_seconds", &heli::HoverPolicyInit::integral_seconds,
                     "The integral term's time constant T_i, s: each channel's int weight starts at its err "
                     "gain / T_i (the PI rule); 0: no integral term (34 weights, the thesis's class).");
  def_array(init, "command_lower", &heli::HoverPolicyInit::command_lower,
            "Each output's lower command limit, after the clip to [-1, 1] (-1: none).");
  def_array(init, "command_upper", &heli::HoverPolicyInit::command_upper,
            "Each output's upper command limit, after the clip to [-1, 1] (1: none).");
  set_fields(init, {"trim", "trim_roll", "trim_pitch", "k_pos", "k_vel", "k_att", "k_pos_lat", "k_vel_lat",
                    "k_roll", "k_alt", "k_climb", "k_yaw", "k_yaw_rate", "integral_seconds", "command_lower",
                    "command_upper"});

  py::class_<HoverPolicy>(m, "HoverPolicy", R"doc(
The hover policy class of thesis §5.3 (Fig 5.4, Eqs 5.7-5.8): 34 weights, one tanh network per control channel
fed by the body-frame errors, velocities and attitude.)doc")
      .def(py::init<const heli::HoverPolicyInit&>(),
           py::arg_v("init", heli::HoverPolicyInit{}, "HoverPolicyInit()"))
      .def_property_readonly("parameters", &HoverPolicy::parameters, py::return_value_policy::copy,
                             "The ParameterSpec of the weights: 34, \"a1.bias\" .. \"a4.out_linear\", then "
                             "\"a1.int\" .. \"a4.int\" with the integral term (38).")
      .def(
          "act",
          [](const HoverPolicy& policy, ArrayLikeArg theta, ArrayLikeArg states, const SetPoint& target) {
            const Theta w = as_theta(theta, "theta", policy.parameters());
            const Array s = as_matrix(states, "states", -1, kLogged);
            require_finite(s, "states");
            Array out = matrix(s.shape(0), 4);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              heli::HeliObservation o;
              std::copy(s.data() + r * kLogged, s.data() + (r + 1) * kLogged, o.state.begin());
              o.target = target;
              const Controls u = policy.act(w, o);
              std::copy(u.begin(), u.end(), out.mutable_data() + r * 4);
            }
            return out;
          },
          py::arg("theta"), py::arg("states"), py::arg_v("target", SetPoint{}, "SetPoint()"),
          "The clipped controls [n, 4] of theta for logged states [n, 12] steering to target.");

  auto params = py::class_<AircraftParams>(m, "AircraftParams", R"doc(
The ground-truth helicopter's parameters (heli/aircraft.hpp: the X-Cell 60 of Gavrilets, Mettler and Feron, rotor,
servos, disturbances, crash limits, integration, start), every field with the C++ name and unit.)doc");
  params.def(py::init<>());
  std::vector<const char*> own;  // the fields this aircraft alone has, in order
  // Published values are Gavrilets, Mettler and Feron's (AIAA 2001-4333), as heli/aircraft.hpp cites them.
#define PEGASUS_PARAM(field, doc) \
  (params.def_readwrite(#field, &AircraftParams::field, doc), own.push_back(#field))
  PEGASUS_PARAM(mass_kg, "Mass, kg (Gavrilets et al.: 8.2).");
  PEGASUS_PARAM(ixx, "Moment of inertia about the body x axis (forward), kg m^2 (Gavrilets et al.: 0.18).");
  PEGASUS_PARAM(iyy, "Moment of inertia about the body y axis (right), kg m^2 (Gavrilets et al.: 0.34).");
  PEGASUS_PARAM(izz, "Moment of inertia about the body z axis (down), kg m^2 (Gavrilets et al.: 0.28).");
  PEGASUS_PARAM(gravity, "Gravitational acceleration, m/s^2 (along +z, down, in the NED world frame).");
  PEGASUS_PARAM(air_density, "Air density, kg/m^3 (1.204: sea level at 20 C).");
  PEGASUS_PARAM(omega_mr, "Nominal main-rotor speed, rad/s (Gavrilets et al.: 167, about 1600 rpm).");
  PEGASUS_PARAM(radius_mr, "Main-rotor radius R_mr, m (Gavrilets et al.: 0.775).");
  PEGASUS_PARAM(chord_mr, "Main-rotor blade chord c_mr, m (Gavrilets et al.: 0.058; two blades).");
  PEGASUS_PARAM(lift_slope_mr, "Main-rotor blade lift-curve slope a_mr, 1/rad (Gavrilets et al.: 5.5).");
  PEGASUS_PARAM(profile_drag_mr,
                "Main-rotor blade profile drag coefficient C_D0, dimensionless (Gavrilets et al.: 0.024).");
  PEGASUS_PARAM(hub_height,
                "Main-rotor hub height h_mr above the centre of mass, m (Gavrilets et al.: 0.235).");
  PEGASUS_PARAM(hub_stiffness,
                "Effective hub torsional stiffness K_beta: hub moment per rad of flapping, N m/rad "
                "(Gavrilets et al.: 54).");
  PEGASUS_PARAM(tau_flap,
                "Time constant tau_e of the rotor with its stabilizer bar: the flapping's first-order lag, s "
                "(Gavrilets et al.: 0.1).");
  PEGASUS_PARAM(a_lon,
                "Steady longitudinal flapping per rad of longitudinal cyclic pitch A_lon, rad/rad (Gavrilets "
                "et al.: 4.2).");
  PEGASUS_PARAM(b_lat,
                "Steady lateral flapping per rad of lateral cyclic pitch B_lat, rad/rad (Gavrilets et al.: "
                "4.2).");
  PEGASUS_PARAM(cyclic_max_rad,
                "Cyclic blade pitch at full stick (a1 or a2 = +-1), rad (chosen: with A_lon 4.2, 0.21 rad of "
                "steady flapping).");
  PEGASUS_PARAM(collective_mid_rad, "Main collective pitch at a3 = 0, rad (chosen; hover needs about 0.1).");
  PEGASUS_PARAM(collective_span_rad,
                "Main collective pitch change from a3 = 0 to a3 = +-1, rad (pitch = mid + span * a3).");
  PEGASUS_PARAM(gear_tr, "Tail-rotor to main-rotor speed ratio n_tr (Gavrilets et al.: 4.66).");
  PEGASUS_PARAM(radius_tr, "Tail-rotor radius R_tr, m (Gavrilets et al.: 0.13).");
  PEGASUS_PARAM(chord_tr, "Tail-rotor blade chord c_tr, m (Gavrilets et al.: 0.029).");
  PEGASUS_PARAM(lift_slope_tr, "Tail-rotor blade lift-curve slope a_tr, 1/rad (Gavrilets et al.: 5.0).");
  PEGASUS_PARAM(arm_tr,
                "Tail-rotor hub distance l_tr behind the centre of mass, m (Gavrilets et al.: 0.91).");
  PEGASUS_PARAM(height_tr,
                "Tail-rotor hub height h_tr above the centre of mass, m (Gavrilets et al.: 0.08).");
  PEGASUS_PARAM(tail_mid_rad, "Tail collective pitch at a4 = 0, rad (chosen).");
  PEGASUS_PARAM(tail_span_rad,
                "Tail collective pitch change from a4 = 0 to a4 = +-1, rad (pitch = mid + span * a4, less "
                "the gyro's feedback).");
  PEGASUS_PARAM(gyro_gain,
                "Yaw-rate gyro: tail pitch taken off per rad/s of its lagged yaw rate, rad per rad/s "
                "(chosen).");
  PEGASUS_PARAM(gyro_tau, "First-order lag of the yaw-rate gyro loop, s (chosen).");
  PEGASUS_PARAM(fus_area_x,
                "Fuselage effective flat-plate drag area S_x^fus along the body x axis, m^2 "
                "(Gavrilets et al.: 0.1).");
  PEGASUS_PARAM(fus_area_y,
                "Fuselage effective flat-plate drag area S_y^fus along the body y axis, m^2 "
                "(Gavrilets et al.: 0.22).");
  PEGASUS_PARAM(fus_area_z,
                "Fuselage effective flat-plate drag area S_z^fus along the body z axis (in the rotor "
                "downwash), m^2 (Gavrilets et al.: 0.15).");
  PEGASUS_PARAM(servo_rate,
                "Servo slew-rate limit, control units (of [-1, 1]) per second (chosen: an RC servo "
                "moves about 60 degrees in 0.15 s).");
  PEGASUS_PARAM(max_thrust_coeff_over_solidity,
                "Main-rotor C_T / sigma beyond this crashes (blade stall, rotor overload), dimensionless.");
#undef PEGASUS_PARAM
  bind_ground_truth_params(params, std::move(own));

  auto aircraft = py::class_<Aircraft>(m, "Aircraft", R"doc(
The ground-truth helicopter (heli/aircraft.hpp): a nonlinear 6-DOF model of the X-Cell 60 stepped at 50 Hz, with
turbulence and state-estimate errors drawn from the uniforms of each step (noise_dim 15, initial_noise_dim 21).
A state row has 36 columns (STATE_COLUMNS: position p_W and velocity v_B, attitude, rates w_B, flapping, gyro,
servos, gusts, estimate errors, time, crash code); observe() gives the 12 logged states a flight computer sees.)doc");
  aircraft
      .def(py::init([](const AircraftParams& p) {
             std::string error;
             if (!p.IsValid(&error)) throw py::value_error("params." + error);
             return Aircraft(p);
           }),
           py::arg_v("params", AircraftParams{}, "AircraftParams()"))
      .def_property_readonly("params", &Aircraft::params, py::return_value_policy::copy,
                             "The AircraftParams it was built with (a copy: a model's settings are fixed).")
      .def_property_readonly_static(
          "STATE_COLUMNS", [](py::object) { return aircraft_columns(); },
          "The names of a state row's 36 columns, in order (p_W.x .. crash).")
      .def_property_readonly(
          "hover_trim",
          [](const Aircraft& a) {
            py::dict d;
            d["controls"] = vector_array(a.hover_trim().controls);
            d["roll"] = a.hover_trim().roll;
            d["pitch"] = a.hover_trim().pitch;
            d["residual"] = a.hover_trim().residual;
            return d;
          },
          "The hover trim (Newton's method): controls, roll, pitch, residual acceleration.")
      .def(
          "true_state",
          [](const Aircraft&, ArrayLikeArg states) {
            const Array s = as_matrix(states, "states", -1, kAircraftColumns);
            Array out = matrix(s.shape(0), kLogged);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              const LoggedState x =
                  heli::true_logged_state(aircraft_row(s.data() + r * kAircraftColumns, r, "states"));
              std::copy(x.begin(), x.end(), out.mutable_data() + r * kLogged);
            }
            return out;
          },
          py::arg("states"), "The true 12 logged states (no estimate error), [n, 12].")
      .def(
          "crash_reason",
          [](const Aircraft&, ArrayLikeArg states) {
            const Array s = as_matrix(states, "states", -1, kAircraftColumns);
            std::vector<std::string> out;
            for (py::ssize_t r = 0; r < s.shape(0); ++r)
              out.push_back(
                  heli::crash_reason_name(aircraft_row(s.data() + r * kAircraftColumns, r, "states").crash));
            return out;
          },
          py::arg("states"), "Why each row crashed ('none' when it has not).");
  HeliBatch<Aircraft>::bind(aircraft);

  m.def(
      "fly_pilot",
      [](const std::string& simulator, double seconds, std::uint64_t seed, double gust_sigma,
         bool estimate_noise, double hover_seconds, bool sweeps) {
        heli::GroundTruthSettings settings;
        settings.gust_sigma = gust_sigma;
        settings.estimate_noise = estimate_noise;
        std::unique_ptr<heli::GroundTruth> ground_truth;
        try {
          ground_truth = heli::make_ground_truth(simulator, settings);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        if (!(seconds > 0 && seconds <= 36000))
          throw py::value_error("seconds: expected a number in (0, 36000]");
        heli::PilotOptions options = heli::pilot_options_for(simulator);
        options.hover_seconds = hover_seconds;
        options.sweeps = sweeps;
        std::string error;
        if (!options.IsValid(&error)) throw py::value_error(error);
        heli::PilotFlight f;
        {
          ReleaseGilInterruptibly release;
          f = heli::fly_pilot(*ground_truth, options, seconds, seed);
        }
        Array truth = matrix(static_cast<py::ssize_t>(f.truth.size()), heli::kLoggedStates);
        for (std::size_t r = 0; r < f.truth.size(); ++r)
          std::copy(f.truth[r].begin(), f.truth[r].end(), truth.mutable_data() + r * heli::kLoggedStates);
        py::dict out;
        out["log"] = std::move(f.log);
        out["truth"] = truth;
        out["crash"] = heli::crash_reason_name(f.crash);
        out["crash_time"] = f.crash_time;
        return out;
      },
      py::arg("simulator") = "xcell", py::arg("seconds") = 60.0, py::arg("seed") = 1,
      py::arg("gust_sigma") = -1.0, py::arg("estimate_noise") = true, py::arg("hover_seconds") = 10.0,
      py::arg("sweeps") = true, fly_pilot_doc().c_str());

  auto lmo = py::class_<LearnedModelOptions>(m, "LearnedModelOptions", R"doc(
How the identified model is flown as a 50 Hz simulator (sysid/learned_model.hpp): refit period, support margin,
crash penalty (footnote 13), noise on or off, and the start state and its perturbation.)doc");
  lmo.def(py::init<>())
      .def_readwrite("dt", &LearnedModelOptions::dt, "One model step, s (50 Hz: 0.02).")
      .def_readwrite("refit_every", &LearnedModelOptions::refit_every,
                     "Steps between local-regression refits (§5.2.2: 5).")
      .def_readwrite(
          "support_bandwidths", &LearnedModelOptions::support_bandwidths,
          "A query with no training point within this many bandwidths crashes (off the data's support).")
      .def_readwrite("crash_reward", &LearnedModelOptions::crash_reward,
                     "Reward of a crash (footnote 13: -50000).")
      .def_readwrite("max_tilt_rad", &LearnedModelOptions::max_tilt_rad,
                     "|roll| or |pitch| beyond this crashes, rad.")
      .def_readwrite("noise", &LearnedModelOptions::noise,
                     "False: the mean model (the scenario's numbers are ignored).");
  def_array(lmo, "start", &LearnedModelOptions::start, "The 12 logged states before perturbation.");
  lmo.def_readwrite("start_pos_sigma", &LearnedModelOptions::start_pos_sigma,
                    "Start position perturbation per axis, m.")
      .def_readwrite("start_vel_sigma", &LearnedModelOptions::start_vel_sigma,
                     "Start velocity perturbation per axis, m/s.")
      .def("is_valid", is_valid_method<LearnedModelOptions>(), kIsValidDoc);
  set_fields(lmo, {"dt", "refit_every", "support_bandwidths", "crash_reward", "max_tilt_rad", "noise",
                   "start", "start_pos_sigma", "start_vel_sigma"});

  auto learned = py::class_<LearnedHeliModel>(m, "LearnedHeliModel", R"doc(
The identified helicopter (an IdentifiedModel, or the path of a model.json from `pegasus heli identify`) as a
deterministic 50 Hz simulator g(s, a, p) (thesis §5.2.2): locally weighted regression refitted every refit_every
steps, noise_dim 8, initial_noise_dim 6 (16 and 14 for a model identified with AR(1) noise, noise on). A state
row has 161 columns (STATE_COLUMNS: the 12 logged states first, then the extra states, the held coefficients,
the predictive variance, the AR part of the noise, the step and the crash flag); reward() is the crash
penalty.)doc");
  learned
      .def(py::init([](IdentifiedModelArg model, const LearnedModelOptions& o) {
             std::string error;
             if (!o.IsValid(&error)) throw py::value_error("options." + error);
             return LearnedHeliModel(identified_model(model), o);
           }),
           py::arg("model"), py::arg_v("options", LearnedModelOptions{}, "LearnedModelOptions()"))
      .def_property_readonly("options", &LearnedHeliModel::options, py::return_value_policy::copy,
                             "The LearnedModelOptions it was built with.")
      .def_property_readonly_static(
          "STATE_COLUMNS", [](py::object) { return learned_columns(); },
          "The names of a state row's 161 columns, in order (x .. yaw_rate first, crashed last).")
      .def(
          "reward",
          [](const LearnedHeliModel& model, ArrayLikeArg states, ArrayLikeArg actions, ArrayLikeArg next) {
            const Array s = as_matrix(states, "states", -1, kLearnedColumns);
            const Array a = as_matrix(actions, "actions", s.shape(0), 4);
            const Array n = as_matrix(next, "next_states", s.shape(0), kLearnedColumns);
            Array out(s.shape(0));
            for (py::ssize_t r = 0; r < s.shape(0); ++r)
              out.mutable_data()[r] = model.reward(
                  learned_row(s.data() + r * kLearnedColumns, r, "states"), controls_row(a.data() + 4 * r),
                  learned_row(n.data() + r * kLearnedColumns, r, "next_states"));
            return out;
          },
          py::arg("states"), py::arg("actions"), py::arg("next_states"),
          "The crash penalty of each transition (0 unless it crashed).");
  HeliBatch<LearnedHeliModel>::bind(learned);

  bind_hover(m);
  bind_heli_policy_files(m);
}

}  // namespace pegasus::python
