#include "pegasus/policies/policy_json.hpp"

#include <fmt/format.h>

#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/json_input.hpp"

namespace pegasus {

const nlohmann::json& policy_parameters_json(const nlohmann::json& j, std::string_view source,
                                             std::string_view policy_class, const ParameterSpec& spec,
                                             std::string_view what) {
  if (!j.is_object()) json_field_error(source, "(top level)", "a JSON object", j);
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
