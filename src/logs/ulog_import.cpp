#include "pegasus/logs/ulog_import.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "../io/toml_input.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/heli/frames.hpp"

namespace pegasus::logs {

using heli::Euler;
using heli::Vec3;

namespace {

// ------------------------------------------------------------------ the vehicle file

class SpecReader {
 public:
  SpecReader(const toml::table& root, std::string file) : root_(root), file_(std::move(file)) {}

  [[noreturn]] void fail(const toml::node* node, const std::string& key, const std::string& what) const {
    const auto line = node ? node->source().begin.line : 0;
    throw InputError(line ? fmt::format("{}:{}: {}: {}", file_, line, key, what)
                          : fmt::format("{}: {}: {}", file_, key, what));
  }
  const toml::node* at(const std::string& key) const { return root_.at_path(key).node(); }
  const toml::node& required(const std::string& key, const std::string& what) const {
    const toml::node* n = at(key);
    if (!n) fail(root_.get("log"), key, "missing; expected " + what);
    return *n;
  }
  std::string string(const std::string& key, std::string fallback,
                     std::vector<std::string> choices = {}) const {
    const toml::node* n = at(key);
    if (!n) return fallback;
    const auto v = n->value<std::string>();
    if (!v) fail(n, key, "expected a string");
    if (!choices.empty() && std::find(choices.begin(), choices.end(), *v) == choices.end()) {
      std::string list;
      for (const auto& c : choices) list += (list.empty() ? "" : " or ") + ("'" + c + "'");
      fail(n, key, fmt::format("expected {}, found '{}'", list, *v));
    }
    return *v;
  }
  std::string required_string(const std::string& key) const {
    const toml::node& n = required(key, "a string");
    const auto v = n.value<std::string>();
    if (!v || v->empty()) fail(&n, key, "expected a non-empty string");
    return *v;
  }
  double number(const std::string& key, double fallback, double lo, double hi) const {
    const toml::node* n = at(key);
    if (!n) return fallback;
    const auto v = n->value<double>();
    if (!v || !std::isfinite(*v)) fail(n, key, "expected a number");
    if (*v < lo || *v > hi) fail(n, key, fmt::format("expected a number in [{}, {}], found {}", lo, hi, *v));
    return *v;
  }
  TopicFields fields(const std::string& key, std::size_t count) const {
    TopicFields t;
    t.topic = required_string(key + ".topic");
    const toml::node& n = required(key + ".fields", fmt::format("a list of {} field names", count));
    const toml::array* a = n.as_array();
    if (!a || a->size() != count)
      fail(&n, key + ".fields", fmt::format("expected a list of {} field names", count));
    for (const auto& e : *a) {
      const auto v = e.value<std::string>();
      if (!v || v->empty()) fail(&n, key + ".fields", "expected field names (strings)");
      t.fields.push_back(*v);
    }
    return t;
  }

 private:
  const toml::table& root_;
  std::string file_;
};

// ------------------------------------------------------------------ resampling

// One topic's records as doubles, with its time in seconds.
struct Series {
  std::string topic;
  std::vector<double> time;                 // s, non-decreasing
  std::vector<std::vector<double>> fields;  // per field, per record
};

Series series(const UlogFile& ulog, const std::string& file, int instance, const std::string& topic,
              const std::vector<std::string>& fields) {
  const UlogTopic* t = ulog.topic(topic, instance);
  if (!t || t->rows() == 0) {
    const auto inst = ulog.instances(topic);
    std::string what = inst.empty() ? "is not in the log"
                                    : fmt::format("has no records for instance {} (instances logged: {})",
                                                  instance, fmt::join(inst, ", "));
    throw InputError(fmt::format("{}: topic {} {}", file, topic, what));
  }
  Series s;
  s.topic = topic;
  s.time.resize(t->rows());
  for (std::size_t r = 0; r < t->rows(); ++r) {
    s.time[r] = static_cast<double>(t->timestamps[r]) * 1e-6;
    if (r > 0 && t->timestamps[r] < t->timestamps[r - 1])
      throw InputError(
          fmt::format("{}: topic {}: record {} has timestamp {} us, before the previous record's {} us; "
                      "expected timestamps that never go back",
                      file, topic, r, t->timestamps[r], t->timestamps[r - 1]));
  }
  for (const auto& f : fields) s.fields.push_back(t->column(f, file));
  return s;
}

// Index of the last record at or before time t (0 when t precedes every record).
std::size_t record_at(const Series& s, double t, std::size_t hint) {
  std::size_t i = hint;
  while (i + 1 < s.time.size() && s.time[i + 1] <= t) ++i;
  return i;
}

// Linear interpolation weight of record i + 1 at t.
double weight_at(const Series& s, std::size_t i, double t) {
  if (i + 1 >= s.time.size()) return 0;
  const double span = s.time[i + 1] - s.time[i];
  return span > 0 ? std::clamp((t - s.time[i]) / span, 0.0, 1.0) : 0.0;
}

Vec3 interpolate3(const Series& s, std::size_t i, double w) {
  Vec3 v;
  const std::size_t j = std::min(i + 1, s.time.size() - 1);
  for (int c = 0; c < 3; ++c) {
    const auto& f = s.fields[static_cast<std::size_t>(c)];
    v[c] = (1 - w) * f[i] + w * f[j];
  }
  return v;
}

// Z-Y-X Euler angles of a unit quaternion (w, x, y, z) that rotates body vectors into the world frame.
Euler euler_from_quaternion(double w, double x, double y, double z) {
  Euler e;
  e.roll = std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
  e.pitch = std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0));
  e.yaw = std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
  return e;
}

