#include "pegasus/runs/optimizer_config.hpp"

#include <fmt/format.h>

#include <cstdint>
#include <limits>
#include <string_view>
#include <type_traits>

namespace pegasus {
namespace {

// The field `name` of method section `section` under `prefix`: "optimizer.hill_climbing.max_step".
std::string field_name(const std::string& prefix, std::string_view section, const char* name) {
  return fmt::format("{}.{}.{}", prefix, section, name);
}

// Declares one method's fields with the values of `values` (its defaults).
template <class Options>
struct Declarer {
  ConfigSchema& schema;
  const std::string& prefix;
  const Options& values;
  std::string name(const char* field) const { return field_name(prefix, Options::kMethod.section, field); }

  template <class Int>
  void integer(const char* field, Int Options::*member, const char* help, double lo,
               double hi = static_cast<double>(std::numeric_limits<Int>::max())) {
    auto& f = schema.add_int(name(field), values.*member, help);
    // A 64-bit field's only upper bound is its type's, which the schema's integers already have.
    if (std::is_same_v<Int, std::int64_t> && hi == static_cast<double>(std::numeric_limits<Int>::max())) {
      f.min(lo);
    } else {
      f.range(lo, hi);
    }
  }
  void real(const char* field, double Options::*member, const char* help, double lo, double hi,
            bool exclusive_lo = false) {
    auto& f = schema.add_double(name(field), values.*member, help);
    if (exclusive_lo) {
      f.greater_than(lo);
    } else {
      f.min(lo);
    }
    // Finite: an infinite step or tolerance is never what was meant, and would be refused later under
    // another name.
    if (hi == kNoUpperLimit) {
      f.less_than(kNoUpperLimit);
    } else {
      f.max(hi);
    }
  }
  // Seeds come from the run's --seed, not from the section.
  template <class T>
  void internal(const char*, T Options::*, const char*) {}
};

// Reads one method's fields back into `values`.
template <class Options>
struct Reader {
  const ConfigSchema& schema;
  const std::string& prefix;
  Options& values;
  std::string name(const char* field) const { return field_name(prefix, Options::kMethod.section, field); }

  template <class Int>
  void integer(const char* field, Int Options::*member, const char*, double, double = 0) {
    values.*member = static_cast<Int>(schema.get_int(name(field)));
  }
  void real(const char* field, double Options::*member, const char*, double, double, bool = false) {
    values.*member = schema.get_double(name(field));
  }
  template <class T>
  void internal(const char*, T Options::*, const char*) {}
};

}  // namespace

std::vector<std::string> continuous_class_methods(bool finite_bounds) {
  std::vector<std::string> methods;
  ForEachOptimizerMethod([&](auto member) {
    const OptimizerMethodInfo& info = OptimizerMethodOptions<decltype(member)>::kMethod;
    if (info.integer_parameters) return;
    for (const std::string_view name : info.method_names)
      if (!name.empty() && (finite_bounds || !info.needs_finite_bounds(name))) methods.emplace_back(name);
  });
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
  // Every method's options, also those of methods the command does not offer: a resolved config.toml lists
  // them all, and stays a valid input (and --resume) for every command.
  ForEachOptimizerMethod([&](auto member) {
    using Options = OptimizerMethodOptions<decltype(member)>;
    Declarer<Options> declarer{schema, prefix, defaults.*member};
    Options::VisitFields(declarer);
  });
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
  ForEachOptimizerMethod([&](auto member) {
    using Options = OptimizerMethodOptions<decltype(member)>;
    Reader<Options> reader{schema, prefix, options->*member};
    Options::VisitFields(reader);
  });
}

}  // namespace pegasus
