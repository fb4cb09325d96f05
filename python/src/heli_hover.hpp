#pragma once
// What the helicopter's Python files share: heli.cpp (the models) and heli_hover.cpp (the hover task and its
// training).
#include <memory>

#include "common.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::python {

// A pegasus.IdentifiedModel, or the one a model.json path names (a ValueError otherwise).
std::shared_ptr<const sysid::IdentifiedModel> identified_model(IdentifiedModelArg model);
// HoverTrainingOptions, HoverProblem and the hover functions (thesis §5.3).
void bind_hover(py::module_& m);

}  // namespace pegasus::python
