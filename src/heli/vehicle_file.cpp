#include "pegasus/heli/vehicle_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <map>
#include <set>

#include "../io/toml_fields.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "pegasus/heli/simulators.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/sysid/body_model.hpp"
#include "pegasus/vehicle/frames.hpp"
#include "vehicle_cost.hpp"

namespace pegasus::logs {
namespace {

class SpecReader {
 public:
  SpecReader(const toml::table& root, std::string file) : root_(root), fields_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& what) const {
    fields_.fail(node, key, what);
  }
  const toml::node* at(const std::string& key) const { return root_.at_path(key).node(); }
  const toml::node& required(const std::string& key, const std::string& what) const {
    const toml::node* n = at(key);
    if (!n) fail(root_.get("log"), key, "missing; expected " + what);
    return *n;
  }
  std::string string(const std::string& key, std::string fallback,
                     const std::vector<std::string>& choices = {}) const {
    return choices.empty() ? fields_.string(at(key), key, std::move(fallback))
                           : fields_.choice(at(key), key, std::move(fallback), choices);
  }
  std::string required_string(const std::string& key) const {
    const toml::node& n = required(key, "a string");
    const auto v = n.value<std::string>();
    if (!v || v->empty()) fail(&n, key, "expected a non-empty string");
    return *v;
  }
  double number(const std::string& key, double fallback, double lo, double hi) const {
    return fields_.number(at(key), key, fallback, lo, hi);
  }
  std::vector<double> numbers(const std::string& key, std::size_t count) const {
    const toml::node* n = at(key);
    const toml::array* a = n ? n->as_array() : nullptr;
    if (!a || a->size() != count) fail(n, key, fmt::format("expected a list of {} numbers", count));
    std::vector<double> out;
    for (const auto& e : *a) {
      const auto v = e.value<double>();
      if (!v || !std::isfinite(*v)) fail(n, key, fmt::format("expected a list of {} numbers", count));
      out.push_back(*v);
    }
    return out;
  }
  // A quantity's fields; its topic is optional (a CSV log has none; a ULog import asks for it).
  TopicFields fields(const std::string& key, std::size_t count) const {
    TopicFields t;
    t.topic = string(key + ".topic", "");
    const toml::node& n =
        required(key + ".fields", fmt::format("a list of {} field (or CSV column) names", count));
    const toml::array* a = n.as_array();
    if (!a || a->size() != count)
      fail(&n, key + ".fields", fmt::format("expected a list of {} field (or CSV column) names", count));
    for (const auto& e : *a) {
      const auto v = e.value<std::string>();
      if (!v || v->empty()) fail(&n, key + ".fields", "expected field names (strings)");
      t.fields.push_back(*v);
    }
    return t;
  }
  // Every key of the table at `key` must be one of `known` (a misspelt key would silently keep a default).
  void only_keys(const std::string& key, const toml::table& table, const std::set<std::string>& known) const {
    fields_.only_keys(table, key, known);
  }
  void only_keys(const std::string& key, const std::set<std::string>& known) const {
    if (const toml::node* n = key.empty() ? &root_ : at(key)) {
      if (const toml::table* t = n->as_table())
        only_keys(key, *t, known);
      else if (!n->is_array_of_tables())
        fail(n, key, "expected a table");
    }
  }

