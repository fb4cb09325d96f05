#include "pegasus/policies/policy_json.hpp"

#include <fmt/format.h>

#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"

namespace pegasus {

const nlohmann::json& policy_parameters_json(const nlohmann::json& j, std::string_view source,
                                             std::string_view policy_class, const ParameterSpec& spec,
                                             std::string_view what) {
  if (!j.is_object()) throw InputError(fmt::format("{}: expected a JSON object", source));
  if (!j.contains("policy") || j.at("policy") != policy_class)
    throw InputError(fmt::format("{}: field 'policy': expected \"{}\"", source, policy_class));
  if (!j.contains("parameters") || !j.at("parameters").is_object())
    throw InputError(
        fmt::format("{}: field 'parameters': expected an object of parameter names and numbers", source));
  const auto& parameters = j.at("parameters");
  for (const auto& [name, value] : parameters.items())
    if (spec.index_of(name) == spec.size())
      throw InputError(
          fmt::format("{}: field 'parameters.{}': not a parameter of {}", source, printable(name), what));
  return parameters;
}

Theta named_parameters(const nlohmann::json& parameters, std::string_view source, const ParameterSpec& spec,
                       std::size_t count) {
  Theta theta(count);
  for (std::size_t k = 0; k < count; ++k) {
    const std::string& name = spec[k].name;
    if (!parameters.contains(name))
      throw InputError(fmt::format("{}: field 'parameters.{}': missing", source, name));
    const auto& value = parameters.at(name);
    if (!value.is_number() || !std::isfinite(value.get<double>()))
      throw InputError(fmt::format("{}: field 'parameters.{}': expected a finite number, got {}", source,
                                   name, value.dump()));
    theta[k] = value.get<double>();
  }
  return theta;
}

}  // namespace pegasus
