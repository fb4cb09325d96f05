// The compiled half of `import pegasus` (python/pegasus/__init__.py re-exports it).
#include <nlohmann/json.hpp>
#include <system_error>

#include "common.hpp"
#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/parallel/interrupt.hpp"

PYBIND11_MODULE(_pegasus, m) {
  namespace py = pybind11;
  m.doc() =
      "Pegasus: PEGASUS policy search and reward shaping (the compiled extension; use `import pegasus`).";
  // Bad input found by the library (InputError) is a ValueError on this side, with the library's message.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pegasus::Interrupted&) {
      // Ctrl-C stopped the call (ReleaseGilInterruptibly re-raised the signal for the interpreter): its own
      // handler raises KeyboardInterrupt, or whatever the program set it to do.
      if (PyErr_CheckSignals() == 0) PyErr_SetNone(PyExc_KeyboardInterrupt);
    } catch (const pegasus::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const nlohmann::json::exception& e) {
      // A JSON value of the wrong type deep in a checkpoint or file the caller gave: bad input too.
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const pegasus::EnvironmentError& e) {
      // The machine refused (a full disk, a missing permission): what Python calls an OSError.
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const std::system_error& e) {  // std::filesystem::filesystem_error among them
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });
  pegasus::python::bind_scenarios(m);
  pegasus::python::bind_optimizers(m);
  pegasus::python::bind_training(m);
  pegasus::python::bind_vectorized(m);
  // Before the environments: corner_gridworld_mdp's signature then names the Python class FiniteMdp.
  pegasus::python::bind_mdp(m);
  pegasus::python::bind_envs(m);
  pegasus::python::bind_sysid(m);
  pegasus::python::bind_heli(m);
  pegasus::python::bind_quadrotor(m);
  pegasus::python::bind_pipeline(m);
}
