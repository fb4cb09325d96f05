// The judged cost of a vehicle file (heli/vehicle_file.hpp: JudgedCost) and its exact map onto the hover
// reward. Weights are written in the file's frames and units; a quadratic weight follows its quantity's
// conversion squared: a frame change permutes axes and flips signs (the squares keep their weights, on the
// other axis), a unit u per radian scales the weight by u^2, and a channel a = scale x value + offset by 1 /
// scale^2.
#include "vehicle_cost.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <set>
#include <string>

namespace pegasus::logs {
namespace {

constexpr double kMaxWeight = 1e9;  // per unit^2; with a unit's factor still below the reward's largest

template <std::size_t N>
std::array<double, N> weights(const toml::table& root, const TomlFields& f, const std::string& key) {
  std::array<double, N> out{};
  const toml::node* n = root.at_path(key).node();
  if (!n) return out;
  const toml::array* a = n->as_array();
  const std::string expected = fmt::format("expected a list of {} weights in [0, {:g}]", N, kMaxWeight);
  if (!a || a->size() != N) f.fail(n, key, expected);
  for (std::size_t i = 0; i < N; ++i) {
    const auto v = (*a)[i].value<double>();
    if (!v || !(*v >= 0 && *v <= kMaxWeight)) f.fail(n, key, expected);
    out[i] = *v;
  }
  return out;
}

std::array<double, 3> abs3(const heli::Vec3& v) {
  return {std::abs(v.x()), std::abs(v.y()), std::abs(v.z())};
}
heli::Vec3 vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

}  // namespace

std::optional<JudgedCost> read_judged_cost(const toml::table& root, const TomlFields& f) {
  const toml::node* section = root.get("cost");
  if (!section) return std::nullopt;
  if (!section->as_table()) f.fail(section, "cost", "expected a table");
  f.only_keys(
      *section->as_table(), "cost",
      {"position", "velocity", "euler", "quaternion", "body_rates", "controls", "controls_about", "crash"});
  if (root.at_path("hover.reward").node())
    f.fail(root.at_path("hover.reward").node(), "hover.reward",
           "the [cost] section is the whole reward; expected either [cost] or [hover.reward], not both");
  JudgedCost c;
  c.position = weights<3>(root, f, "cost.position");
  c.velocity = weights<3>(root, f, "cost.velocity");
  const toml::node* euler = root.at_path("cost.euler").node();
  const toml::node* quaternion = root.at_path("cost.quaternion").node();
  if (euler && quaternion)
    f.fail(quaternion, "cost.quaternion",
           "expected either euler or quaternion weights on the attitude, not both");
  if (euler || quaternion) {
    c.attitude = euler ? "euler" : "quaternion";
    c.attitude_weights = weights<3>(root, f, euler ? "cost.euler" : "cost.quaternion");
  }
  c.body_rates = weights<3>(root, f, "cost.body_rates");
  c.controls = weights<4>(root, f, "cost.controls");
  if (const toml::node* about = root.at_path("cost.controls_about").node()) {
    if (const auto s = about->value<std::string>()) {
      if (*s != "trim")
        f.fail(about, "cost.controls_about", "expected \"trim\" or a list of 4 channel values");
    } else {
      const toml::array* a = about->as_array();
      const char* expected =
          "expected \"trim\" or a list of 4 channel values (the aircraft's order and units)";
      if (!a || a->size() != 4) f.fail(about, "cost.controls_about", expected);
      for (std::size_t i = 0; i < 4; ++i) {
        const auto v = (*a)[i].value<double>();
        if (!v || !std::isfinite(*v)) f.fail(about, "cost.controls_about", expected);
        c.controls_about[i] = *v;
      }
      c.controls_about_trim = false;
    }
  }
  c.crash = f.number(root.at_path("cost.crash").node(), "cost.crash", c.crash, 0, 1e12);
  return c;
}

void read_envelope_limits(const toml::table& root, const TomlFields& f, Vehicle& v) {
  const auto limit = [&](const char* key, double per_unit) {
    const toml::node* n = root.at_path(key).node();
    if (!n) return std::numeric_limits<double>::infinity();
    const double x = f.number(n, key, 0, 0, 1e12);
    if (!(x > 0)) f.fail(n, key, "expected a positive limit");
    return x * per_unit;
  };
  v.max_position_error_m = limit("envelope.max_position_error", 1);
  v.max_speed_mps = limit("envelope.max_speed", 1);
  v.max_rate_radps = limit("envelope.max_rate", radians_per_rates_unit(v.log));
}

namespace {

// Reads each of Disturbance::VisitFields's settings from [hover.wind] KEY: a number within its bounds, or the
// steady wind's 3, in the file's world frame.
struct HoverWindReader {
  const toml::table& root;
  const TomlFields& f;
  const VehicleLogSpec& spec;
  sysid::Disturbance d;
  void setting(const sysid::DisturbanceSetting& s, double sysid::Disturbance::*member) {
    const std::string key = std::string("hover.wind.") + s.key;
    const toml::node* n = root.at_path(key).node();
    if (!n) return;
    const double x =
        f.number(n, key, d.*member);  // a finite number; its bounds below, as the setting states them
    if (!s.within(x))
      f.fail(n, key, fmt::format("expected a number in {} ({}), got {}", s.range(), s.unit, x));
    d.*member = x;
  }
  void setting(const sysid::DisturbanceSetting& s, std::array<double, 3> sysid::Disturbance::*member) {
    const std::string key = std::string("hover.wind.") + s.key;
    const toml::node* n = root.at_path(key).node();
    if (!n) return;
    const std::string expected =
        fmt::format("expected a list of 3 numbers in {} ({}, the file's world frame)", s.range(), s.unit);
    const toml::array* a = n->as_array();
    if (!a || a->size() != 3) f.fail(n, key, expected);
    std::array<double, 3> w{};
    for (std::size_t i = 0; i < 3; ++i) {
      const auto v = (*a)[i].value<double>();
      if (!v || !s.within(*v)) f.fail(n, key, expected);
      w[i] = *v;
    }
    const heli::Vec3 w_W = world_vector_of(spec, vec(w));
    d.*member = {w_W.x(), w_W.y(), w_W.z()};
  }
};

}  // namespace

std::optional<sysid::Disturbance> read_hover_wind(const toml::table& root, const TomlFields& f,
                                                  const VehicleLogSpec& spec) {
  const toml::node* section = root.at_path("hover.wind").node();
  if (!section) return std::nullopt;
  if (!section->as_table()) f.fail(section, "hover.wind", "expected a table");
  std::set<std::string> keys;
  for (const sysid::DisturbanceSetting& s : sysid::Disturbance::settings()) keys.insert(s.key);
  f.only_keys(*section->as_table(), "hover.wind", keys);
  HoverWindReader reader{root, f, spec, {}};
  sysid::Disturbance::VisitFields(reader);
  return reader.d;
}

heli::HoverReward judged_reward(const Vehicle& v) {
  const JudgedCost& c = v.cost.value();
  const VehicleLogSpec& spec = v.log;
  heli::HoverReward r;
  r.alpha_pos = abs3(world_vector_of(spec, vec(c.position)));
  r.alpha_vel = abs3(world_vector_of(spec, vec(c.velocity)));
  r.alpha_yaw = 0;
  r.alpha_action = {0, 0, 0, 0};
  if (c.attitude == "euler") {
    // Roll and pitch about level and the yaw error keep their magnitudes in every pair of frames.
    const double per = radians_per_attitude_unit(spec);
    r.alpha_attitude = {c.attitude_weights[0] / (per * per), c.attitude_weights[1] / (per * per)};
    r.alpha_yaw = c.attitude_weights[2] / (per * per);
  } else if (c.attitude == "quaternion") {
    // The error rotation's vector part is a body vector (the world frame cancels in R_target^T R).
    r.alpha_quaternion = abs3(body_vector_of(spec, vec(c.attitude_weights)));
  }
  const double per_rate = radians_per_rates_unit(spec);
  r.alpha_body_rate = abs3(body_vector_of(spec, vec(c.body_rates)));
  for (double& w : r.alpha_body_rate) w /= per_rate * per_rate;
  for (std::size_t k = 0; k < 4; ++k) {
    const ControlChannel& ch = spec.controls[k];
    r.alpha_action[static_cast<std::size_t>(ch.column(k))] = c.controls[k] / (ch.scale * ch.scale);
  }
  if (!c.controls_about_trim) r.centre = v.axes_of(c.controls_about);
  return r;
}

}  // namespace pegasus::logs
