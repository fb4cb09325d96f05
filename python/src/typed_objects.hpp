#pragma once
// Python objects a binding takes as they come (it converts or checks them itself: as_matrix, as_vector, a
// model's name or object), named for what they should be. pybind11 calls a py::object parameter "object" in
// every signature; these name the Python type instead, so that help(), the manual and the .pyi stubs
// generated from the compiled module (scripts/generate_stubs.py) say what to pass. Each accepts any object:
// the conversion inside the binding still raises the ValueError that names the argument.
#include <pybind11/pybind11.h>

namespace pegasus::python {

namespace py = pybind11;

inline bool accepts_any_object(PyObject*) { return true; }

#define PEGASUS_TYPED_OBJECT(Name)                                \
  struct Name : py::object {                                      \
    PYBIND11_OBJECT_DEFAULT(Name, py::object, accepts_any_object) \
  };

PEGASUS_TYPED_OBJECT(ArrayLikeArg)        // a float array or anything numpy.asarray takes
PEGASUS_TYPED_OBJECT(TimeArg)             // a time in seconds, or one per row
PEGASUS_TYPED_OBJECT(SeedArg)             // a seed: any Python int of 0 .. 2^64 - 1
PEGASUS_TYPED_OBJECT(IdentifiedModelArg)  // an IdentifiedModel, or the path of its model.json
PEGASUS_TYPED_OBJECT(HeliModelArg)        // what a hover is flown on
PEGASUS_TYPED_OBJECT(FlightLogsArg)       // one hold-out flight or several
PEGASUS_TYPED_OBJECT(CheckpointCallbackArg)
PEGASUS_TYPED_OBJECT(CheckpointArg)  // a checkpoint as on_checkpoint gave it
PEGASUS_TYPED_OBJECT(OptionalCheckpointArg)
PEGASUS_TYPED_OBJECT(IterationCallbacksArg)
PEGASUS_TYPED_OBJECT(ObjectiveFunctionArg)  // f(theta) -> float
PEGASUS_TYPED_OBJECT(JsonObject)            // a JSON document as Python values
PEGASUS_TYPED_OBJECT(HeliPolicyArg)         // a HeliPolicy, or None
PEGASUS_TYPED_OBJECT(UserObjectArg)         // a user's duck-typed Python object (its protocol in the doc)
PEGASUS_TYPED_OBJECT(PathArg)               // a file or folder: a str or an os.PathLike (pathlib.Path)

#undef PEGASUS_TYPED_OBJECT

}  // namespace pegasus::python

namespace pybind11::detail {

#define PEGASUS_TYPED_OBJECT_NAME(Name, text)      \
  template <>                                      \
  struct handle_type_name<pegasus::python::Name> { \
    static constexpr auto name = const_name(text); \
  };

PEGASUS_TYPED_OBJECT_NAME(ArrayLikeArg, "ArrayLike")
PEGASUS_TYPED_OBJECT_NAME(TimeArg, "Union[float, ArrayLike]")
PEGASUS_TYPED_OBJECT_NAME(SeedArg, "int")
PEGASUS_TYPED_OBJECT_NAME(IdentifiedModelArg, "Union[IdentifiedModel, str]")
PEGASUS_TYPED_OBJECT_NAME(HeliModelArg, "Union[Aircraft, Quadrotor, LearnedHeliModel]")
PEGASUS_TYPED_OBJECT_NAME(FlightLogsArg, "Union[FlightLog, Sequence[FlightLog]]")
PEGASUS_TYPED_OBJECT_NAME(CheckpointCallbackArg, "Optional[Callable[[dict], None]]")
PEGASUS_TYPED_OBJECT_NAME(CheckpointArg, "dict")
PEGASUS_TYPED_OBJECT_NAME(OptionalCheckpointArg, "Optional[dict]")
PEGASUS_TYPED_OBJECT_NAME(IterationCallbacksArg, "Optional[Sequence[IterationCallback]]")
PEGASUS_TYPED_OBJECT_NAME(ObjectiveFunctionArg, "Callable[[Array], float]")
PEGASUS_TYPED_OBJECT_NAME(JsonObject, "dict")
PEGASUS_TYPED_OBJECT_NAME(HeliPolicyArg, "Optional[HeliPolicy]")
PEGASUS_TYPED_OBJECT_NAME(UserObjectArg, "Any")
PEGASUS_TYPED_OBJECT_NAME(PathArg, "Union[str, os.PathLike]")

#undef PEGASUS_TYPED_OBJECT_NAME

}  // namespace pybind11::detail
