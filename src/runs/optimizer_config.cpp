#include "pegasus/runs/optimizer_config.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <limits>

namespace pegasus {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Every option of every method, listed once; a Visitor either declares the fields or reads them back.
// Ranges here are the per-field ones of each Options::IsValid; the cross-field rules stay in IsValid.
template <class Visitor>
void visit_optimizer_fields(Visitor& v, OptimizerOptions& o) {
  auto& g = o.gradient;
  v.integer("gradient.max_iterations", g.max_iterations, "gradient ascent: iterations at most", 0);
  v.integer("gradient.max_evaluations", g.max_evaluations, "gradient ascent: U-hat evaluations at most", 1);
  v.real("gradient.relative_step", g.relative_step,
         "gradient ascent: central-difference half-width, in parameter scales", 0, kInf, true);
  v.real("gradient.initial_step", g.initial_step, "gradient ascent: first step length, in parameter scales",
         0, kInf, true);
  v.real("gradient.max_step", g.max_step, "gradient ascent: longest step, in parameter scales (thesis 4.6)",
         0, kInf, true);
  v.real("gradient.min_step", g.min_step,
         "gradient ascent: stop when backtracking shrinks the step below this", 0, kInf);
  v.real("gradient.step_growth", g.step_growth, "gradient ascent: step factor after an accepted step", 1,
         kInf);
  v.integer32("gradient.max_backtracks", g.max_backtracks,
              "gradient ascent: step halvings tried before an iteration gives up", 0);
  v.real("gradient.function_tolerance", g.function_tolerance,
         "gradient ascent: stop when a step improves U-hat by at most this fraction", 0, kInf);

  auto& h = o.hill_climbing;
  v.integer("hill_climbing.max_iterations", h.max_iterations, "hill climbing: iterations at most", 0);
  v.integer("hill_climbing.max_evaluations", h.max_evaluations, "hill climbing: U-hat evaluations at most",
            1);
  v.integer32("hill_climbing.proposals_per_iteration", h.proposals_per_iteration,
              "hill climbing: proposals per iteration (evaluated in parallel)", 1, kMaxPointsPerIteration);
  v.real("hill_climbing.initial_step", h.initial_step,
         "hill climbing: first perturbation size, in parameter scales", 0, kInf, true);
  v.real("hill_climbing.max_step", h.max_step, "hill climbing: largest perturbation, in parameter scales", 0,
         kInf, true);
  v.real("hill_climbing.min_step", h.min_step, "hill climbing: stop when the step shrinks below this", 0,
         kInf);
  v.real("hill_climbing.step_growth", h.step_growth, "hill climbing: step factor after an improvement", 1,
         kInf);
  v.real("hill_climbing.step_shrink", h.step_shrink,
         "hill climbing: step factor after an iteration without one", 0, 1, true);

  auto& n = o.nlopt;
  v.integer("nlopt.max_evaluations", n.max_evaluations,
            "bobyqa, sbplx, crs2, esch: U-hat evaluations at most", 1);
  v.real("nlopt.initial_step", n.initial_step, "bobyqa, sbplx: initial step, in parameter scales", 0, kInf,
         true);
  v.real("nlopt.x_tolerance", n.x_tolerance,
         "NLopt methods: stop when a step moves every parameter less (0: off)", 0, kInf);
  v.real("nlopt.function_tolerance", n.function_tolerance,
         "NLopt methods: stop when a step changes U-hat by a smaller fraction (0: off)", 0, kInf);
  v.integer32("nlopt.population", n.population, "crs2, esch: population size (0: NLopt's default)", 0,
              kMaxPointsPerIteration);

  auto& c = o.cmaes;
  v.integer("cmaes.max_iterations", c.max_iterations, "CMA-ES: generations at most", 0);
  v.integer("cmaes.max_evaluations", c.max_evaluations, "CMA-ES: U-hat evaluations at most", 1);
  v.integer32("cmaes.population_size", c.population_size,
              "CMA-ES: samples per generation (0: 4 + floor(3 ln n), Hansen's default)", 0,
              kMaxPointsPerIteration);
  v.real("cmaes.initial_step", c.initial_step, "CMA-ES: first sigma, in parameter scales", 0, kInf, true);
  v.real("cmaes.x_tolerance", c.x_tolerance, "CMA-ES: stop when every step is below this, in scales (0: off)",
         0, kInf);
  v.real("cmaes.function_tolerance", c.function_tolerance,
         "CMA-ES: stop when recent best U-hats differ by less than this (0: off)", 0, kInf);
  v.real("cmaes.max_condition", c.max_condition,
         "CMA-ES: fail when the covariance's condition number passes this", 1, kInf);
  v.integer(
      "cmaes.stall_generations", c.stall_generations,
      "CMA-ES: a run stops when its best U-hat rose by at most stall_tolerance over this many generations "
      "(0: off)",
      0);
  v.real("cmaes.stall_tolerance", c.stall_tolerance, "CMA-ES: see stall_generations", 0, kInf);
  v.integer32(
      "cmaes.restarts", c.restarts,
      "CMA-ES: runs after the first (IPOP): each starts again from the start with twice the population", 0,
      kCmaesMaxRestarts);

  auto& a = o.ars;
  v.integer("ars.max_iterations", a.max_iterations, "ARS: iterations at most", 0);
  v.integer("ars.max_evaluations", a.max_evaluations, "ARS: U-hat evaluations at most", 1);
  v.integer32("ars.directions", a.directions, "ARS: random directions per iteration (each evaluated +-)", 1,
              kMaxPointsPerIteration);
  v.integer32("ars.top_directions", a.top_directions, "ARS: best directions that move theta (b)", 1);
  v.real("ars.step_size", a.step_size, "ARS: step size alpha, in parameter scales", 0, kInf, true);
  v.real("ars.exploration_noise", a.exploration_noise, "ARS: direction size nu, in parameter scales", 0, kInf,
         true);

  auto& e = o.exhaustive;
  v.integer("exhaustive.max_policies", e.max_policies, "exhaustive search: refuse a larger policy class", 1);
  v.integer("exhaustive.block_size", e.block_size, "exhaustive search: policies per parallel batch", 1);
}

std::string field_name(const std::string& prefix, const char* name) { return prefix + "." + name; }

struct Declarer {
  ConfigSchema& schema;
  const std::string& prefix;
  void integer(const char* name, std::int64_t& value, const char* help, double lo) {
    schema.add_int(field_name(prefix, name), value, help).min(lo);
  }
  void integer32(const char* name, int& value, const char* help, double lo,
                 double hi = std::numeric_limits<int>::max()) {
    schema.add_int(field_name(prefix, name), value, help).range(lo, hi);
  }
  void real(const char* name, double& value, const char* help, double lo, double hi,
            bool exclusive_lo = false) {
    auto& f = schema.add_double(field_name(prefix, name), value, help);
    if (exclusive_lo) {
      f.greater_than(lo);
    } else {
      f.min(lo);
    }
    // Finite: an infinite step or tolerance is never what was meant, and would be refused later under
    // another name.
    if (hi == kInf) {
      f.less_than(kInf);
    } else {
      f.max(hi);
    }
  }
};

struct Reader {
  const ConfigSchema& schema;
  const std::string& prefix;
  void integer(const char* name, std::int64_t& value, const char*, double) {
    value = schema.get_int(field_name(prefix, name));
  }
  void integer32(const char* name, int& value, const char*, double, double = 0) {
    value = static_cast<int>(schema.get_int(field_name(prefix, name)));
  }
  void real(const char* name, double& value, const char*, double, double, bool = false) {
    value = schema.get_double(field_name(prefix, name));
  }
};

}  // namespace

