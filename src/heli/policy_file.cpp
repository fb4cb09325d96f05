#include "pegasus/heli/policy_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/io/json_input.hpp"

namespace pegasus::heli {
namespace {

struct PolicyClass {
  PolicyClassFactory controller;
  PolicyClassCText c_text;  // empty: no C export
};

// The classes every build knows. A new class adds its line here (its factory and C text live with the class).
std::map<std::string, PolicyClass> builtin_classes() {
  return {{"hover", {make_hover_controller, hover_c_text}},
          {"maneuver", {make_maneuver_controller, maneuver_c_text}}};
}

struct Registry {
  std::mutex mutex;
  std::map<std::string, PolicyClass> classes = builtin_classes();
};
Registry& registry() {
  static Registry r;
  return r;
}

class HoverController final : public HeliController {
 public:
  HoverController(Theta theta, SetPoint target, ErrorIntegrator integrator, const HoverPolicyInit& limits)
      : policy_(limits), theta_(std::move(theta)), target_(target), integrator_(integrator) {}
  using HeliController::act;
  Controls act(const LoggedState& estimate, double, ControllerMemory& memory) const override {
    if (integrator_.on() &&
        std::all_of(estimate.begin(), estimate.end(), [](double x) { return std::isfinite(x); })) {
      // The first call of a flight starts from 0, as the training task's state does; every later call first
      // adds the control period's error (the state reached), as HoverTask::step does. A non-finite estimate
      // leaves the memory alone (as `heli control` and the exported C leave it for a malformed line).
      memory.integral =
          memory.started ? integrator_.advanced(memory.integral, estimate, target_) : std::array<double, 4>{};
      memory.started = true;
    }
    return policy_.act(theta_, HeliObservation{estimate, target_, memory.integral});
  }
  SetPoint target(double) const override { return target_; }

 private:
  HoverPolicy policy_;
  Theta theta_;
  SetPoint target_;
  ErrorIntegrator integrator_;
};

}  // namespace

void register_policy_class(const std::string& name, PolicyClassFactory factory, PolicyClassCText c_text) {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  r.classes[name] = {std::move(factory), std::move(c_text)};
}

std::vector<std::string> policy_class_names() {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, c] : r.classes) names.push_back(name);
  return names;
}

std::vector<std::string> c_text_policy_class_names() {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  std::vector<std::string> names;
  for (const auto& [name, c] : r.classes)
    if (c.c_text) names.push_back(name);
  return names;
}

PolicyClassCText policy_class_c_text(const std::string& name) {
  Registry& r = registry();
  const std::lock_guard lock(r.mutex);
  const auto it = r.classes.find(name);
  return it == r.classes.end() ? PolicyClassCText{} : it->second.c_text;
}

nlohmann::json policy_file_json(const PolicyFile& p) {
  nlohmann::json params = nlohmann::json::array();
  for (std::size_t i = 0; i < p.values.size(); ++i)
    params.push_back(
        {{"name", i < p.names.size() ? p.names[i] : fmt::format("w{}", i)}, {"value", p.values[i]}});
  nlohmann::json j = {
      {"format", kPolicyFormat},
      {"version", kPolicyVersion},
      {"class", p.class_name},
      {"parameters", params},
      {"target", {{"x", p.target.x}, {"y", p.target.y}, {"z", p.target.z}, {"yaw", p.target.yaw}}},
      {"trim", {{"a1", p.trim[0]}, {"a2", p.trim[1]}, {"a3", p.trim[2]}, {"a4", p.trim[3]}}}};
  if (!p.options.empty()) j["options"] = p.options;
  if (!p.provenance.empty()) j["provenance"] = p.provenance;
  return j;
}

void write_policy_file(const std::filesystem::path& file, const PolicyFile& policy) {
  write_file_atomic(file, json_text(policy_file_json(policy)));
}

std::string trained_vehicle(const PolicyFile& file) {
  const auto it = file.provenance.find("vehicle");
  return it != file.provenance.end() && it->is_string() ? it->get<std::string>()
                                                        : std::string(kBuiltInVehicle);
}

