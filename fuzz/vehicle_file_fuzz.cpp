// libFuzzer harness: vehicle files (logs/ulog_import: parse_vehicle_log_spec), the TOML that `pegasus log
// import --vehicle` reads. Any bytes are accepted or refused with one InputError line naming the file; an
// accepted file names its topics once each and keeps the rate rule (model rate divides the log rate).
#include <cmath>

#include "fuzz_contract.hpp"
#include "pegasus/logs/ulog_import.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("vehicle.toml", [&] {
    const pegasus::logs::VehicleLogSpec spec = pegasus::logs::parse_vehicle_log_spec(text, "vehicle.toml");
    const double ratio = spec.rate_hz / spec.model_rate_hz;
    if (!(spec.rate_hz > 0) || std::abs(ratio - std::round(ratio)) > 1e-9)
      pegasus::fuzz::violation("an accepted file breaks the rate rule", text);
    const auto topics = spec.topic_names();
    for (std::size_t i = 0; i < topics.size(); ++i)
      for (std::size_t j = i + 1; j < topics.size(); ++j)
        if (topics[i] == topics[j]) pegasus::fuzz::violation("a topic named twice", topics[i]);
  });
  return 0;
}
