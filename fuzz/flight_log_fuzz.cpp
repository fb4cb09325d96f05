// libFuzzer harness: CSV flight logs (sysid/flight_log: parse_flight_log), the input of `heli identify`.
#include "fuzz_contract.hpp"
#include "pegasus/sysid/flight_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(pegasus::fuzz::as_text(data, size));
  pegasus::sysid::LogReadOptions options;
  options.min_rows = 2;  // small logs reach the checks past the row count
  pegasus::fuzz::keeps_error_contract(
      "fuzz.csv", [&] { (void)pegasus::sysid::parse_flight_log(text, "fuzz.csv", options); });
  return 0;
}
