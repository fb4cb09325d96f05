#include "pegasus/core/number_setting.hpp"

#include <fmt/format.h>

namespace pegasus {

std::string NumberSetting::range() const {
  return fmt::format("{}{}, {}]", lower_open ? "(" : "[", lower, upper);
}

std::string NumberSetting::range_in_unit() const { return *unit != '\0' ? range() + " " + unit : range(); }

std::string NumberSetting::refusal(const std::string& name, const char* what, double x) const {
  return fmt::format("{}: expected {} in {}, got {}", name, what, range_in_unit(), x);
}

}  // namespace pegasus
