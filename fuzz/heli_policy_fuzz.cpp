// libFuzzer harness: helicopter policy files (heli/policy_file: the common fields, then the class's own
// through the registry, the manoeuvre class registered as the CLI registers it), the input of `heli fly`,
// `heli control` and `heli maneuver`.
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/heli/maneuver_file.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool registered = [] {
    pegasus::heli::register_policy_class("maneuver", pegasus::heli::make_maneuver_controller);
    return true;
  }();
  (void)registered;
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::heli::read_policy_file(file); },
      pegasus::kMaxDataFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("fuzz.json", [&] {
    const pegasus::heli::PolicyFile policy =
        pegasus::heli::parse_policy_file(pegasus::parse_json_input(text, "fuzz.json", "policy"), "fuzz.json");
    (void)pegasus::heli::make_controller(policy, "fuzz.json");
  });
  return 0;
}
