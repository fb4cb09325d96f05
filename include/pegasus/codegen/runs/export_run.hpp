#pragma once
// `export` as a library function: a policy file written as a dependency-free C99 controller (PREFIX.h,
// PREFIX.c; codegen/c_policy.hpp: the classes, the API, the bit-identity guarantee) into a run directory,
// with summary.json naming its functions, sizes and columns; and its config section.
#include <string>

#include "pegasus/codegen/c_policy.hpp"
#include "pegasus/runs/config.hpp"
#include "pegasus/runs/run_sink.hpp"

namespace pegasus {

struct ExportRunOptions {
  std::string policy_file;                                // policy.json of a training command
  std::string prefix = codegen::CPolicyOptions{}.prefix;  // file name and symbol prefix
  std::string vehicle_file;  // helicopter classes: also PREFIX_act_vehicle in its terms
};
// Bad input (no policy, a class the C export has no formula for, a prefix that is no C identifier, a vehicle
// file the policy's class cannot use) throws InputError naming it.
void run_c_export(const ExportRunOptions& options, RunSink& sink);

void declare_export_config(ConfigSchema& s);
ExportRunOptions read_export_config(const ConfigSchema& c);

}  // namespace pegasus
