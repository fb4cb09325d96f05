#pragma once
// Policy files of the form {"format": "pegasus-parameter-policy", "version": 1, "policy": CLASS,
// "parameters": {NAME: NUMBER, ...}} (the bicycle's and the pendulum's): the checks every such reader makes,
// written once. Files written before the format was named (no "format", no "version") are version 0 and still
// load. Errors are InputError "SOURCE: field 'parameters.NAME': ..." with the name made printable.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string_view>

#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

inline constexpr const char* kParameterPolicyFormat = "pegasus-parameter-policy";
inline constexpr int kParameterPolicyVersion = 1;

// The file of a policy of class `policy_class` with `parameters` ({name: number}), at the current version.
nlohmann::json parameter_policy_json(std::string_view policy_class, nlohmann::json parameters);

// The "parameters" object of `j` after checking that `j` is an object of class `policy_class` and that every
// name in it is one of `spec`'s (`what` names the class in that message: "the bicycle policy").
const nlohmann::json& policy_parameters_json(const nlohmann::json& j, std::string_view source,
                                             std::string_view policy_class, const ParameterSpec& spec,
                                             std::string_view what);

// The first `count` of `spec`'s parameters, in spec order, read from `parameters` (each present and finite).
Theta named_parameters(const nlohmann::json& parameters, std::string_view source, const ParameterSpec& spec,
                       std::size_t count);

}  // namespace pegasus
