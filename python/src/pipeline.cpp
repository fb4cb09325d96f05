// pegasus.pipeline: `pegasus heli pipeline` (`pegasus pipeline --vehicle V.toml` with a vehicle) run in this
// process by the command table's own code (include/pegasus/cli/command.hpp: call_command), its summary.json
// returned as a dict.
#include <fmt/format.h>

#include <cstdint>
#include <iostream>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include "common.hpp"
#include "pegasus/cli/command.hpp"
#include "pegasus/io/atomic_file.hpp"

namespace pegasus::python {

namespace {

// A keyword's value as a config field takes it: a bool, an int, a float, a str, or a list of one of them.
FieldValue setting_value(const std::string& name, py::handle value) {
  const auto refuse = [&] {
    return py::value_error(
        fmt::format("{}: expected a number, a bool, a string or a list of one of them, got {}", name,
                    py::repr(value).cast<std::string>()));
  };
  try {
    if (py::isinstance<py::bool_>(value)) return value.cast<bool>();
    if (py::isinstance<py::int_>(value)) return value.cast<std::int64_t>();
    if (py::isinstance<py::float_>(value)) return value.cast<double>();
    if (py::isinstance<py::str>(value)) return value.cast<std::string>();
    if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value)) throw refuse();
    const auto items = value.cast<py::sequence>();
    bool all_int = true, all_number = true, all_str = true;
    for (py::handle item : items) {
      const bool is_int = py::isinstance<py::int_>(item) && !py::isinstance<py::bool_>(item);
      all_int = all_int && is_int;
      all_number = all_number && (is_int || py::isinstance<py::float_>(item));
      all_str = all_str && py::isinstance<py::str>(item);
    }
    if (all_int) return value.cast<std::vector<std::int64_t>>();  // an empty list too
    if (all_number) return value.cast<std::vector<double>>();
    if (all_str) return value.cast<std::vector<std::string>>();
  } catch (const py::cast_error&) {  // an int beyond 64 bits
  }
  throw refuse();
}

}  // namespace

void bind_pipeline(py::module_& m) {
  m.def(
      "pipeline",
      [](const PathArg& out, const std::optional<std::string>& vehicle, std::int64_t seed,
         std::int64_t threads, bool force, bool resume, bool quiet, const py::kwargs& settings) {
        const auto dir = py::module_::import("os").attr("fspath")(out).cast<std::string>();
        std::vector<std::pair<std::string, FieldValue>> values = {{"seed", seed}, {"threads", threads}};
        if (vehicle) values.emplace_back("vehicle", *vehicle);
        for (const auto& [key, value] : settings) {
          const auto name = key.cast<std::string>();
          values.emplace_back(name, setting_value(name, value));
        }
        cli::NullStream nowhere;
        {
          ReleaseGilInterruptibly release;
          cli::call_command(vehicle ? "pipeline" : "heli pipeline", values, dir,
                            {.force = force, .resume = resume, .quiet = quiet}, quiet ? nowhere : std::cout,
                            std::cerr);
        }
        return JsonObject(py::module_::import("json").attr("loads")(read_file(dir + "/summary.json")));
      },
      py::arg("out"), py::arg("vehicle") = py::none(), py::arg("seed") = 1, py::arg("threads") = 2,
      py::arg("force") = false, py::arg("resume") = false, py::arg("quiet") = true, R"doc(
The whole helicopter chain (pilot logs, identification, hover training, flights against the pilot) into the
run directory `out`, as `pegasus heli pipeline --out OUT` does (`pegasus pipeline --vehicle V.toml` with a
vehicle file), by the same code in this process: the same files, summary.json byte for byte. `settings` are
the pipeline's fields by their TOML names (train_seconds=60, scenarios=2; see `pegasus heli pipeline
--help`). force and resume are --force and --resume; quiet: no progress bars and no printed lines (run.json
keeps them). Returns summary.json as a dict. Bad input raises ValueError naming the setting, and leaves no
directory behind; the working directory is never changed.)doc");
}

}  // namespace pegasus::python