std::string other_vehicle_warning(const std::string& trained_for, const std::string& file,
                                  const std::string& vehicle, const std::string& doing) {
  if (trained_for.empty() || trained_for == vehicle) return {};
  return fmt::format("warning: {} was trained for vehicle '{}'; {} '{}'", printable(file),
                     printable(trained_for), doing, printable(vehicle));
}

PolicyFile parse_policy_file(const nlohmann::json& j, const std::string& file) {
  json_format_header(j, file, kPolicyFormat, kPolicyVersion);
  PolicyFile p;
  const auto& cls = json_member(j, "class", file, "class");
  p.class_name = json_nonempty_string(cls, file, "class");
  const auto& params = json_member(j, "parameters", file, "parameters");
  if (!params.is_array() || params.empty())
    json_field_error(file, "parameters", "a non-empty array of {\"name\", \"value\"}", params);
  for (std::size_t i = 0; i < params.size(); ++i) {
    const std::string where = fmt::format("parameters[{}]", i);
    const auto& e = params[i];
    if (!e.is_object()) json_field_error(file, where, "{\"name\": ..., \"value\": ...}", e);
    const auto& name = json_member(e, "name", file, where + ".name");
    if (!name.is_string()) json_field_error(file, where + ".name", "a string", name);
    p.names.push_back(name.get<std::string>());
    p.values.push_back(json_finite_number(json_member(e, "value", file, where + ".value"), file,
                                          fmt::format("{}.value ({})", where, p.names.back())));
  }
  const auto& target = json_member(j, "target", file, "target");
  if (!target.is_object()) json_field_error(file, "target", "{\"x\", \"y\", \"z\", \"yaw\"}", target);
  p.target.x = json_finite_number(json_member(target, "x", file, "target.x"), file, "target.x");
  p.target.y = json_finite_number(json_member(target, "y", file, "target.y"), file, "target.y");
  p.target.z = json_finite_number(json_member(target, "z", file, "target.z"), file, "target.z");
  p.target.yaw = json_finite_number(json_member(target, "yaw", file, "target.yaw"), file, "target.yaw");
  const auto& trim = json_member(j, "trim", file, "trim");
  if (!trim.is_object()) json_field_error(file, "trim", "{\"a1\", \"a2\", \"a3\", \"a4\"}", trim);
  for (std::size_t c = 0; c < 4; ++c) {
    const std::string field = fmt::format("trim.a{}", c + 1);
    const double v = json_finite_number(json_member(trim, kControlNames[c], file, field), file, field);
    if (std::abs(v) > 1) json_field_error(file, field, "a control in [-1, 1]", v);
    p.trim[c] = v;
  }
  if (const auto it = j.find("options"); it != j.end()) {
    if (!it->is_object()) json_field_error(file, "options", "an object", *it);
    p.options = *it;
  }
  if (const auto it = j.find("provenance"); it != j.end()) p.provenance = *it;
  return p;
}

PolicyFile read_policy_file(const std::filesystem::path& file) {
  return parse_policy_file(read_json_input(file, "policy"), file.string());
}

std::unique_ptr<HeliController> make_controller(const PolicyFile& policy, const std::string& file) {
  PolicyClassFactory factory;
  {
    Registry& r = registry();
    const std::lock_guard lock(r.mutex);
    const auto it = r.classes.find(policy.class_name);
    if (it == r.classes.end()) {
      std::string known;
      for (const auto& [name, f] : r.classes) known += (known.empty() ? "" : ", ") + name;
      json_field_error(file, "class", "one of " + known, policy.class_name);
    }
    factory = it->second.controller;
  }
  return factory(policy, file);
}

std::unique_ptr<HeliController> load_controller(const std::filesystem::path& file) {
  return make_controller(read_policy_file(file), file.string());
}

