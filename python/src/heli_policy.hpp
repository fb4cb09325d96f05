#pragma once
// Helicopter policy files from Python (heli/policy_file.hpp): a file with its controller bound, serving the
// controls of a batch of logged states; shared by the batch models (heli.cpp), which fly such a policy.
#include <memory>
#include <string>

#include "common.hpp"
#include "pegasus/heli/policy_file.hpp"

namespace pegasus::python {

// A policy file with its controller bound.
struct HeliPolicyObject {
  heli::PolicyFile file;
  std::string source;
  std::shared_ptr<const heli::HeliController> controller;

  HeliPolicyObject(heli::PolicyFile f, std::string from);

  // The controls [n, 4] for logged states [n, 12] at `time` (one number or one per row), on `threads`
  // threads; with one_flight the rows are one flight's control periods (the controller's memory carried).
  Array controls(ArrayLikeArg states, TimeArg time, std::int64_t threads, bool one_flight) const;
};

// pegasus.HeliPolicy and heli_policy_classes (needs pegasus.SetPoint and pegasus.HoverPolicyInit bound
// first).
void bind_heli_policy_files(py::module_& m);

}  // namespace pegasus::python
