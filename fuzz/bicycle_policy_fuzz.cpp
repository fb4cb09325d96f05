// libFuzzer harness: bicycle policy files (experiments/bicycle_experiment: bicycle_policy_from_json), the
// input of `bicycle ride`.
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::read_bicycle_policy(file); }, pegasus::kMaxDataFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("fuzz.json", [&] {
    (void)pegasus::bicycle_policy_from_json(pegasus::parse_json_input(text, "fuzz.json", "bicycle policy"),
                                            "fuzz.json");
  });
  return 0;
}
