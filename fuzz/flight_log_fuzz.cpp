// libFuzzer harness: CSV flight logs (sysid/flight_log: parse_flight_log), the input of `heli identify`.
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/vehicle/flight_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::sysid::read_flight_log(file); },
      pegasus::kMaxDataFileBytes);
  const std::string text(pegasus::fuzz::as_text(data, size));
  pegasus::sysid::LogReadOptions options;
  options.min_rows = 2;  // small logs reach the checks past the row count
  pegasus::fuzz::keeps_error_contract(
      "fuzz.csv", [&] { (void)pegasus::sysid::parse_flight_log(text, "fuzz.csv", options); });
  return 0;
}