 private:
  const toml::table& root_;
  TomlFields fields_;
};

// A channel's scale and offset (a = scale * value + offset): bounded so that the mapping inverts in doubles.
constexpr double kSmallestScale = 1e-9, kLargestScale = 1e6, kLargestOffset = 1e6;

int axis_index(const SpecReader& r, const std::string& key) {
  const std::string name = r.string(key, "", {"pitch", "roll", "thrust", "yaw"});
  for (std::size_t a = 0; a < kControlAxisNames.size(); ++a)
    if (name == kControlAxisNames[a]) return static_cast<int>(a);
  return -1;
}

// The [log] section's conventions (issue 53): the defaults are the pipeline's own.
void read_conventions(const SpecReader& r, VehicleLogSpec& s) {
  s.world_frame = r.string("log.world_frame", s.world_frame, {"NED", "ENU"});
  s.body_frame = r.string("log.body_frame", s.body_frame, {"FRD", "FLU"});
  // Position and velocity have one unit each; a file may say it.
  (void)r.string("log.position.unit", "m", {"m"});
  (void)r.string("log.velocity.unit", "m/s", {"m/s"});
  const bool quaternion = s.attitude_form == "quaternion";
  for (const char* key : {"log.attitude.order", "log.attitude.direction"})
    if (!quaternion && r.at(key))
      r.fail(r.at(key), key, "applies to a quaternion; expected it only with form = \"quaternion\"");
  s.quaternion_order = r.string("log.attitude.order", s.quaternion_order, {"wxyz", "xyzw"});
  s.quaternion_direction =
      r.string("log.attitude.direction", s.quaternion_direction, {"body_to_world", "world_to_body"});
  s.attitude_unit = r.string("log.attitude.unit", s.attitude_unit, {"rad", "deg"});
  s.rates_unit = r.string("log.rates.unit", s.rates_unit, {"rad/s", "deg/s"});
}

// A channel's mapping onto its axis, a = scale * value + offset: given as the channel's range and sign, or
// as scale and offset.
void read_channel_mapping(const SpecReader& r, const std::string& key, ControlChannel& ch) {
  const bool by_range = r.at(key + ".range") || r.at(key + ".sign");
  if (by_range && (r.at(key + ".scale") || r.at(key + ".offset")))
    r.fail(r.at(key + ".scale") ? r.at(key + ".scale") : r.at(key + ".offset"), key,
           "expected either range and sign, or scale and offset, not both");
  if (by_range) {
    // The channel's range maps onto [-1, 1]; sign -1: the channel's + drives the axis's -.
    const double sign = r.number(key + ".sign", 1, -INFINITY, INFINITY);
    if (sign != 1 && sign != -1)
      r.fail(r.at(key + ".sign"), key + ".sign", fmt::format("expected 1 or -1, got {}", sign));
    double lo = -1, hi = 1;
    if (r.at(key + ".range")) {
      const auto range = r.numbers(key + ".range", 2);
      lo = range[0];
      hi = range[1];
      if (!(hi > lo))
        r.fail(r.at(key + ".range"), key + ".range", fmt::format("expected [low, high] with low < high"));
    }
    ch.scale = sign * 2 / (hi - lo);
    ch.offset = -sign * (hi + lo) / (hi - lo);
    if (!(std::abs(ch.scale) >= kSmallestScale && std::abs(ch.scale) <= kLargestScale &&
          std::abs(ch.offset) <= kLargestOffset))
      r.fail(r.at(key + ".range"), key + ".range",
             fmt::format("expected a width in [{}, {}] and a centre within {} widths of 0", 2 / kLargestScale,
                         2 / kSmallestScale, kLargestOffset / 2));
  } else {
    ch.scale = r.number(key + ".scale", 1, -kLargestScale, kLargestScale);
    if (!(std::abs(ch.scale) >= kSmallestScale))
      r.fail(r.at(key + ".scale"), key + ".scale",
             fmt::format("expected a number of size at least {} (the channel must move its axis)",
                         kSmallestScale));
    ch.offset = r.number(key + ".offset", 0, -kLargestOffset, kLargestOffset);
  }
}

// The four [[log.controls]] channels: where each is logged, how it maps onto [-1, 1], and which axis it
// drives (each axis once, or no `axis` keys at all: a1..a4 in order).
void read_controls(const toml::table& root, const SpecReader& r, VehicleLogSpec& s) {
  const toml::node* controls = r.at("log.controls");
  const toml::array* list = controls ? controls->as_array() : nullptr;
  if (!list || list->size() != 4 || !list->is_array_of_tables())
    r.fail(controls ? controls : root.get("log"), "log.controls",
           "expected four [[log.controls]] tables: the aircraft's channels in its order, each with the axis "
           "it drives (or, without `axis` keys, a1, a2, a3, a4 in this order)");
  int with_axis = 0;
  std::array<int, 4> driver{-1, -1, -1, -1};
  for (std::size_t c = 0; c < 4; ++c) {
    const std::string key = fmt::format("log.controls[{}]", c);
    r.only_keys(key, *(*list)[c].as_table(),
                {"topic", "field", "scale", "offset", "axis", "name", "range", "sign", "unit"});
    ControlChannel& ch = s.controls[c];
    ch.topic = r.string(key + ".topic", "");
    ch.field = r.required_string(key + ".field");
    ch.name = r.string(key + ".name", "");
    if (r.at(key + ".unit"))
      ch.unit =
          r.string(key + ".unit", "", std::vector<std::string>(kChannelUnits.begin(), kChannelUnits.end()));
    read_channel_mapping(r, key, ch);
    if (r.at(key + ".axis")) {
      ++with_axis;
      ch.axis = axis_index(r, key + ".axis");
      if (driver[static_cast<std::size_t>(ch.axis)] >= 0)
        r.fail(r.at(key + ".axis"), key + ".axis",
               fmt::format("the {} axis is already driven by log.controls[{}]; expected each of pitch, roll, "
                           "thrust and yaw once",
                           kControlAxisNames[static_cast<std::size_t>(ch.axis)],
                           driver[static_cast<std::size_t>(ch.axis)]));
      driver[static_cast<std::size_t>(ch.axis)] = static_cast<int>(c);
    }
  }
  if (with_axis != 0 && with_axis != 4)
    r.fail(controls, "log.controls",
           "expected an axis on every channel or on none (none: the channels are a1..a4 in order)");
}

// A channel's unit must suit its axis, and its name (or label) be its own.
void check_channels(const SpecReader& r, const VehicleLogSpec& s) {
  for (std::size_t c = 0; c < 4; ++c) {
    const ControlChannel& ch = s.controls[c];
    const bool angular = ch.unit == "rad" || ch.unit == "deg" || ch.unit == "rad/s" || ch.unit == "deg/s";
    if (angular && ch.column(c) == 2) {
      const std::string key = fmt::format("log.controls[{}].unit", c);
      r.fail(r.at(key), key,
             fmt::format("'{}' is an angle or angular rate, but the channel drives the thrust axis; expected "
                         "one of m/s, N, 1, %, us (or no unit)",
                         ch.unit));
    }
  }
  for (std::size_t c = 0; c < 4; ++c)
    for (std::size_t d = 0; d < c; ++d)
      if (s.controls[c].label() == s.controls[d].label())
        r.fail(r.at("log.controls"), "log.controls",
               fmt::format("channels {} and {} have the same name '{}'; expected distinct names", d, c,
                           printable(s.controls[c].label())));
}

// Each log column (or topic field) means one thing: a second use would silently read the first.
void check_fields_used_once(const SpecReader& r, const VehicleLogSpec& s) {
  std::vector<std::pair<std::string, std::string>> used;  // (key, topic + field)
  used.emplace_back("log.time", "\n" + s.time);
  for (const auto& [key, quantity] : {std::pair{"log.position", &s.position},
                                      {"log.velocity", &s.velocity},
                                      {"log.attitude", &s.attitude},
                                      {"log.rates", &s.rates}})
    for (const std::string& field : quantity->fields) used.emplace_back(key, quantity->topic + "\n" + field);
  for (std::size_t c = 0; c < 4; ++c)
    used.emplace_back(fmt::format("log.controls[{}]", c), s.controls[c].topic + "\n" + s.controls[c].field);
  for (std::size_t i = 0; i < used.size(); ++i) {
    // A ULog topic's `timestamp` is its records' time (the import's clock), never a measured quantity.
    const auto [topic, field] = std::pair{used[i].second.substr(0, used[i].second.find('\n')),
                                          used[i].second.substr(used[i].second.find('\n') + 1)};
    if (!topic.empty() && field == "timestamp")
      r.fail(
          r.at(used[i].first), used[i].first,
          fmt::format("topic {}: 'timestamp' is the records' time, not a measured quantity; expected a data "
                      "field of the topic",
                      printable(topic)));
  }
  for (std::size_t i = 0; i < used.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (used[i].second == used[j].second) {
        const std::string field = used[i].second.substr(used[i].second.find('\n') + 1);
        r.fail(r.at(used[i].first), used[i].first,
               fmt::format("the field '{}' is also in {}; expected each field once", printable(field),
                           used[j].first));
      }
}

// The aircraft's name, the log's rates and the quantities' fields, in the log's conventions.
void read_log_quantities(const SpecReader& r, const std::filesystem::path& file, VehicleLogSpec& s) {
  s.file = file.string();
  s.vehicle = r.string("vehicle.name", file.stem().string());
  // An empty name would make a model or policy of this aircraft look like the X-Cell's (which has none).
  if (s.vehicle.empty()) r.fail(r.at("vehicle.name"), "vehicle.name", "expected a non-empty name");
  s.rate_hz = r.number("log.rate_hz", s.rate_hz, 1, 10000);
  // Identify's bounds on its rate (ModelStructure::VisitFields), which this rate becomes, and at most the
  // log's.
  const NumberSetting& model_rate = number_setting<sysid::ModelStructure>("rate_hz");
  s.model_rate_hz =
      r.number("log.model_rate_hz", s.model_rate_hz, model_rate.lower, std::min(model_rate.upper, s.rate_hz));
  const double ratio = s.rate_hz / s.model_rate_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9)
    r.fail(r.at("log.model_rate_hz"), "log.model_rate_hz",
           fmt::format("expected a rate that divides log.rate_hz = {} Hz, got {} Hz", s.rate_hz,
                       s.model_rate_hz));
  s.instance = static_cast<int>(r.number("log.instance", 0, 0, 255));
  if (s.instance != r.number("log.instance", 0, 0, 255))
    r.fail(r.at("log.instance"), "log.instance", "expected an integer multi_id");
  s.max_gap_s = r.number("log.max_gap_s", s.max_gap_s, 0, 1e6);
  s.time = r.string("log.time", s.time);
  if (s.time.empty()) r.fail(r.at("log.time"), "log.time", "expected a non-empty column name");
  s.attitude_form = r.string("log.attitude.form", s.attitude_form, {"quaternion", "euler"});
  s.velocity_frame = r.string("log.velocity.frame", s.velocity_frame, {"world", "body"});
  s.rates_form = r.string("log.rates.form", s.rates_form, {"body", "euler"});
  s.position = r.fields("log.position", 3);
  s.velocity = r.fields("log.velocity", 3);
  s.attitude = r.fields("log.attitude", s.attitude_form == "quaternion" ? 4 : 3);
  s.rates = r.fields("log.rates", 3);
}

VehicleLogSpec vehicle_log_spec(const toml::table& root, const SpecReader& r,
                                const std::filesystem::path& file) {
  if (!root.get("log") || !root.get("log")->is_table())
    throw InputError(
        fmt::format("{}: expected a [log] section (see the README's vehicle files)", file.string()));
  VehicleLogSpec s;
  read_log_quantities(r, file, s);
  read_conventions(r, s);
  read_controls(root, r, s);
  check_channels(r, s);
  check_fields_used_once(r, s);
  return s;
}

// [hover] target x, y, z, yaw in the log's world frame and attitude unit -> the pipeline's.
std::array<double, 4> target_of(const VehicleLogSpec& spec, const std::array<double, 4>& native) {
  const heli::Vec3 p_W = world_vector_of(spec, heli::Vec3(native[0], native[1], native[2]));
  double yaw = native[3];
  if (spec.attitude_unit != "rad") yaw *= radians_per_attitude_unit(spec);
  return {p_W.x(), p_W.y(), p_W.z(), euler_of(spec, heli::Euler{0, 0, yaw}).yaw};
}

// [envelope] max_tilt: the tilt in the log's attitude unit (exclusive with max_tilt_rad).
double max_tilt_of(const SpecReader& r, const VehicleLogSpec& spec) {
  if (r.at("envelope.max_tilt_rad"))
    r.fail(r.at("envelope.max_tilt"), "envelope.max_tilt",
           "expected either max_tilt (in the attitude unit) or max_tilt_rad, not both");
  const double per = radians_per_attitude_unit(spec);
  return r.number("envelope.max_tilt", 1, 0.01 / per, 1.5 / per) * per;
}

// [hover.reward]'s keys: the typical sizes HoverReward describes.
std::set<std::string> hover_reward_keys() {
  std::set<std::string> keys;
  for (const heli::HoverRewardSize& size : heli::HoverReward::sizes()) keys.insert(size.key);
  return keys;
}

// [hover.reward]: the sizes the file gives, in HoverReward's order. A size of 0 leaves a term out where the
// term allows it (the action, attitude and rate terms); else a size is at least kMinTypicalSize.
void read_hover_reward(const SpecReader& r, Vehicle& v) {
  for (const heli::HoverRewardSize& s : heli::HoverReward::sizes()) {
    const std::string path = std::string("hover.reward.") + s.key;
    if (!r.at(path)) continue;
    const double size = r.number(path, 0, 0, 1e150);
    const double least = heli::HoverReward::kMinTypicalSize;  // smaller makes a weight past the largest
    if (!(size >= least || (s.may_be_zero && size == 0)))
      r.fail(r.at(path), path,
             s.may_be_zero
                 ? fmt::format("expected 0 (no term) or a typical size of at least {}, got {}", least, size)
                 : fmt::format("expected a typical size of at least {}, got {}", least, size));
    v.reward.emplace_back(s.key, size);
  }
}

Vehicle vehicle(const toml::table& root, const std::filesystem::path& file) {
  const SpecReader r(root, file.string());
  r.only_keys("", {"vehicle", "log", "model", "control", "hover", "envelope", "cost"});
  r.only_keys("vehicle", {"name", "latent_states", "simulator"});
  r.only_keys("log", {"rate_hz", "model_rate_hz", "instance", "max_gap_s", "time", "position", "velocity",
                      "attitude", "rates", "controls", "world_frame", "body_frame"});
  r.only_keys("log.position", {"topic", "fields", "unit"});
  r.only_keys("log.velocity", {"topic", "fields", "frame", "unit"});
  r.only_keys("log.attitude", {"topic", "fields", "form", "order", "direction", "unit"});
  r.only_keys("log.rates", {"topic", "fields", "form", "unit"});
  r.only_keys("model", {"templates"});
  r.only_keys("control", {"rate_hz"});
  r.only_keys("hover", {"target", "starting_gains", "integral_seconds", "reward", "wind"});
  r.only_keys("hover.reward", hover_reward_keys());
  r.only_keys("envelope", {"max_tilt_rad", "max_tilt", "max_position_error", "max_speed", "max_rate"});
  Vehicle v;
  v.log = vehicle_log_spec(root, r, file);
  v.xcell_latent_states = r.string("vehicle.latent_states", "none", {"none", "xcell"}) == "xcell";
  v.simulator = r.string("vehicle.simulator", v.simulator, heli::simulator_names());
  v.kinematic_templates = r.string("model.templates", "kinematic", {"kinematic", "none"}) == "kinematic";
  // Bounded as hover's option (HoverTrainingOptions::VisitFields), which the file's value sets.
  const NumberSetting& rate = heli::HoverTrainingOptions::setting("control_rate_hz");
  v.control_rate_hz = r.number("control.rate_hz", v.control_rate_hz, rate.lower, rate.upper);
  // The controller is compared with the log step by step: one rate must be a whole multiple of the other.
  if (r.at("control.rate_hz") && sysid::log_rows_per_model_step(1 / v.log.rate_hz, v.control_rate_hz) == 0 &&
      sysid::log_rows_per_model_step(1 / v.control_rate_hz, v.log.rate_hz) == 0)
    r.fail(r.at("control.rate_hz"), "control.rate_hz",
           fmt::format("expected a rate that log.rate_hz = {} Hz is a whole multiple of, or a whole multiple "
                       "of it, got {}",
                       v.log.rate_hz, v.control_rate_hz));
  if (r.at("hover.target")) {
    const auto t = r.numbers("hover.target", 4);
    std::copy(t.begin(), t.end(), v.target.begin());
    v.target = target_of(v.log, v.target);
  }
  v.starting_gains = r.string("hover.starting_gains", v.starting_gains, {"lqr", "constant"});
  const NumberSetting& integral = heli::HoverTrainingOptions::setting("integral_seconds");
  v.integral_seconds = r.number("hover.integral_seconds", v.integral_seconds, integral.lower, integral.upper);
  // Checked here, not only by the commands that train (a vehicle file is valid or not as a whole).
  if (v.integral_seconds > 0 && v.integral_seconds * v.control_rate_hz < 1)
    r.fail(r.at("hover.integral_seconds"), "hover.integral_seconds",
           fmt::format("expected 0 (no integral term) or at least one control step ({:g} s), got {}",
                       1 / v.control_rate_hz, v.integral_seconds));
  read_hover_reward(r, v);
  v.max_tilt_rad = r.number("envelope.max_tilt_rad", v.max_tilt_rad, 0.01, 1.5);
  if (r.at("envelope.max_tilt")) v.max_tilt_rad = max_tilt_of(r, v.log);
  const TomlFields fields(file.string());
  read_envelope_limits(root, fields, v);
  v.cost = read_judged_cost(root, fields);
  v.wind = read_hover_wind(root, fields, v.log);
  return v;
}

}  // namespace

