#pragma once
// The regression problem of thesis §5.2.2: body-frame variables, the extra rotor and gyro states taken from a
// published model, kinematic templates, and the datasets built from flight logs.
//
// Body-frame variables s^b (§5.2.2): roll, pitch (rad), the velocity in the body frame B (xdot_b, ydot_b,
// zdot_b, m/s) and the Euler angle rates (roll_rate, pitch_rate, yaw_rate, rad/s). Each is predicted as its
// one-step change over the model step dt.
// Regression inputs x (kInputs = 16): the 8 body variables, the extra states flap_lon, flap_lat, gyro_rate,
// the controls a1..a4 and a constant 1.
#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "pegasus/core/number_setting.hpp"
#include "pegasus/vehicle/flight_log.hpp"

namespace pegasus::sysid {

inline constexpr int kBodyVars = 8;
inline constexpr int kInputs = 16;
inline constexpr std::array<const char*, kBodyVars> kBodyVarNames = {
    "roll", "pitch", "xdot_b", "ydot_b", "zdot_b", "roll_rate", "pitch_rate", "yaw_rate"};
inline constexpr std::array<const char*, kInputs> kInputNames = {
    "roll",     "pitch",    "xdot_b",    "ydot_b", "zdot_b", "roll_rate", "pitch_rate", "yaw_rate",
    "flap_lon", "flap_lat", "gyro_rate", "a1",     "a2",     "a3",        "a4",         "one"};
enum InputIndex : int {
  kRoll = 0,
  kPitch,
  kU,
  kV,
  kW,
  kRollRate,
  kPitchRate,
  kYawRate,
  kFlapLon,
  kFlapLat,
  kGyro,
  kA1,
  kA2,
  kA3,
  kA4,
  kOne
};
using InputVec = Eigen::Matrix<double, kInputs, 1>;
using BodyVec = Eigen::Matrix<double, kBodyVars, 1>;

// The unobserved states' model, from the published identification (Gavrilets, Mettler and Feron, AIAA
// 2001-4333, [GMF01]); §5.2.2 took them from Shim's model for the same reason: they are not observed.
struct ExtraStateModel {
  double tau_flap = 0.1;      // [GMF01] tau_e, s
  double flap_per_a1 = 0.21;  // [GMF01] A_lon (4.2 rad/rad) times the cyclic range (0.05 rad), rad
  double flap_per_a2 = 0.21;  // [GMF01] B_lat times the cyclic range, rad
  double gyro_tau = 0.05;     // the yaw gyro loop's lag, s
  // Advances (flap_lon, flap_lat, gyro_rate) over dt with controls and body rates (p, q, r) held: exact
  // solution of the first-order lags flap' = q + (A a1 - flap) / tau etc.
  void advance(double dt, const Eigen::Vector3d& w_B, const std::array<double, 4>& a, double* flap_lon,
               double* flap_lat, double* gyro) const;
};

// Which variants of §5.2.2 the model uses.
struct ModelStructure {
  double rate_hz = 10;       // identification rate (the log's 50 Hz downsampled)
  bool extra_states = true;  // use flap_lon, flap_lat, gyro_rate as inputs
  bool intercept = true;     // regress on the constant 1
  bool templates = true;     // kinematic templates (else every coefficient is regressed)
  double gravity = 9.81;
  ExtraStateModel extra{};
  // Inputs left out of every output's regression because they do not vary in the training data (a control
  // the pilot never moved, a rotor that never spun): their coefficients would be unidentifiable (X'WX
  // singular with the intercept), so they are fixed at 0 and the intercept carries their constant value.
  // identify() sets them from the data; empty for the X-Cell's logs, where every input moves.
  std::array<bool, kInputs> constant_inputs{};
  std::string describe() const;

  // What a user sets, once (issue 49 item 1): identify's rate_hz and its three switches, as options with
  // their help and reading (bounds: IdentifyOptions::IsValid too); the rest is the model's or the data's.
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    v.setting({"rate_hz", 1, 50, false, "Hz", "identification rate, Hz (the log is downsampled)"},
              &ModelStructure::rate_hz);
  }
  template <class Visitor>
  static void VisitFlags(Visitor& v) {
    v.flag({"extra_states", "use the flapping and yaw-gyro states of the published model"},
           &ModelStructure::extra_states);
    v.flag({"intercept", "regress on a constant"}, &ModelStructure::intercept);
    v.flag({"templates", "fix kinematic and gravity coefficients (thesis 5.2.2)"},
           &ModelStructure::templates);
  }
};

// Template of §5.2.2 for output k: the known part of the change (coefficients fixed at 0, +-1, +-g through
// kinematics and gravity) and which inputs are left to the regression.
struct OutputTemplate {
  std::array<bool, kInputs> free{};
  int free_count() const;
};
std::array<OutputTemplate, kBodyVars> output_templates(const ModelStructure& m);
// The known part of the change of each body variable over dt at input x (0 where nothing is known).
BodyVec known_change(const ModelStructure& m, const InputVec& x, double dt);

// Log rows to body variables and back. world = the 12 log states.
BodyVec body_from_log_state(const std::array<double, kLogStates>& s);

// The regression data at the model rate, in time order.
struct Dataset {
  double dt = 0.1;                                                      // model step, s
  Eigen::Matrix<double, Eigen::Dynamic, kInputs, Eigen::RowMajor> x;    // inputs at step t
  Eigen::Matrix<double, Eigen::Dynamic, kBodyVars, Eigen::RowMajor> y;  // change minus the known part
  std::vector<double> time;                                             // s, of each row
  Eigen::Index rows() const { return x.rows(); }
};

// Log rows per model step when the model rate divides the log's rate (1 / log_dt) within 1 %: 5 for a 10 Hz
// model of a 50 Hz log; 0 when it does not (a 25 Hz model of a 10 Hz log, or of a 40 Hz one).
std::size_t log_rows_per_model_step(double log_dt, double rate_hz);
// Downsamples a 50 Hz log to the model rate (every k-th row; the controls of a model step are the mean of the
// log's controls over it), runs the extra-state model along the full-rate log, and builds inputs and
// targets. InputError when the log's rate is not a multiple of the model rate.
Dataset build_dataset(const FlightLog& log, const ModelStructure& m);
// The inputs (the constant 1 aside) whose every row equals the first: ModelStructure::constant_inputs.
std::array<bool, kInputs> constant_inputs(const Dataset& data);
// The extra states along a full-rate log (one row per log row): flap_lon, flap_lat, gyro.
std::vector<std::array<double, 3>> extra_states_along(const FlightLog& log, const ModelStructure& m);

}  // namespace pegasus::sysid
