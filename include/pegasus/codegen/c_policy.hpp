#pragma once
// Controllers out: a policy file the project writes becomes a dependency-free C99 header and source that a
// flight computer compiles (`pegasus export --policy P.json --lang c --out DIR`).
//
// Every policy class whose policy file a fixed formula expresses: the helicopter classes of heli's registry
// that registered a C text (heli/policy_file.hpp: register_policy_class; the built-in ones below), and the
// two parameter-file classes. Shipped:
//   "hover"               heli hover policy.json (heli/hover_policy.hpp, thesis §5.3, Eqs 5.7-5.8)
//   "maneuver"            heli maneuver policy.json (heli/maneuver_policy.hpp, §5.4): the hover networks
//                         fed the trajectory's set point, its legs emitted as a constant table
//   "bicycle-sigmoid-15"  bicycle train policy.json (envs/bicycle_policy.hpp, §4.6): SigmoidPolicy over the
//                         fifteen bicycle features
//   "pendulum-swing-up"   pendulum train policy.json (envs/pendulum_policy.hpp): five or seven numbers
// The generic TablePolicy / LinearPolicy / SigmoidPolicy of policies/policies.hpp have no policy file of
// their own (their features are C++ callables); the bicycle's file is the one SigmoidPolicy the project
// writes.
//
// The generated code (see the header comment it carries for the columns and units of each class):
//   #define PREFIX_OBSERVATION_SIZE n, PREFIX_ACTION_SIZE k (PREFIX upper-cased)
//   int prefix_act(const double* observation, double* action);
//       0 when every observation value is finite; otherwise 1 and the class's safe output (helicopter: the
//       policy file's trim, which `heli control` answers to a malformed line; bicycle and pendulum: 0)
//   int prefix_target(double time, double* set_point);   helicopter classes: x, y, z (W, NED, m), yaw (rad)
//   int prefix_act_vehicle(const double* observation, double* action);   with a vehicle file: the same
//       controller in the aircraft's own terms (quaternion or Euler attitude, body or world velocity, body
//       or Euler rates in; its channels out), converted as `pegasus control --vehicle` converts a line
// A controller with memory (a hover policy with the integral term: options "integral") remembers its error
// integral within a flight; its code adds `typedef struct prefix_memory {...} prefix_memory;` and
// `void prefix_reset(prefix_memory*)`, and its prefix_act and prefix_act_vehicle take the flight's memory
// first: int prefix_act(prefix_memory* memory, const double* observation, double* action).
// No allocation, no global written (weights and tables are `static const`), only <math.h> (link -lm).
//
// The guarantee: compiled without FMA contraction (x86-64 without -march, or -ffp-contract=off), the C
// computes every operation of the C++ policy in the same order with the same libm functions, so its
// outputs equal the C++ policy's bit for bit (tests/export checks it on 100,000 inputs per class and in
// the ground-truth flight loop).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pegasus/heli/vehicle_file.hpp"

namespace pegasus::codegen {

struct CPolicyOptions {
  // Name of the files (PREFIX.h, PREFIX.c) and prefix of every exported symbol; a C identifier.
  std::string prefix = "pegasus_policy";
  // Helicopter classes: also PREFIX_act_vehicle, the controller in this aircraft's own terms (its state
  // fields after the time, as its vehicle file names them; its channels in its order, ranges and signs).
  // Null: none.
  const logs::Vehicle* vehicle = nullptr;
  bool IsValid(std::string* error) const;
};

struct CPolicyCode {
  std::string class_name;  // "hover", "maneuver", "bicycle-sigmoid-15", "pendulum-swing-up"
  std::string header_name, header;
  std::string source_name, source;
  std::vector<std::string> observation_names;  // the observation's columns, in order
  std::vector<std::string> action_names;       // the action's columns, in order
  bool has_target = false;                     // PREFIX_target exists (helicopter classes)
  bool has_memory = false;                     // PREFIX_memory and PREFIX_reset exist; PREFIX_act takes one
  // PREFIX_act_vehicle (options.vehicle): its observation (time, the vehicle's state fields) and action (its
  // channels); empty without a vehicle.
  std::vector<std::string> vehicle_observation_names, vehicle_action_names;
  // The aircraft a helicopter policy file was trained for (heli::trained_vehicle: the X-Cell when it names
  // none); empty for the other classes, which fly no aircraft.
  std::string trained_vehicle;
};

// The class names export_c_policy knows, in the order above.
std::vector<std::string> c_policy_class_names();

// The C of a parsed policy file; `source` names it in messages and in the generated comment. InputError
// "SOURCE: FIELD: expected ..." for a file no class accepts.
CPolicyCode export_c_policy(const nlohmann::json& policy, const std::string& source,
                            const CPolicyOptions& options = {});
// Reads the file first: InputError "FILE: ..." when it cannot be read or is not JSON.
CPolicyCode export_c_policy_file(const std::filesystem::path& file, const CPolicyOptions& options = {});

}  // namespace pegasus::codegen
