// The wind's settings, described once (vehicle/disturbance.hpp).
#include "pegasus/vehicle/disturbance.hpp"

namespace pegasus::sysid {

namespace {

// Collects the settings, or checks a Disturbance's values against them.
struct SettingsList {
  std::vector<DisturbanceSetting> settings;
  template <class T>
  void setting(const DisturbanceSetting& s, T Disturbance::* /*member*/) {
    settings.push_back(s);
  }
};

struct BoundsCheck {
  const Disturbance& d;
  std::string error;
  void check(const DisturbanceSetting& s, double x, const char* what) {
    if (error.empty() && !s.within(x)) error = s.refusal(s.field, what, x);
  }
  void setting(const DisturbanceSetting& s, double Disturbance::*member) { check(s, d.*member, "a number"); }
  void setting(const DisturbanceSetting& s, std::array<double, 3> Disturbance::*member) {
    for (const double x : d.*member) check(s, x, "numbers");
  }
};

}  // namespace

const std::vector<DisturbanceSetting>& Disturbance::settings() {
  static const std::vector<DisturbanceSetting> list = [] {
    SettingsList v;
    VisitFields(v);
    return v.settings;
  }();
  return list;
}

bool Disturbance::IsValid(std::string* error) const {
  BoundsCheck v{*this, {}};
  VisitFields(v);
  if (v.error.empty()) return true;
  if (error) *error = v.error;
  return false;
}

}  // namespace pegasus::sysid
