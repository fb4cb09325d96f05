// libFuzzer harness: vehicle files (heli/vehicle_file: parse_vehicle), the TOML that `pegasus log import`,
// `identify`, `hover`, `fly` and `control` read with --vehicle. Any bytes are accepted or refused with one
// InputError line naming the file; an accepted file names its topics once each, keeps the rate rule (model
// rate divides the log rate), drives each control axis with exactly one channel, and maps controls both ways.
#include <array>
#include <cmath>
#include <string>

#include "fuzz_contract.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "pegasus/io/atomic_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  pegasus::fuzz::refuses_input_past_its_limit(
      [](const std::string& file) { (void)pegasus::logs::read_vehicle(file); },
      pegasus::kMaxSettingsFileBytes);
  const std::string_view text = pegasus::fuzz::as_text(data, size);
  pegasus::fuzz::keeps_error_contract("vehicle.toml", [&] {
    const pegasus::logs::Vehicle vehicle = pegasus::logs::parse_vehicle(text, "vehicle.toml");
    const pegasus::logs::VehicleLogSpec& spec = vehicle.log;
    const double ratio = spec.rate_hz / spec.model_rate_hz;
    if (!(spec.rate_hz > 0) || std::abs(ratio - std::round(ratio)) > 1e-9)
      pegasus::fuzz::violation("an accepted file breaks the rate rule", text);
    const auto topics = spec.topic_names();
    for (std::size_t i = 0; i < topics.size(); ++i)
      for (std::size_t j = i + 1; j < topics.size(); ++j)
        if (topics[i] == topics[j]) pegasus::fuzz::violation("a topic named twice", topics[i]);
    std::array<int, 4> drivers{};
    for (std::size_t c = 0; c < 4; ++c) {
      const int axis = spec.controls[c].column(c);
      if (axis < 0 || axis > 3) pegasus::fuzz::violation("a channel drives no axis", text);
      ++drivers[static_cast<std::size_t>(axis)];
    }
    if (drivers != std::array<int, 4>{1, 1, 1, 1}) pegasus::fuzz::violation("an axis driven twice", text);
    const pegasus::heli::Controls axes{0.5, -0.25, 1, -1};
    const pegasus::heli::Controls back = vehicle.axes_of(vehicle.native_of(axes));
    for (std::size_t k = 0; k < 4; ++k)
      if (!(std::abs(back[k] - axes[k]) <= 1e-6)) pegasus::fuzz::violation("controls do not map back", text);
  });
  return 0;
}
