// The second aircraft from Python: the Crazyflie 2.0 ground truth (heli/quadrotor.hpp) as a batch model over
// numpy rows, with the helicopter's batch interface (heli_batch.hpp) and its parameters by their C++ names.
#include "pegasus/heli/quadrotor.hpp"

#include <fmt/format.h>

#include <cmath>

#include "heli_batch.hpp"

namespace pegasus::python {

namespace {

using heli::Quadrotor;
using heli::QuadrotorParams;
using heli::QuadrotorState;

// The state as a row of 33 numbers: every field of QuadrotorState, frames as there.
constexpr py::ssize_t kQuadrotorColumns = 33;
std::vector<std::string> quadrotor_columns() {
  std::vector<std::string> c = {
      "p_W.x",         "p_W.y",         "p_W.z",    "v_B.x",    "v_B.y",   "v_B.z",         "roll",
      "pitch",         "yaw",           "w_B.x",    "w_B.y",    "w_B.z",   "rotor_speed.1", "rotor_speed.2",
      "rotor_speed.3", "rotor_speed.4", "gust_W.x", "gust_W.y", "gust_W.z"};
  for (const char* n : heli::kLoggedStateNames) c.push_back(std::string("estimate_error.") + n);
  c.push_back("time");
  c.push_back("crash");
  return c;
}

}  // namespace

template <>
struct StateRows<Quadrotor> {
  static constexpr py::ssize_t kColumns = kQuadrotorColumns;
  static void write(const QuadrotorState& s, double* x) {
    for (int i = 0; i < 3; ++i)
      x[i] = s.p_W[i], x[3 + i] = s.v_B[i], x[9 + i] = s.w_B[i], x[16 + i] = s.gust_W[i];
    x[6] = s.attitude.roll, x[7] = s.attitude.pitch, x[8] = s.attitude.yaw;
    for (std::size_t i = 0; i < 4; ++i) x[12 + i] = s.rotor_speed[i];
    for (std::size_t i = 0; i < heli::kLoggedStates; ++i) x[19 + i] = s.estimate_error[i];
    x[31] = s.time;
    x[32] = static_cast<double>(static_cast<int>(s.crash));
  }
  static QuadrotorState read(const double* x, py::ssize_t row, const char* name) {
    QuadrotorState s;
    for (int i = 0; i < 3; ++i)
      s.p_W[i] = x[i], s.v_B[i] = x[3 + i], s.w_B[i] = x[9 + i], s.gust_W[i] = x[16 + i];
    s.attitude = {x[6], x[7], x[8]};
    for (std::size_t i = 0; i < 4; ++i) s.rotor_speed[i] = x[12 + i];
    for (std::size_t i = 0; i < heli::kLoggedStates; ++i) s.estimate_error[i] = x[19 + i];
    s.time = x[31];
    const double crash = x[32];
    if (!(crash >= 0 && crash <= static_cast<int>(heli::CrashReason::kModelSupport) &&
          crash == std::floor(crash)))
      throw py::value_error(
          fmt::format("{}: expected a crash code in 0..{} in column 32 (crash), got {} at row {}", name,
                      static_cast<int>(heli::CrashReason::kModelSupport), crash, row));
    s.crash = static_cast<heli::CrashReason>(static_cast<int>(crash));
    return s;
  }
};

void bind_quadrotor(py::module_& m) {
  auto params = py::class_<QuadrotorParams>(m, "QuadrotorParams", R"doc(
The ground-truth quadrotor's parameters (heli/quadrotor.hpp: the Crazyflie 2.0 as Förster identified it, its
onboard angle-mode controller, disturbances, crash limits, integration, start), every field with the C++ name
and unit.)doc");
  params.def(py::init<>());
  std::vector<const char*> own;  // the fields this aircraft alone has, in order
  // Published values are Förster's ("System Identification of the Crazyflie 2.0 Nano Quadrocopter", 2015), as
  // heli/quadrotor.hpp cites them.
#define PEGASUS_PARAM(field, doc) \
  (params.def_readwrite(#field, &QuadrotorParams::field, doc), own.push_back(#field))
  PEGASUS_PARAM(mass_kg, "Mass with the battery, kg (Förster: 0.028).");
  PEGASUS_PARAM(ixx, "Moment of inertia about the body x axis (forward), kg m^2 (Förster: 16.571710e-6).");
  PEGASUS_PARAM(iyy, "Moment of inertia about the body y axis (right), kg m^2 (Förster: 16.655602e-6).");
  PEGASUS_PARAM(izz, "Moment of inertia about the body z axis (down), kg m^2 (Förster: 29.261652e-6).");
  PEGASUS_PARAM(arm_m,
                "Distance from each motor to the centre of mass, m (Förster: 0.046; X configuration, motors "
                "45 degrees off the body axes).");
  PEGASUS_PARAM(gravity, "Gravitational acceleration, m/s^2 (along +z, down, in the NED world frame).");
  PEGASUS_PARAM(thrust_coeff,
                "Rotor thrust coefficient k_f: each rotor's thrust is k_f w^2, N per (rad/s)^2 (Förster, as "
                "gym-pybullet-drones' cf2x: 3.16e-10 N/rpm^2).");
  PEGASUS_PARAM(torque_per_thrust_m,
                "Rotor drag torque per newton of thrust, m (Förster; the firmware's THRUST2TORQUE: "
                "0.005964552).");
  PEGASUS_PARAM(max_motor_thrust_n,
                "Thrust of one motor at full PWM, N (Förster's PWM-to-thrust map: 0.1597).");
  PEGASUS_PARAM(motor_tau,
                "Time constant of each rotor speed's first-order lag behind its command, s (CrazyS's "
                "time_constant_up: 0.0125).");
  PEGASUS_PARAM(drag_xy,
                "Rotor drag K_aero along the body x and y axes, kg/rad: force against the airspeed per "
                "(sum of rotor speeds * airspeed) (Förster: 9.1785e-7).");
  PEGASUS_PARAM(drag_z,
                "Rotor drag K_aero along the body z axis, kg/rad: force against the airspeed per (sum of "
                "rotor speeds * airspeed) (Förster: 10.311e-7).");
  PEGASUS_PARAM(max_tilt_command_rad,
                "Onboard controller: roll and pitch set point at full stick (a1 or a2 = +-1), rad (cfclient: "
                "30 degrees).");
  PEGASUS_PARAM(max_yaw_rate_command,
                "Onboard controller: yaw-rate set point at full stick (a4 = +-1), rad/s (cfclient: "
                "200 deg/s).");
  PEGASUS_PARAM(attitude_gain,
                "Onboard controller: roll or pitch rate set point per rad of attitude error, 1/s (the "
                "firmware's Kp: 6).");
  PEGASUS_PARAM(rate_gain,
                "Onboard controller: roll or pitch angular acceleration per rad/s of rate error, 1/s.");
  PEGASUS_PARAM(yaw_rate_gain,
                "Onboard controller: yaw angular acceleration per rad/s of yaw-rate error, 1/s.");
#undef PEGASUS_PARAM
  bind_ground_truth_params(params, std::move(own));

  auto quadrotor = py::class_<Quadrotor>(m, "Quadrotor", R"doc(
The ground-truth quadrotor (heli/quadrotor.hpp): the Crazyflie 2.0 flown through its onboard angle-mode
controller, stepped at 50 Hz (500 Hz inside), with rotor dynamics and drag, turbulence and state-estimate errors
drawn from the uniforms of each step (noise_dim 15, initial_noise_dim 21). Controls a1..a4 in [-1, 1]: pitch and
roll set points, collective thrust, yaw rate set point. A state row has 33 columns (STATE_COLUMNS: position p_W
and velocity v_B, attitude, rates w_B, rotor speeds, gusts, estimate errors, time, crash code); observe() gives
the 12 logged states a flight computer sees. The batch methods are Aircraft's.)doc");
  quadrotor
      .def(py::init([](const QuadrotorParams& p) {
             std::string error;
             if (!p.IsValid(&error)) throw py::value_error("params." + error);
             return Quadrotor(p);
           }),
           py::arg_v("params", QuadrotorParams{}, "QuadrotorParams()"))
      .def_property_readonly("params", &Quadrotor::params, py::return_value_policy::copy,
                             "The QuadrotorParams it was built with (a copy: a model's settings are fixed).")
      .def_property_readonly_static(
          "STATE_COLUMNS", [](py::object) { return quadrotor_columns(); },
          "The names of a state row's 33 columns, in order (p_W.x .. crash).")
      .def_property_readonly(
          "hover_trim",
          [](const Quadrotor& q) {
            const heli::HoverPoint h = q.hover_point();
            py::dict d;
            d["controls"] = vector_array(h.controls);
            d["roll"] = h.roll;
            d["pitch"] = h.pitch;
            return d;
          },
          "The controls and attitude that hold it still in calm air (collective at the hover thrust).")
      .def_property_readonly("hover_rotor_speed", &Quadrotor::hover_rotor_speed,
                             "The rotor speed that holds it at rest, rad/s.")
      .def(
          "true_state",
          [](const Quadrotor&, ArrayLikeArg states) {
            const Array s = as_matrix(states, "states", -1, kQuadrotorColumns);
            Array out = matrix(s.shape(0), kLogged);
            for (py::ssize_t r = 0; r < s.shape(0); ++r) {
              const heli::LoggedState x = heli::true_logged_state(
                  StateRows<Quadrotor>::read(s.data() + r * kQuadrotorColumns, r, "states"));
              std::copy(x.begin(), x.end(), out.mutable_data() + r * kLogged);
            }
            return out;
          },
          py::arg("states"), "The true 12 logged states (no estimate error), [n, 12].")
      .def(
          "crash_reason",
          [](const Quadrotor&, ArrayLikeArg states) {
            const Array s = as_matrix(states, "states", -1, kQuadrotorColumns);
            std::vector<std::string> out;
            for (py::ssize_t r = 0; r < s.shape(0); ++r)
              out.push_back(heli::crash_reason_name(
                  StateRows<Quadrotor>::read(s.data() + r * kQuadrotorColumns, r, "states").crash));
            return out;
          },
          py::arg("states"), "Why each row crashed ('none' when it has not).");
  HeliBatch<Quadrotor>::bind(quadrotor);
}

}  // namespace pegasus::python
