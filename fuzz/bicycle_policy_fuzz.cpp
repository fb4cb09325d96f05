// libFuzzer harness: bicycle policy files (experiments/bicycle_experiment: bicycle_policy_from_json), the
// input of `bicycle ride`.
#include "fuzz_contract.hpp"
#include "pegasus/experiments/bicycle_experiment.hpp"
#include "pegasus/io/json_input.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("fuzz.json", [&] {
    (void)pegasus::bicycle_policy_from_json(pegasus::parse_json_input(text, "fuzz.json", "bicycle policy"),
                                            "fuzz.json");
  });
  return 0;
}