std::vector<std::string> continuous_class_methods(bool finite_bounds) {
  std::vector<std::string> methods;
  for (const std::string_view name : OptimizerMethodNames())
    if (name != "exhaustive" && (finite_bounds || (name != "crs2" && name != "esch")))
      methods.emplace_back(name);
  return methods;
}

void declare_optimizer_options(ConfigSchema& schema, const std::string& prefix,
                               const OptimizerOptions& defaults, std::vector<std::string> methods,
                               bool allow_none) {
  if (methods.empty())
    for (auto name : OptimizerMethodNames()) methods.emplace_back(name);
  if (allow_none) methods.emplace_back("none");
  schema
      .add_string(
          prefix + ".method", defaults.method,
          "optimizer: " +
              [&] {
                std::string list;
                for (const auto& m : methods) list += (list.empty() ? "" : ", ") + m;
                return list;
              }())
      .choices(methods);
  OptimizerOptions values = defaults;
  Declarer declarer{schema, prefix};
  visit_optimizer_fields(declarer, values);
  schema.add_constraint([prefix](const ConfigSchema& s) -> std::string {
    OptimizerOptions options;
    read_optimizer_options(s, prefix, &options);
    if (options.method == "none") return {};
    std::string error;
    if (options.IsValid(&error)) return {};
    // IsValid names "<method section>.<field>: expected ..."; say where the offending value came from, as
    // the user wrote it (the option or file:line), like every other value's message. A cross-field rule
    // broken by a value the user gave (initial_step below the default min_step) is reported under that value.
    const std::string section = error.substr(0, error.find('.'));
    std::string field = prefix + "." + error.substr(0, error.find(':'));
    if (s.has(field) && s.origin(field) == "default") {
      for (const ConfigField& f : s.fields()) {
        const std::string& name = f.name();
        if (name.rfind(prefix + "." + section + ".", 0) != 0 || s.origin(name) == "default") continue;
        if (error.find(name.substr(name.rfind('.') + 1)) != std::string::npos) {
          const std::string& where = s.origin(name);
          const std::string shown = where.rfind("--", 0) == 0 ? ConfigSchema::option_name(name) : where;
          return fmt::format("{}: {} breaks {}.{}", shown, ConfigSchema::format_value(s.value(name)), prefix,
                             error);
        }
      }
    }
    const std::string& where = s.origin(s.has(field) ? field : prefix + ".method");
    const std::string name = where.rfind("--", 0) == 0 ? ConfigSchema::option_name(field) : field;
    const std::string message = name + error.substr(error.find(':'));
    return where == "default" || where.rfind("--", 0) == 0 ? message : where + ": " + message;
  });
}

void read_optimizer_options(const ConfigSchema& schema, const std::string& prefix,
                            OptimizerOptions* options) {
  options->method = schema.get_string(prefix + ".method");
  Reader reader{schema, prefix};
  visit_optimizer_fields(reader, *options);
}

}  // namespace pegasus
