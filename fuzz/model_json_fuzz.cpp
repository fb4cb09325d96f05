// libFuzzer harness: identified helicopter models (sysid/identify: IdentifiedModel::from_json), the
// model.json that `heli identify` writes and `heli hover` / `heli maneuver` read.
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/sysid/identify.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::sysid::IdentifiedModel::load(file); },
      pegasus::kMaxDataFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("model.json", [&] {
    (void)pegasus::sysid::IdentifiedModel::from_json(pegasus::parse_json_input(text, "model.json", "model"));
  });
  return 0;
}
