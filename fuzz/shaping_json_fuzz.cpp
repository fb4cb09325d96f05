// libFuzzer harness: shaping tables (shaping/shaping_table: shaping_from_json), the --shaping of the
// shaping commands.
#include "fuzz_contract.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/shaping/shaping_table.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("fuzz.json", [&] {
    (void)pegasus::shaping_from_json(pegasus::parse_json_input(text, "fuzz.json", "shaping"), "fuzz.json");
  });
  return 0;
}
