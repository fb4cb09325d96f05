#pragma once
// Shared pieces of the Python bindings: numpy arrays checked where they enter (shape, dtype, finiteness), so
// that a wrong argument raises ValueError naming it and the expected form instead of reaching the library.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <signal.h>

#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "pegasus/optimizers/run_progress.hpp"
#include "pegasus/policies/parameter_spec.hpp"
#include "typed_objects.hpp"

namespace pegasus::python {

namespace py = pybind11;

// Releases the GIL for a long call into the library and lets Ctrl-C stop it (issue 51): while it lives,
// SIGINT requests an interrupt (parallel/interrupt.hpp) instead of waiting for the interpreter, which cannot
// run its handler until the call returns; the pools then stop within one work item and throw Interrupted,
// which the module raises as KeyboardInterrupt. The interpreter's handler is back when it ends. Use it in
// place of py::gil_scoped_release around library work.
class ReleaseGilInterruptibly {
 public:
  ReleaseGilInterruptibly();
  ~ReleaseGilInterruptibly();
  ReleaseGilInterruptibly(const ReleaseGilInterruptibly&) = delete;
  ReleaseGilInterruptibly& operator=(const ReleaseGilInterruptibly&) = delete;

 private:
  bool installed_ = false;  // only the outermost of nested ones, on the main thread, takes SIGINT
  struct sigaction previous_ {};
  py::gil_scoped_release release_;
};

// A C-contiguous float64 array (a copy when the argument was another dtype or not contiguous).
using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Any array-like of booleans, integers or reals as float64; ValueError naming `name` otherwise.
Array as_array(py::handle object, const std::string& name);
// A 2-D array; rows or cols of -1 accept any size.
Array as_matrix(py::handle object, const std::string& name, py::ssize_t rows, py::ssize_t cols);
// A 1-D array; size -1 accepts any size.
Array as_vector(py::handle object, const std::string& name, py::ssize_t size);
// ValueError naming `name` and the first non-finite entry.
void require_finite(const Array& array, const std::string& name);
// A finite theta of spec.size() entries.
Theta as_theta(py::handle object, const std::string& name, const ParameterSpec& spec);
// A finite [K, spec.size()] batch of thetas (a 1-D theta is a batch of one).
std::vector<Theta> as_thetas(py::handle object, const std::string& name, const ParameterSpec& spec);

// A seed: a Python int in [0, 2^64).
std::uint64_t as_seed(py::handle object, const std::string& name);
// A Python int in [0, 2**bits) (bits <= 64), else ValueError naming `name` and the range.
std::uint64_t as_unsigned(py::handle object, const std::string& name, int bits);

Array matrix(py::ssize_t rows, py::ssize_t cols);
Array vector_array(std::span<const double> values);

// JSON across the boundary through Python's json module (doubles round-trip exactly both ways).
py::object to_python(const nlohmann::json& j);
nlohmann::json from_python(py::handle object, const std::string& name);

// A Python object kept alive by C++ copies that may be made and dropped without the GIL: the reference is
// released under the GIL.
std::shared_ptr<py::object> hold(py::object object);
// A Python callable (or None) as a CheckpointCallback that takes the GIL and passes the checkpoint as a dict.
CheckpointCallback checkpoint_callback(py::object callback);

// What a Python iteration callback receives: IterationReport with its best theta copied (the C++ span is
// valid during the call only).
struct IterationReportCopy {
  std::string method;
  IterationRecord record;
  Theta best_theta;
};

// Python callables f(IterationReport) -> None | bool | CallbackReturnType as the IterationCallbacks of one
// run (optimizers/run_progress.hpp): each call takes the GIL; True or TERMINATE stops the run
// (USER_REQUESTED). ValueError naming `callbacks[k]` for an entry that is not callable.
class IterationCallbackList {
 public:
  explicit IterationCallbackList(py::handle callbacks);
  IterationCallbackList(const IterationCallbackList&) = delete;  // pointers_ points into this object
  IterationCallbackList& operator=(const IterationCallbackList&) = delete;
  const IterationCallbacks& pointers() const { return pointers_; }

 private:
  class Adapter final : public IterationCallback {
   public:
    explicit Adapter(std::shared_ptr<py::object> f) : f_(std::move(f)) {}
    CallbackReturnType operator()(const IterationReport& report) override;

   private:
    std::shared_ptr<py::object> f_;
  };
  // Raises KeyboardInterrupt (or what a signal handler raised) in the C++ run: always the first callback, so
  // Ctrl-C stops any run within an iteration, as it would stop Python code.
  class InterruptCheck final : public IterationCallback {
   public:
    CallbackReturnType operator()(const IterationReport& report) override;
  };
  InterruptCheck interrupt_check_;
  std::vector<std::unique_ptr<Adapter>> owned_;
  IterationCallbacks pointers_;
};

// The noise sizes of every batch model (Aircraft, Quadrotor, LearnedHeliModel, Bicycle, Pendulum) and of
// ScenarioSet: one meaning (SimulativeModel, thesis §4.2.1), so one text.
inline constexpr const char* kNoiseDimDoc =
    "Uniforms per step: the width of each p_t of a scenario (all of a step's randomness).";
inline constexpr const char* kInitialNoiseDimDoc = "Uniforms that draw the initial state s0 of a scenario.";

// `.def("is_valid", is_valid_method<T>(), kIsValidDoc)`: options.is_valid() -> (ok, error) for a C++ type
// with IsValid(std::string*).
inline constexpr const char* kIsValidDoc =
    "(ok, error): whether these settings are valid, and when not, the first field that is not and what was "
    "expected of it (the message the functions taking them raise as ValueError).";
template <class T>
auto is_valid_method() {
  return [](const T& o) {
    std::string error;
    const bool ok = o.IsValid(&error);
    return std::pair<bool, std::string>(ok, error);  // typed: the signature says Tuple[bool, str]
  };
}

// Gives a bound class the dataclass-like attribute `_fields` (its field names, as the C++ struct's); the
// package adds __repr__, __eq__ and copy from it (python/pegasus/__init__.py).
template <class C>
void set_fields(C& c, const std::vector<std::string>& names) {
  py::tuple t(names.size());
  std::size_t k = 0;
  for (const std::string& n : names) t[k++] = py::str(n);
  c.attr("_fields") = t;
  using T = typename C::type;
  if constexpr (std::is_copy_constructible_v<T>) {
    c.def("__copy__", [](const T& x) { return T(x); });
    c.def(
        "__deepcopy__", [](const T& x, py::handle) { return T(x); }, py::arg("memo"));
  }
}
template <class C>
void set_fields(C& c, const std::vector<const char*>& names) {
  set_fields(c, std::vector<std::string>(names.begin(), names.end()));
}
template <class C>
void set_fields(C& c, std::initializer_list<const char*> names) {
  set_fields(c, std::vector<std::string>(names.begin(), names.end()));
}

void bind_scenarios(py::module_& m);
void bind_training(py::module_& m);
void bind_heli(py::module_& m);
void bind_quadrotor(py::module_& m);  // after bind_heli
void bind_optimizers(py::module_& m);
void bind_vectorized(py::module_& m);
void bind_envs(py::module_& m);
void bind_mdp(py::module_& m);
void bind_sysid(py::module_& m);
void bind_pipeline(py::module_& m);  // pegasus.pipeline (pipeline.cpp)

}  // namespace pegasus::python
