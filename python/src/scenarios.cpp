// Scenario sets (thesis §4.4.2, §4.7) as numpy arrays: the same counter-based numbers the C++ evaluators use.
#include <fmt/format.h>

#include "common.hpp"
#include "pegasus/scenarios/scenario_set.hpp"

namespace pegasus::python {

namespace {
int checked_int(std::int64_t value, const char* name, std::int64_t lowest) {
  if (value < lowest || value > 100'000'000)
    throw py::value_error(
        fmt::format("{}: expected an integer in [{}, 100000000], got {}", name, lowest, value));
  return static_cast<int>(value);
}
}  // namespace

ScenarioSet make_scenario_set(SeedArg seed, std::int64_t count, std::int64_t horizon, std::int64_t noise_dim,
                              std::int64_t initial_noise_dim, const std::string& variant,
                              const char* count_name) {
  ScenarioOptions o;
  o.seed = as_seed(seed, "seed");
  o.count = checked_int(count, count_name, 1);
  o.horizon = checked_int(horizon, "horizon", 1);
  o.noise_dim = checked_int(noise_dim, "noise_dim", 0);
  o.initial_noise_dim = checked_int(initial_noise_dim, "initial_noise_dim", 0);
  o.variant = parse_scenario_variant(variant);
  return ScenarioSet(o);
}

void bind_scenarios(py::module_& m) {
  py::class_<ScenarioSet>(m, "ScenarioSet", R"doc(
m PEGASUS scenarios (thesis §4.4.2): scenario i is (s0 noise, p_1, ..., p_H), computed on demand by the
counter-based generator keyed by `seed`, so Python sees exactly the numbers the C++ evaluators use.
variant: "plain", "antithetic" (scenario 2k+1 uses 1-u), "stratified" (Latin hypercube initial noise) or
"sobol" (randomised quasi-Monte Carlo); all uniforms lie in the open interval (0, 1).)doc")
      .def(py::init([](SeedArg seed, std::int64_t count, std::int64_t horizon, std::int64_t noise_dim,
                       std::int64_t initial_noise_dim, const std::string& variant) {
             return make_scenario_set(std::move(seed), count, horizon, noise_dim, initial_noise_dim, variant,
                                      "count");
           }),
           py::arg("seed"), py::arg("count"), py::arg("horizon"), py::arg("noise_dim"),
           py::arg("initial_noise_dim") = 0, py::arg("variant") = "plain")
      .def_property_readonly("count", &ScenarioSet::size, "Number of scenarios m.")
      .def_property_readonly("horizon", &ScenarioSet::horizon, "Steps H whose noise each scenario holds.")
      .def_property_readonly("noise_dim", &ScenarioSet::noise_dim, kNoiseDimDoc)
      .def_property_readonly("initial_noise_dim", &ScenarioSet::initial_noise_dim, kInitialNoiseDimDoc)
      .def_property_readonly(
          "seed", [](const ScenarioSet& s) { return s.options().seed; },
          "The key of the counter-based generator, in [0, 2^64): every number of the set follows from it.")
      .def_property_readonly(
          "variant", [](const ScenarioSet& s) { return to_string(s.options().variant); },
          "\"plain\", \"antithetic\", \"stratified\" or \"sobol\".")
      .def(
          "initial_noise",
          [](const ScenarioSet& s) {
            Array out = matrix(s.size(), s.initial_noise_dim());
            const auto d = static_cast<std::size_t>(s.initial_noise_dim());
            for (int i = 0; i < s.size(); ++i)
              s.initial_noise(i, std::span<double>(out.mutable_data() + static_cast<std::size_t>(i) * d, d));
            return out;
          },
          "The uniforms that draw s0, shape (count, initial_noise_dim).")
      .def(
          "step_noise",
          [](const ScenarioSet& s) {
            const auto d = static_cast<std::size_t>(s.noise_dim());
            Array out({static_cast<py::ssize_t>(s.size()), static_cast<py::ssize_t>(s.horizon()),
                       static_cast<py::ssize_t>(d)});
            double* x = out.mutable_data();
            for (int i = 0; i < s.size(); ++i)
              for (int t = 0; t < s.horizon(); ++t, x += d) s.step_noise(i, t, std::span<double>(x, d));
            return out;
          },
          "The noise of every step, shape (count, horizon, noise_dim): [i, t] is p_{t+1} of scenario i.")
      .def("__repr__", [](const ScenarioSet& s) {
        return fmt::format(
            "ScenarioSet(seed={}, count={}, horizon={}, noise_dim={}, initial_noise_dim={}, "
            "variant='{}')",
            s.options().seed, s.size(), s.horizon(), s.noise_dim(), s.initial_noise_dim(),
            to_string(s.options().variant));
      });
}

}  // namespace pegasus::python
