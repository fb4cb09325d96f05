#pragma once
// Policy files of the form {"policy": CLASS, "parameters": {NAME: NUMBER, ...}} (the bicycle's and the
// pendulum's): the checks every such reader makes, written once. Errors are InputError "SOURCE: field
// 'parameters.NAME': ..." with the name made printable.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string_view>

#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

// The "parameters" object of `j` after checking that `j` is an object of class `policy_class` and that every
// name in it is one of `spec`'s (`what` names the class in that message: "the bicycle policy").
const nlohmann::json& policy_parameters_json(const nlohmann::json& j, std::string_view source,
                                             std::string_view policy_class, const ParameterSpec& spec,
                                             std::string_view what);

// The first `count` of `spec`'s parameters, in spec order, read from `parameters` (each present and finite).
Theta named_parameters(const nlohmann::json& parameters, std::string_view source, const ParameterSpec& spec,
                       std::size_t count);

}  // namespace pegasus
