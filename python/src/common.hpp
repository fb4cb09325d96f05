#pragma once
// Shared pieces of the Python bindings: numpy arrays checked where they enter (shape, dtype, finiteness), so
// that a wrong argument raises ValueError naming it and the expected form instead of reaching the library.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>
#include <string>

#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus::python {

namespace py = pybind11;

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

Array matrix(py::ssize_t rows, py::ssize_t cols);
Array vector_array(std::span<const double> values);

// JSON across the boundary through Python's json module (doubles round-trip exactly both ways).
py::object to_python(const nlohmann::json& j);
nlohmann::json from_python(py::handle object, const std::string& name);

void bind_scenarios(py::module_& m);
void bind_optimizers(py::module_& m);
void bind_vectorized(py::module_& m);
void bind_envs(py::module_& m);
void bind_mdp(py::module_& m);
void bind_sysid(py::module_& m);

}  // namespace pegasus::python
