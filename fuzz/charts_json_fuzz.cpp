// libFuzzer harness: a run directory's charts.json (runs/charts.hpp: charts_from_json), which the report
// reads from any run directory it is pointed at. Beyond the error contract: sections that load are written
// back and must load again to the same document.
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/runs/charts.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) {
        (void)pegasus::charts_from_json(pegasus::read_json_input(file, "charts"), file);
      },
      pegasus::kMaxDataFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("charts.json", [&] {
    const auto sections = pegasus::charts_from_json(
        pegasus::parse_json_input(text, "charts.json", "chart specifications"), "charts.json");
    const nlohmann::json written = pegasus::to_json(sections);
    try {
      if (pegasus::to_json(pegasus::charts_from_json(written, "written.json")) != written)
        pegasus::fuzz::violation("charts that read back differently once written", written.dump());
    } catch (const std::exception& e) {
      pegasus::fuzz::violation("charts that do not load again once written", e.what());
    }
  });
  return 0;
}
