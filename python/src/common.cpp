#include "common.hpp"

#include <fmt/format.h>

#include <cmath>
#include <mutex>

#include "pegasus/parallel/interrupt.hpp"

namespace pegasus::python {

namespace {

std::mutex g_interruptible_mutex;
int g_interruptible_depth = 0;  // calls inside a ReleaseGilInterruptibly, on any thread

extern "C" void request_interrupt_on_signal(int) { request_interrupt(); }

}  // namespace

ReleaseGilInterruptibly::ReleaseGilInterruptibly() {
  const std::lock_guard lock(g_interruptible_mutex);
  if (g_interruptible_depth++ > 0) return;
  clear_interrupt();
  struct sigaction ours {};
  ours.sa_handler = request_interrupt_on_signal;
  sigemptyset(&ours.sa_mask);
  if (::sigaction(SIGINT, nullptr, &previous_) != 0 || previous_.sa_handler == SIG_IGN) return;
  installed_ = ::sigaction(SIGINT, &ours, nullptr) == 0;
}

ReleaseGilInterruptibly::~ReleaseGilInterruptibly() {
  const std::lock_guard lock(g_interruptible_mutex);
  --g_interruptible_depth;
  if (!installed_) return;
  ::sigaction(SIGINT, &previous_, nullptr);
  // A Ctrl-C during the call goes to the interpreter's handler now, as if it had come after: the
  // KeyboardInterrupt of an Interrupted call, or of a call that ended before a pool looked.
  if (interrupt_requested()) {
    clear_interrupt();
    ::raise(SIGINT);
  }
}

namespace {
std::string shape_of(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}
std::string dim_text(py::ssize_t n) { return n < 0 ? "any" : std::to_string(n); }
}  // namespace

Array as_array(py::handle object, const std::string& name) {
  if (object.is_none()) throw py::value_error(name + ": expected an array of real numbers, got None");
  py::array a;
  try {
    a = py::array::ensure(object);
  } catch (const py::error_already_set&) {
    a = py::array();
  }
  if (!a) throw py::value_error(name + ": expected an array of real numbers");
  const char kind = a.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f')
    throw py::value_error(fmt::format("{}: expected an array of real numbers, got dtype {}", name,
                                      py::str(a.dtype()).cast<std::string>()));
  return Array::ensure(a);
}

Array as_matrix(py::handle object, const std::string& name, py::ssize_t rows, py::ssize_t cols) {
  Array a = as_array(object, name);
  if (a.ndim() != 2 || (rows >= 0 && a.shape(0) != rows) || (cols >= 0 && a.shape(1) != cols))
    throw py::value_error(fmt::format("{}: expected a 2-D array of shape ({}, {}), got shape {}", name,
                                      dim_text(rows), dim_text(cols), shape_of(a)));
  return a;
}

Array as_vector(py::handle object, const std::string& name, py::ssize_t size) {
  Array a = as_array(object, name);
  if (a.ndim() != 1 || (size >= 0 && a.shape(0) != size))
    throw py::value_error(fmt::format("{}: expected a 1-D array of length {}, got shape {}", name,
                                      dim_text(size), shape_of(a)));
  return a;
}

void require_finite(const Array& array, const std::string& name) {
  const double* x = array.data();
  for (py::ssize_t k = 0; k < array.size(); ++k)
    if (!std::isfinite(x[k]))
      throw py::value_error(
          fmt::format("{}: expected finite numbers, got {} at flat index {}", name, x[k], k));
}

Theta as_theta(py::handle object, const std::string& name, const ParameterSpec& spec) {
  const Array a = as_vector(object, name, static_cast<py::ssize_t>(spec.size()));
  require_finite(a, name);
  Theta theta(a.data(), a.data() + a.size());
  if (const std::string why = spec.integer_violation(theta); !why.empty())
    throw py::value_error(name + ": " + why);
  return theta;
}

std::vector<Theta> as_thetas(py::handle object, const std::string& name, const ParameterSpec& spec) {
  const auto n = static_cast<py::ssize_t>(spec.size());
  Array a = as_array(object, name);
  if (a.ndim() == 1) return {as_theta(a, name, spec)};
  a = as_matrix(a, name, -1, n);
  require_finite(a, name);
  std::vector<Theta> thetas;
  for (py::ssize_t k = 0; k < a.shape(0); ++k) {
    thetas.emplace_back(a.data() + k * n, a.data() + (k + 1) * n);
    if (const std::string why = spec.integer_violation(thetas.back()); !why.empty())
      throw py::value_error(fmt::format("{}[{}]: {}", name, k, why));
  }
  return thetas;
}

std::uint64_t as_unsigned(py::handle object, const std::string& name, int bits) {
  const std::string expected = fmt::format("{}: expected an integer in [0, 2**{})", name, bits);
  if (!py::isinstance<py::int_>(object) || py::isinstance<py::bool_>(object)) throw py::value_error(expected);
  const py::int_ value = py::reinterpret_borrow<py::int_>(object);
  if (value < py::int_(0) || value >= py::int_(1).attr("__lshift__")(bits))
    throw py::value_error(expected + ", got " + py::repr(object).cast<std::string>());
  return value.cast<std::uint64_t>();
}

std::uint64_t as_seed(py::handle object, const std::string& name) { return as_unsigned(object, name, 64); }

Array matrix(py::ssize_t rows, py::ssize_t cols) { return Array({rows, cols}); }

Array vector_array(std::span<const double> values) {
  Array a(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

// A Python object kept alive by C++ copies that may be made and dropped without the GIL: the reference is
// released under the GIL.
std::shared_ptr<py::object> hold(py::object object) {
  return std::shared_ptr<py::object>(new py::object(std::move(object)), [](py::object* o) {
    py::gil_scoped_acquire gil;
    delete o;
  });
}

CheckpointCallback checkpoint_callback(py::object callback) {
  if (callback.is_none()) return {};
  if (!PyCallable_Check(callback.ptr())) throw py::value_error("on_checkpoint: expected a callable or None");
  auto held = hold(std::move(callback));
  return [held](const nlohmann::json& state) {
    py::gil_scoped_acquire gil;
    (*held)(to_python(state));
  };
}

IterationCallbackList::IterationCallbackList(py::handle callbacks) : pointers_{&interrupt_check_} {
  if (callbacks.is_none()) return;
  if (!py::isinstance<py::sequence>(callbacks) || py::isinstance<py::str>(callbacks))
    throw py::value_error("callbacks: expected a list of callables");
  std::size_t k = 0;
  for (py::handle f : callbacks) {
    if (!PyCallable_Check(f.ptr()))
      throw py::value_error(fmt::format("callbacks[{}]: expected a callable", k));
    owned_.push_back(std::make_unique<Adapter>(hold(py::reinterpret_borrow<py::object>(f))));
    pointers_.push_back(owned_.back().get());
    ++k;
  }
}

CallbackReturnType IterationCallbackList::InterruptCheck::operator()(const IterationReport&) {
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() != 0) throw py::error_already_set();
  return CallbackReturnType::kContinue;
}

CallbackReturnType IterationCallbackList::Adapter::operator()(const IterationReport& report) {
  py::gil_scoped_acquire gil;
  IterationReportCopy copy{std::string(report.method), report.record,
                           Theta(report.best_theta.begin(), report.best_theta.end())};
  const py::object answer = (*f_)(std::move(copy));
  if (answer.is_none()) return CallbackReturnType::kContinue;
  if (py::isinstance<CallbackReturnType>(answer)) return answer.cast<CallbackReturnType>();
  if (py::isinstance<py::bool_>(answer))
    return answer.cast<bool>() ? CallbackReturnType::kTerminate : CallbackReturnType::kContinue;
  throw py::value_error(
      "callbacks: expected a callback to return None, a bool (True: stop) or a CallbackReturnType");
}

py::object to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

nlohmann::json from_python(py::handle object, const std::string& name) {
  std::string text;
  try {
    // allow_nan=False: JSON has no NaN or infinity, and nlohmann's parser would refuse Python's spelling of
    // them.
    text =
        py::module_::import("json").attr("dumps")(object, py::arg("allow_nan") = false).cast<std::string>();
  } catch (const py::error_already_set& e) {
    throw py::value_error(name + ": expected JSON-serialisable data (" + std::string(e.what()) + ")");
  }
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw py::value_error(name + ": " + e.what());
  }
}

}  // namespace pegasus::python