Euler attitude_at(const Series& s, std::size_t i, double w, bool quaternion) {
  const std::size_t j = std::min(i + 1, s.time.size() - 1);
  if (quaternion) {
    // Normalised linear interpolation, on the same hemisphere (q and -q are one rotation).
    std::array<double, 4> a{}, b{};
    for (std::size_t c = 0; c < 4; ++c) {
      a[c] = s.fields[c][i];
      b[c] = s.fields[c][j];
    }
    const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    const double sign = dot < 0 ? -1 : 1;
    std::array<double, 4> q{};
    double norm = 0;
    for (std::size_t c = 0; c < 4; ++c) {
      q[c] = (1 - w) * a[c] + w * sign * b[c];
      norm += q[c] * q[c];
    }
    norm = std::sqrt(norm);
    if (!(norm > 0)) return Euler{NAN, NAN, NAN};
    return euler_from_quaternion(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
  }
  const auto lerp_angle = [&](std::size_t c) {
    const double a = s.fields[c][i];
    return heli::wrap_angle(a + w * heli::wrap_angle(s.fields[c][j] - a));
  };
  return Euler{lerp_angle(0), lerp_angle(1), lerp_angle(2)};
}

}  // namespace

std::vector<std::string> VehicleLogSpec::topic_names() const {
  std::vector<std::string> out;
  auto add = [&](const std::string& t) {
    if (std::find(out.begin(), out.end(), t) == out.end()) out.push_back(t);
  };
  for (const auto* t : {&position, &velocity, &attitude, &rates}) add(t->topic);
  for (const auto& c : controls) add(c.topic);
  return out;
}

namespace {
VehicleLogSpec vehicle_log_spec(const toml::table& root, const std::filesystem::path& file) {
  const SpecReader r(root, file.string());
  if (!root.get("log") || !root.get("log")->is_table())
    throw InputError(
        fmt::format("{}: expected a [log] section (see the README's vehicle files)", file.string()));
  VehicleLogSpec s;
  s.file = file.string();
  s.vehicle = r.string("vehicle.name", file.stem().string());
  s.rate_hz = r.number("log.rate_hz", s.rate_hz, 1, 10000);
  s.model_rate_hz = r.number("log.model_rate_hz", s.model_rate_hz, 0.1, s.rate_hz);
  const double ratio = s.rate_hz / s.model_rate_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9)
    r.fail(r.at("log.model_rate_hz"), "log.model_rate_hz",
           fmt::format("expected a rate that divides log.rate_hz = {} Hz, found {} Hz", s.rate_hz,
                       s.model_rate_hz));
  s.instance = static_cast<int>(r.number("log.instance", 0, 0, 255));
  if (s.instance != r.number("log.instance", 0, 0, 255))
    r.fail(r.at("log.instance"), "log.instance", "expected an integer multi_id");
  s.max_gap_s = r.number("log.max_gap_s", s.max_gap_s, 0, 1e6);
  s.attitude_form = r.string("log.attitude.form", s.attitude_form, {"quaternion", "euler"});
  s.velocity_frame = r.string("log.velocity.frame", s.velocity_frame, {"world", "body"});
  s.rates_form = r.string("log.rates.form", s.rates_form, {"body", "euler"});
  s.position = r.fields("log.position", 3);
  s.velocity = r.fields("log.velocity", 3);
  s.attitude = r.fields("log.attitude", s.attitude_form == "quaternion" ? 4 : 3);
  s.rates = r.fields("log.rates", 3);
  const toml::node* controls = r.at("log.controls");
  const toml::array* list = controls ? controls->as_array() : nullptr;
  if (!list || list->size() != 4 || !list->is_array_of_tables())
    r.fail(controls ? controls : root.get("log"), "log.controls",
           "expected four [[log.controls]] tables, for the log's columns a1, a2, a3, a4 in this order");
  for (std::size_t c = 0; c < 4; ++c) {
    const std::string key = fmt::format("log.controls[{}]", c);
    ControlChannel& ch = s.controls[c];
    ch.topic = r.required_string(key + ".topic");
    ch.field = r.required_string(key + ".field");
    ch.scale = r.number(key + ".scale", 1, -1e6, 1e6);
    ch.offset = r.number(key + ".offset", 0, -1e6, 1e6);
  }
  return s;
}
}  // namespace

