#pragma once
// Helicopter policy files: a learned controller saved so that `pegasus heli fly`, `pegasus heli control` or
// anyone else can fly it. JSON, one object:
//
//   {
//     "format": "pegasus-heli-policy",      required, exactly this string
//     "version": 1,                         required, 1
//     "class": "hover",                     required: a registered policy class ("hover", "maneuver", ...)
//     "parameters": [                       required: every parameter of the class, in the class's order
//       {"name": "a1.bias", "value": 0.0123}, ...
//     ],
//     "target": {"x": 0, "y": 0, "z": -10, "yaw": 0},   required: world NED, m and rad (hover: the set point;
//                                                        other classes: where their path is anchored)
//     "trim": {"a1": 0, "a2": 0.036, "a3": 0.184, "a4": 0.194},  required: the hover trim estimate of the
//                                                        pilot's logs (the class's starting point, and the
//                                                        safe output of `heli control`), each in [-1, 1]
//     "options": {...},                     optional: class-specific settings (maneuver: which trajectory
//                                           ...; hover: "integral": {"dt", "limit_position", "limit_yaw"},
//                                           the integral term's integrator, with parameters a1.int..a4.int;
//                                           "command_limits": {"lower": [4], "upper": [4]}, each output's
//                                           limits within [-1, 1], absent: [-1, 1])
//     "provenance": {...}                   optional, ignored: how the policy was made (command, U-hat, ...)
//   }
// Doubles are written with the shortest text that reads back to the same bits, so a policy file reproduces
// the trained controller exactly. Reading checks everything and throws InputError
// "FILE: FIELD: expected ..., got ..." naming the first bad field (parameters by index and name).
//
// A registry maps class names to what each class is: the factory that binds the weights into a
// HeliController (flying, `control`, Python), and, where the class has one, its C text (the C export).
// "hover" and "maneuver" are built in; another class registers itself once with register_policy_class (or
// adds one line to the built-in table in src/heli/policy_file.cpp, so that it is there without a call).
#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "pegasus/heli/hover_policy.hpp"
#include "pegasus/policies/c_text.hpp"

