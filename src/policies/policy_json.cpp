#include "pegasus/policies/policy_json.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <utility>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/json_input.hpp"

namespace pegasus {

const nlohmann::json& policy_parameters_json(const nlohmann::json& j, std::string_view source,
                                             std::string_view policy_class, const ParameterSpec& spec,
                                             std::string_view what) {
  if (!j.is_object()) json_field_error(source, "(top level)", "a JSON object", j);
  // Version 0 (no "format") or a version this build reads.
  if (j.contains("format") || j.contains("version")) {
    const auto& format = json_member(j, "format", source, "format");
    if (format != kParameterPolicyFormat)
      json_field_error(source, "format", fmt::format("\"{}\"", kParameterPolicyFormat), format);
    const auto& version = json_member(j, "version", source, "version");
    if (!version.is_number_integer() || version.get<std::int64_t>() < 1 ||
        version.get<std::int64_t>() > kParameterPolicyVersion)
      json_field_error(
          source, "version",
          fmt::format("an integer in [1, {}] (the versions this build reads)", kParameterPolicyVersion),
          version);
  }
  const auto& policy = json_member(j, "policy", source, "policy");
  if (policy != policy_class) json_field_error(source, "policy", fmt::format("\"{}\"", policy_class), policy);
  const auto& parameters = json_member(j, "parameters", source, "parameters");
  if (!parameters.is_object())
    json_field_error(source, "parameters", "an object of parameter names and numbers", parameters);
  for (const auto& [name, value] : parameters.items())
    if (spec.index_of(name) == spec.size())
      throw InputError(
          fmt::format("{}: parameters.{}: not a parameter of {}", printable(source), printable(name), what));
  return parameters;
}

nlohmann::json parameter_policy_json(std::string_view policy_class, nlohmann::json parameters) {
  return {{"format", kParameterPolicyFormat},
          {"version", kParameterPolicyVersion},
          {"policy", policy_class},
          {"parameters", std::move(parameters)}};
}

Theta named_parameters(const nlohmann::json& parameters, std::string_view source, const ParameterSpec& spec,
                       std::size_t count) {
  Theta theta(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::string& name = spec[k].name;
    const std::string field = "parameters." + name;
    theta[k] = json_finite_number(json_member(parameters, name.c_str(), source, field), source, field);
  }
  return theta;
}

}  // namespace pegasus
