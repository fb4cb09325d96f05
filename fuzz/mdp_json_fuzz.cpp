// libFuzzer harness: finite MDP files (mdp/mdp_json: mdp_from_json), the --mdp of the shaping commands.
// Beyond the error contract: an MDP that loads is written back and must load again.
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/mdp/mdp_json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit([](const std::string& file) { (void)pegasus::load_mdp(file); },
                                              pegasus::kMaxDataFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("fuzz.json", [&] {
    const pegasus::FiniteMdp mdp =
        pegasus::mdp_from_json(pegasus::parse_json_input(text, "fuzz.json", "MDP"), "fuzz.json");
    try {
      (void)pegasus::mdp_from_json(pegasus::mdp_to_json(mdp), "written.json");
    } catch (const std::exception& e) {
      pegasus::fuzz::violation("an MDP that does not load again once written", e.what());
    }
  });
  return 0;
}