Theta checked_parameters(const PolicyFile& policy, const ParameterSpec& spec, const std::string& file) {
  const std::size_t n = std::min(policy.names.size(), spec.size());
  for (std::size_t i = 0; i < n; ++i)
    if (policy.names[i] != spec[i].name)
      json_field_error(file, fmt::format("parameters[{}].name", i),
                       fmt::format("\"{}\" (class {})", spec[i].name, policy.class_name), policy.names[i]);
  if (policy.names.size() != spec.size())
    json_field_error(file, "parameters",
                     fmt::format("{} parameters for class {}", spec.size(), policy.class_name),
                     policy.names.size());
  for (std::size_t i = 0; i < n; ++i)
    if (!(policy.values[i] >= spec[i].lower && policy.values[i] <= spec[i].upper))
      json_field_error(file, fmt::format("parameters[{}].value ({})", i, spec[i].name),
                       fmt::format("a value in [{}, {}]", spec[i].lower, spec[i].upper), policy.values[i]);
  return policy.values;
}

ErrorIntegrator hover_file_integrator(const PolicyFile& policy, const std::string& file) {
  const auto it = policy.options.find("integral");
  if (it == policy.options.end()) return {};
  if (!it->is_object())
    json_field_error(file, "options.integral", "{\"dt\", \"limit_position\", \"limit_yaw\"}", *it);
  const auto positive = [&](const char* name, const char* unit) {
    const std::string field = fmt::format("options.integral.{}", name);
    const nlohmann::json& v = json_member(*it, name, file, field);
    const double x = json_finite_number(v, file, field);
    if (!(x > 0)) json_field_error(file, field, fmt::format("a number > 0, {}", unit), v);
    return x;
  };
  return {.dt = positive("dt", "s (the control period)"),
          .limit_position = positive("limit_position", "m s"),
          .limit_yaw = positive("limit_yaw", "rad s")};
}

Theta checked_hover_parameters(const PolicyFile& policy, const std::string& file) {
  // Only the names and bounds matter here, which the starting gains do not change.
  const HoverPolicy spec_only(
      HoverPolicyInit{.integral_seconds = hover_file_integrator(policy, file).on() ? 1.0 : 0.0});
  return checked_parameters(policy, spec_only.parameters(), file);
}

HoverPolicyInit hover_file_command_limits(const PolicyFile& policy, const std::string& file) {
  HoverPolicyInit init;
  const auto it = policy.options.find("command_limits");
  if (it == policy.options.end()) return init;
  if (!it->is_object()) json_field_error(file, "options.command_limits", "{\"lower\", \"upper\"}", *it);
  const auto four = [&](const char* name) {
    const std::string field = fmt::format("options.command_limits.{}", name);
    const std::vector<double> v = json_finite_numbers(json_member(*it, name, file, field), file, field, 4);
    return Controls{v[0], v[1], v[2], v[3]};
  };
  init.command_lower = four("lower");
  init.command_upper = four("upper");
  std::string error;
  if (!command_limits_valid(init.command_lower, init.command_upper, &error))
    throw InputError(fmt::format("{}: options.command_limits: {}", file, error));
  return init;
}

void set_file_command_limits(PolicyFile& policy, const Controls& lower, const Controls& upper) {
  if (HoverPolicyInit{.command_lower = lower, .command_upper = upper}.has_command_limits())
    policy.options["command_limits"] = {{"lower", lower}, {"upper", upper}};
}

std::unique_ptr<HeliController> make_hover_controller(const PolicyFile& policy, const std::string& file) {
  return std::make_unique<HoverController>(checked_hover_parameters(policy, file), policy.target,
                                           hover_file_integrator(policy, file),
                                           hover_file_command_limits(policy, file));
}

PolicyFile hover_policy_file(const HoverPolicy& policy, std::span<const double> theta, const SetPoint& target,
                             const Controls& trim, const ErrorIntegrator& integrator) {
  PolicyFile p;
  p.class_name = "hover";
  for (const auto& param : policy.parameters().all()) p.names.push_back(param.name);
  p.values.assign(theta.begin(), theta.end());
  p.target = target;
  p.trim = trim;
  if (integrator.on())
    p.options["integral"] = {{"dt", integrator.dt},
                             {"limit_position", integrator.limit_position},
                             {"limit_yaw", integrator.limit_yaw}};
  set_file_command_limits(p, policy.command_lower(), policy.command_upper());
  return p;
}

}  // namespace pegasus::heli