namespace pegasus::heli {

inline constexpr const char* kPolicyFormat = "pegasus-heli-policy";
inline constexpr int kPolicyVersion = 1;

struct PolicyFile {
  std::string class_name = "hover";
  std::vector<std::string> names;  // parameter names, in order
  Theta values;                    // parameter values, same order
  SetPoint target{};
  Controls trim{};
  nlohmann::json options = nlohmann::json::object();
  nlohmann::json provenance = nlohmann::json::object();
};

// What a controller keeps between the calls of one flight: the hover class's error integral (its integral
// term; ErrorIntegrator). Zero at the start of every flight; the flight owns it, so one controller still
// serves many flights at once. Classes without memory leave it alone.
struct ControllerMemory {
  std::array<double, 4> integral{};  // HeliObservation::integral
  bool started = false;              // set by the flight's first call
};

// A policy with its weights bound: what flies. Const: whatever a class remembers within a flight lives in
// the flight's ControllerMemory (a path observer keeps its own from `time` alone).
class HeliController {
 public:
  virtual ~HeliController() = default;
  // Controls in [-1, 1]^4 for the state estimate (12 logged states, log column order) `time` seconds after
  // the flight (or the manoeuvre) began; one call per control period, in order, with the flight's memory.
  virtual Controls act(const LoggedState& estimate, double time, ControllerMemory& memory) const = 0;
  // One call with a fresh memory: a flight's first call (every call, for a class without memory).
  Controls act(const LoggedState& estimate, double time) const {
    ControllerMemory fresh;
    return act(estimate, time, fresh);
  }
  // The set point the controller steers to at `time` (for traces and errors).
  virtual SetPoint target(double time) const = 0;
};

// Factory: builds the controller of a checked file; throws InputError naming `file` and the field when the
// file does not fit the class (wrong parameter names, bad options).
using PolicyClassFactory =
    std::function<std::unique_ptr<HeliController>(const PolicyFile& policy, const std::string& file)>;

// The C text of a checked file of the class (policies/c_text.hpp), for `pegasus export --lang c`; InputError
// naming `file` and the field when the file does not fit the class.
using PolicyClassCText = std::function<codegen::ClassText(const PolicyFile& policy, const std::string& file)>;

// Adds (or replaces) a class: its controller, and its C text where it has one (none: it flies, and the C
// export refuses it, saying so). Thread-safe; call before flying.
void register_policy_class(const std::string& name, PolicyClassFactory factory, PolicyClassCText c_text = {});
// Registered class names, sorted.
std::vector<std::string> policy_class_names();
// The registered classes that have a C text, sorted.
std::vector<std::string> c_text_policy_class_names();
// The C text of the registered class `name`, or an empty function when it has none or is not registered.
PolicyClassCText policy_class_c_text(const std::string& name);

nlohmann::json policy_file_json(const PolicyFile& policy);
void write_policy_file(const std::filesystem::path& file, const PolicyFile& policy);  // atomic
// Parses and checks the common fields (not yet the class's); `file` names the source in messages.
// The aircraft a model or policy file that names none was made for: the built-in X-Cell 60 (the commands
// without --vehicle, and files of versions before vehicle files). logs::xcell_vehicle() carries the name.
inline constexpr const char* kBuiltInVehicle = "xcell60";
// The aircraft a policy was trained for, as its provenance names it (hover and maneuver with a vehicle
// file), else kBuiltInVehicle.
std::string trained_vehicle(const PolicyFile& file);
// "warning: FILE was trained for vehicle 'A'; DOING 'B'" when `file` names another aircraft than `vehicle`,
// else empty: a policy may be meant for another aircraft, but that should not pass unsaid.
std::string other_vehicle_warning(const std::string& trained_for, const std::string& file,
                                  const std::string& vehicle, const std::string& doing);
PolicyFile parse_policy_file(const nlohmann::json& j, const std::string& file);
PolicyFile read_policy_file(const std::filesystem::path& file);
// The controller of a checked file through the registry (InputError "FILE: class: ..." when unknown).
std::unique_ptr<HeliController> make_controller(const PolicyFile& policy, const std::string& file);
std::unique_ptr<HeliController> load_controller(const std::filesystem::path& file);

// Checks that the file's parameter names are exactly the spec's, in order; InputError naming the file, the
// index and the names otherwise. Returns the values.
Theta checked_parameters(const PolicyFile& policy, const ParameterSpec& spec, const std::string& file);

// The hover class: HoverPolicy steering to policy.target at every time.
std::unique_ptr<HeliController> make_hover_controller(const PolicyFile& policy, const std::string& file);
// The C texts of the built-in classes (src/heli/policy_c_text.cpp): the hover networks, and the manoeuvre's
// with its trajectory as a constant table.
codegen::ClassText hover_c_text(const PolicyFile& policy, const std::string& file);
codegen::ClassText maneuver_c_text(const PolicyFile& policy, const std::string& file);
// A hover policy file from trained weights (with the integrator in its options when it is on, and the
// policy's command limits when they are not [-1, 1]).
PolicyFile hover_policy_file(const HoverPolicy& policy, std::span<const double> theta, const SetPoint& target,
                             const Controls& trim, const ErrorIntegrator& integrator = {});
// The integral term's integrator of a hover file's options (off without "integral"); InputError naming
// `file` and the field.
ErrorIntegrator hover_file_integrator(const PolicyFile& policy, const std::string& file);
// The command limits of a hover or manoeuvre file's options (HoverPolicyInit's command_lower/upper; [-1, 1]
// without "command_limits"); InputError naming `file` and the field.
HoverPolicyInit hover_file_command_limits(const PolicyFile& policy, const std::string& file);
// Adds "command_limits" with these to the options, unless they are [-1, 1] on every channel (then the file
// stays as it was before limits existed).
void set_file_command_limits(PolicyFile& policy, const Controls& lower, const Controls& upper);
// A hover file's weights checked against the class: the 34, and a1.int..a4.int when its options have the
// integral term's integrator. InputError naming `file` and the field.
Theta checked_hover_parameters(const PolicyFile& policy, const std::string& file);

}  // namespace pegasus::heli
