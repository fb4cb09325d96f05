// libFuzzer harness: TOML configuration files (runs/config: ConfigSchema::load_toml_string).
// Beyond the error contract: a configuration that loads is written back (to_toml, as config.toml of every
// run) and must load again to the same values (issue 16: a stored config.toml could not be reloaded).
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/runs/config.hpp"

namespace {

// A schema with every field type, bounds, choices, sections and a cross-field constraint, like the
// commands' own.
pegasus::ConfigSchema make_schema() {
  pegasus::ConfigSchema s;
  s.add_int("scenarios", 30, "scenarios").min(1).max(1000000);
  s.add_double("gamma", 0.99, "discount").range(0, 1);
  s.add_double("epsilon", 0.01, "error").greater_than(0);
  s.add_bool("antithetic", false, "pairs");
  s.add_string("policy", "", "a path");
  s.add_string("method", "gradient", "method").choices({"gradient", "hill-climb"});
  s.add_int_list("sizes", {1, 2, 4}, "sizes").min(1).min_size(1);
  s.add_double_list("target", {0, 0, -10, 0}, "set point");
  s.add_string_list("logs", {}, "paths");
  s.add_double("reward.position_m", 0.5, "scale").min(1e-150);
  s.add_int("optimizer.iterations", 20, "iterations").min(0);
  s.add_constraint([](const pegasus::ConfigSchema& c) -> std::string {
    return c.get_int("optimizer.iterations") <= c.get_int("scenarios") * 1000
               ? std::string()
               : "optimizer.iterations: too many";
  });
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) {
        pegasus::ConfigSchema schema;
        schema.load_toml_file(file);
      },
      pegasus::kMaxSettingsFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::ConfigSchema schema = make_schema();
  const bool loaded = pegasus::fuzz::keeps_error_contract("fuzz.toml", [&] {
    schema.load_toml_string(text, "fuzz.toml");
    schema.validate();
  });
  if (!loaded) return 0;
  const std::string stored = schema.to_toml();
  pegasus::ConfigSchema again = make_schema();
  try {
    again.load_toml_string(stored, "config.toml");
  } catch (const std::exception& e) {
    pegasus::fuzz::violation("a written config.toml that does not load again", e.what());
  }
  if (const auto key = schema.first_difference(again))
    pegasus::fuzz::violation("config.toml reloads to a different value of", *key);
  return 0;
}
