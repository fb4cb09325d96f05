// libFuzzer harness: shaping tables (shaping/shaping_table: shaping_from_json), the --shaping of the
// shaping commands.
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/shaping/shaping_table.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::load_shaping(file); }, pegasus::kMaxDataFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("fuzz.json", [&] {
    (void)pegasus::shaping_from_json(pegasus::parse_json_input(text, "fuzz.json", "shaping"), "fuzz.json");
  });
  return 0;
}