VehicleLogSpec read_vehicle_log_spec(const std::filesystem::path& file) {
  return vehicle_log_spec(read_toml_input(file, "vehicle"), file);
}

VehicleLogSpec parse_vehicle_log_spec(std::string_view text, const std::filesystem::path& name) {
  return vehicle_log_spec(parse_toml_input(text, name.string()), name);
}

sysid::FlightLog import_ulog(const UlogFile& ulog, const VehicleLogSpec& spec, const std::string& file,
                             const ImportOptions& options, ImportProvenance* provenance) {
  const Series position = series(ulog, file, spec.instance, spec.position.topic, spec.position.fields);
  const Series velocity = series(ulog, file, spec.instance, spec.velocity.topic, spec.velocity.fields);
  const Series attitude = series(ulog, file, spec.instance, spec.attitude.topic, spec.attitude.fields);
  const Series rates = series(ulog, file, spec.instance, spec.rates.topic, spec.rates.fields);
  std::vector<Series> controls;
  for (const auto& c : spec.controls)
    controls.push_back(series(ulog, file, spec.instance, c.topic, {c.field}));

  std::vector<const Series*> all = {&position, &velocity, &attitude, &rates};
  for (const auto& c : controls) all.push_back(&c);
  double t0 = -INFINITY, t1 = INFINITY;
  for (const Series* s : all) {
    t0 = std::max(t0, s->time.front());
    t1 = std::min(t1, s->time.back());
  }
  const double common_start = t0;
  t0 = common_start + options.start_s;
  if (options.end_s > 0) t1 = std::min(t1, common_start + options.end_s);
  const double dt = 1 / spec.rate_hz;
  if (!(t1 - t0 >= dt))
    throw InputError(
        fmt::format("{}: the topics of {} share no time range of at least one step ({} s) after the "
                    "cut; common range {:.3f} to {:.3f} s",
                    file, spec.file, dt, t0, t1));
  // Gaps inside the range: interpolating across a long one would invent a flight.
  nlohmann::json topics_json = nlohmann::json::array();
  for (const Series* s : all) {
    double gap = 0, gap_at = t0;
    std::size_t used = 0;
    for (std::size_t i = 0; i + 1 < s->time.size(); ++i) {
      if (s->time[i + 1] < t0 || s->time[i] > t1) continue;
      ++used;
      const double g = s->time[i + 1] - s->time[i];
      if (g > gap) {
        gap = g;
        gap_at = s->time[i];
      }
    }
    if (gap > spec.max_gap_s)
      throw InputError(
          fmt::format("{}: topic {}: no record for {:.3f} s after t = {:.3f} s; expected gaps of at "
                      "most log.max_gap_s = {} s (cut the range with --start-s/--end-s or raise it "
                      "in {})",
                      file, s->topic, gap, gap_at, spec.max_gap_s, spec.file));
    bool listed = false;
    for (const auto& j : topics_json) listed = listed || j["topic"] == s->topic;
    if (!listed)
      topics_json.push_back({{"topic", s->topic},
                             {"records", s->time.size()},
                             {"records_in_range", used},
                             {"rate_hz", used > 0 ? static_cast<double>(used) / (t1 - t0) : 0.0},
                             {"largest_gap_s", gap}});
  }

  const auto rows = static_cast<std::size_t>(std::floor((t1 - t0) / dt + 1e-9)) + 1;
  sysid::FlightLog log;
  log.time.resize(rows);
  log.states.resize(rows);
  log.controls.resize(rows);
  std::size_t ip = 0, iv = 0, ia = 0, ir = 0;
  std::array<std::size_t, 4> ic{};
  const bool quaternion = spec.attitude_form == "quaternion";
  for (std::size_t k = 0; k < rows; ++k) {
    const double t = t0 + static_cast<double>(k) * dt;
    log.time[k] = static_cast<double>(k) * dt;
    ip = record_at(position, t, ip);
    iv = record_at(velocity, t, iv);
    ia = record_at(attitude, t, ia);
    ir = record_at(rates, t, ir);
    const Vec3 p_W = interpolate3(position, ip, weight_at(position, ip, t));
    const Euler e = attitude_at(attitude, ia, weight_at(attitude, ia, t), quaternion);
    Vec3 v = interpolate3(velocity, iv, weight_at(velocity, iv, t));
    if (spec.velocity_frame == "body") v = heli::world_from_body(e, v);
    Vec3 w = interpolate3(rates, ir, weight_at(rates, ir, t));
    if (spec.rates_form == "body") w = heli::euler_rates_from_body_rates(e, w);
    auto& s = log.states[k];
    s = {p_W.x(), p_W.y(), p_W.z(), e.roll, e.pitch, e.yaw, v.x(), v.y(), v.z(), w.x(), w.y(), w.z()};
    for (std::size_t j = 0; j < s.size(); ++j)
      if (!std::isfinite(s[j]))
        throw InputError(
            fmt::format("{}: at t = {:.3f} s the {} column is not finite (a NaN in the log's topics)", file,
                        t, sysid::kLogStateColumns[j]));
    for (std::size_t c = 0; c < 4; ++c) {
      ic[c] = record_at(controls[c], t, ic[c]);
      const double raw = controls[c].fields[0][ic[c]];
      const double a = spec.controls[c].scale * raw + spec.controls[c].offset;
      if (!(std::abs(a) <= 1 + 1e-6))
        throw InputError(
            fmt::format("{}: {}.{} = {} at t = {:.3f} s gives a{} = {}; expected [-1, 1] after the "
                        "scale and offset of {}",
                        file, spec.controls[c].topic, spec.controls[c].field, raw, t, c + 1, a, spec.file));
      log.controls[k][c] = std::clamp(a, -1.0, 1.0);
    }
  }
  if (provenance) {
    nlohmann::json dropouts = nlohmann::json::array();
    double dropout_ms = 0;
    for (const UlogDropout& d : ulog.dropouts) {
      dropouts.push_back({{"after_s", static_cast<double>(d.after_timestamp) * 1e-6},
                          {"duration_ms", d.duration_ms},
                          {"byte", d.offset}});
      dropout_ms += d.duration_ms;
    }
    nlohmann::json control_json = nlohmann::json::array();
    for (std::size_t c = 0; c < 4; ++c)
      control_json.push_back({{"column", fmt::format("a{}", c + 1)},
                              {"topic", spec.controls[c].topic},
                              {"field", spec.controls[c].field},
                              {"scale", spec.controls[c].scale},
                              {"offset", spec.controls[c].offset}});
    provenance->json = {
        {"vehicle", spec.vehicle},
        {"vehicle_file", spec.file},
        {"instance", spec.instance},
        {"rate_hz", spec.rate_hz},
        {"rows", rows},
        {"time_range_s", {t0, t0 + static_cast<double>(rows - 1) * dt}},
        {"common_range_s", {common_start, t1}},
        {"topics", topics_json},
        {"position", {{"topic", spec.position.topic}, {"fields", spec.position.fields}}},
        {"velocity",
         {{"topic", spec.velocity.topic}, {"fields", spec.velocity.fields}, {"frame", spec.velocity_frame}}},
        {"attitude",
         {{"topic", spec.attitude.topic}, {"fields", spec.attitude.fields}, {"form", spec.attitude_form}}},
        {"rates", {{"topic", spec.rates.topic}, {"fields", spec.rates.fields}, {"form", spec.rates_form}}},
        {"controls", control_json},
        {"dropouts", dropouts},
        {"dropout_total_ms", dropout_ms},
        {"ulog",
         {{"version", ulog.version},
          {"data_messages", ulog.data_messages},
          {"truncated_at_byte", ulog.truncated_at ? nlohmann::json(*ulog.truncated_at) : nlohmann::json()},
          {"discarded_bytes", ulog.discarded_bytes},
          {"appended_data", (ulog.incompat_flags[0] & 1) != 0}}}};
    for (const char* key : {"sys_name", "ver_hw", "ver_sw"})
      if (const auto it = ulog.info.find(key); it != ulog.info.end())
        provenance->json["ulog"][key] = it->second.raw;
  }
  return log;
}

std::string file_sha256(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open for its SHA-256", file.string()));
  const std::unique_ptr<EVP_MD_CTX, decltype(&EVP_MD_CTX_free)> ctx(EVP_MD_CTX_new(), EVP_MD_CTX_free);
  if (!ctx || EVP_DigestInit_ex(ctx.get(), EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256: OpenSSL could not start a digest");
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    if (in.gcount() > 0) EVP_DigestUpdate(ctx.get(), buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int size = 0;
  EVP_DigestFinal_ex(ctx.get(), digest.data(), &size);
  std::string hex;
  for (unsigned int i = 0; i < size; ++i) hex += fmt::format("{:02x}", digest[i]);
  return hex;
}

}  // namespace pegasus::logs
