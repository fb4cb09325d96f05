// A policy file as C99 source in a run directory, and `export`'s config section
// (codegen/runs/export_run.hpp).
#include "pegasus/codegen/runs/export_run.hpp"

#include <fmt/format.h>

#include <optional>
#include <ostream>

#include "pegasus/codegen/c_policy.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/vehicle_file.hpp"

namespace pegasus {

void run_c_export(const ExportRunOptions& options, RunSink& sink) {
  const std::string& policy = options.policy_file;
  if (policy.empty()) throw InputError("--policy: expected a policy file");
  std::optional<logs::Vehicle> vehicle;
  if (!options.vehicle_file.empty()) vehicle = logs::read_vehicle(options.vehicle_file);
  const codegen::CPolicyOptions c_options{.prefix = options.prefix, .vehicle = vehicle ? &*vehicle : nullptr};
  std::string error;
  if (!c_options.IsValid(&error)) throw InputError("--" + error);
  const codegen::CPolicyCode code = codegen::export_c_policy_file(policy, c_options);
  if (vehicle)
    if (const std::string w = heli::other_vehicle_warning(code.trained_vehicle, policy, vehicle->name(),
                                                          "writing it in the terms of");
        !w.empty())
      sink.out << w << "\n";
  RunDirectory& dir = sink.dir;
  dir.write_text(code.header_name, code.header);
  dir.write_text(code.source_name, code.source);
  nlohmann::json summary = {{"class", code.class_name},
                            {"lang", "c"},
                            {"header_file", code.header_name},
                            {"source_file", code.source_name},
                            {"act_function", options.prefix + "_act"},
                            {"target_function", code.has_target ? nlohmann::json(options.prefix + "_target")
                                                                : nlohmann::json(nullptr)},
                            {"observation_size", code.observation_names.size()},
                            {"action_size", code.action_names.size()},
                            {"observation_names", code.observation_names},
                            {"action_names", code.action_names}};
  if (code.has_memory) {  // only then: the summaries of stateless classes stay as they were
    summary["memory_type"] = options.prefix + "_memory";
    summary["reset_function"] = options.prefix + "_reset";
  }
  if (vehicle) {
    summary["vehicle"] = vehicle->name();
    summary["vehicle_act_function"] = options.prefix + "_act_vehicle";
    summary["vehicle_observation_names"] = code.vehicle_observation_names;
    summary["vehicle_action_names"] = code.vehicle_action_names;
  }
  dir.write_json("summary.json", summary);
  sink.out << fmt::format("class {}: {} observations -> {} actions\n", code.class_name,
                          code.observation_names.size(), code.action_names.size());
  sink.out << fmt::format("header: {}\nsource: {}\n", sink.named(dir.final_path() / code.header_name),
                          sink.named(dir.final_path() / code.source_name));
}

void declare_export_config(ConfigSchema& s) {
  s.add_string("policy", "",
               "policy file: policy.json of heli hover, heli maneuver, bicycle train or pendulum train")
      .input_file();
  s.add_string("lang", "c", "language of the generated code").choices({"c"});
  s.add_string("prefix", ExportRunOptions{}.prefix, "file name and symbol prefix of the generated code");
  s.add_string("vehicle", "",
               "helicopter classes: a vehicle file; adds PREFIX_act_vehicle, the controller in that "
               "aircraft's own state fields and channels")
      .input_file();
}

ExportRunOptions read_export_config(const ConfigSchema& c) {
  return {.policy_file = c.get_path("policy"),
          .prefix = c.get_string("prefix"),
          .vehicle_file = c.get_path("vehicle")};
}

}  // namespace pegasus
