#pragma once
// What the C export's own files share (c_policy.cpp assembles the files and writes the bicycle and pendulum
// classes; the helicopter classes write theirs in heli/policy_c_text.cpp and register it with the class):
// the class text and its helpers (policies/c_text.hpp), and the wrapper in a vehicle's own terms.
#include "pegasus/codegen/c_policy.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/policies/c_text.hpp"

namespace pegasus::codegen::detail {

// A helicopter class in a vehicle's own terms (PREFIX_act_vehicle; its column names go to `names`).
void add_vehicle(ClassText& t, const logs::Vehicle& vehicle, CPolicyCode* names);

}  // namespace pegasus::codegen::detail