Vehicle read_vehicle(const std::filesystem::path& file) {
  return vehicle(read_toml_input(file, "vehicle"), file);
}

Vehicle parse_vehicle(std::string_view text, const std::filesystem::path& name) {
  return vehicle(parse_toml_input(text, name.string()), name);
}

VehicleLogSpec read_vehicle_log_spec(const std::filesystem::path& file) { return read_vehicle(file).log; }

VehicleLogSpec parse_vehicle_log_spec(std::string_view text, const std::filesystem::path& name) {
  return parse_vehicle(text, name).log;
}

Vehicle xcell_vehicle() {
  Vehicle v;
  VehicleLogSpec& s = v.log;
  s.vehicle = heli::kBuiltInVehicle;
  s.rate_hz = 50;
  s.model_rate_hz = 10;
  s.attitude_form = "euler";
  s.velocity_frame = "world";
  s.rates_form = "euler";
  s.position = {"", {"x", "y", "z"}};
  s.velocity = {"", {"xdot", "ydot", "zdot"}};
  s.attitude = {"", {"roll", "pitch", "yaw"}};
  s.rates = {"", {"roll_rate", "pitch_rate", "yaw_rate"}};
  for (std::size_t c = 0; c < 4; ++c) {
    s.controls[c].field = sysid::kLogControlColumns[c];
    s.controls[c].axis = static_cast<int>(c);
  }
  v.xcell_latent_states = true;
  v.simulator = "xcell";
  v.starting_gains = "constant";
  v.integral_seconds = 0;
  return v;
}

}  // namespace pegasus::logs
