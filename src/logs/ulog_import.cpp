#include "pegasus/logs/ulog_import.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>

#include "../io/toml_input.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/vehicle/frames.hpp"

namespace pegasus::logs {

using heli::Euler;
using heli::Vec3;

namespace {

// ------------------------------------------------------------------ resampling

// One topic's records as doubles, with its time in seconds.
struct Series {
  std::string topic;
  std::vector<double> time;                 // s, non-decreasing
  std::vector<std::size_t> bytes;           // per record, its message's byte offset in the file
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
    // A file cut short (a copy stopped early) may end before a topic's first record: say where it ends.
    if (ulog.truncated_at)
      what +=
          fmt::format(" before the file ends inside a message at byte {} (cut short?)", *ulog.truncated_at);
    throw InputError(fmt::format("{}: topic {} {}", file, topic, what));
  }
  Series s;
  s.topic = topic;
  s.bytes = t->offsets;
  s.time.resize(t->rows());
  for (std::size_t r = 0; r < t->rows(); ++r) {
    s.time[r] = static_cast<double>(t->timestamps[r]) * 1e-6;
    if (r > 0 && t->timestamps[r] < t->timestamps[r - 1])
      throw InputError(fmt::format(
          "{}: byte {}: topic {}: record {} has timestamp {} us, before the previous record's {} "
          "us (byte {}); expected timestamps that never go back",
          file, t->offsets[r], topic, r, t->timestamps[r], t->timestamps[r - 1], t->offsets[r - 1]));
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

// The attitude at a time, in the log's own frames (rad): Euler angles or a quaternion in the log's order and
// direction.
Euler attitude_at(const Series& s, std::size_t i, double w, const VehicleLogSpec& spec) {
  const std::size_t j = std::min(i + 1, s.time.size() - 1);
  if (spec.attitude_form == "quaternion") {
    // Normalised linear interpolation, on the same hemisphere (q and -q are one rotation).
    std::array<double, 4> a{}, b{};
    for (std::size_t c = 0; c < 4; ++c) {
      a[c] = s.fields[c][i];
      b[c] = s.fields[c][j];
    }
    const double dot = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    const double sign = dot < 0 ? -1 : 1;
    std::array<double, 4> q{};
    for (std::size_t c = 0; c < 4; ++c) q[c] = (1 - w) * a[c] + w * sign * b[c];
    return native_euler_of_quaternion(spec, q.data());
  }
  // Interpolated in radians: the wrap is at +-pi.
  const bool rad = spec.attitude_unit == "rad";
  const double k = radians_per_attitude_unit(spec);
  const auto lerp_angle = [&](std::size_t c) {
    const double a = rad ? s.fields[c][i] : s.fields[c][i] * k;
    const double b = rad ? s.fields[c][j] : s.fields[c][j] * k;
    return heli::wrap_angle(a + w * heli::wrap_angle(b - a));
  };
  return Euler{lerp_angle(0), lerp_angle(1), lerp_angle(2)};
}

// ------------------------------------------------------------------ import

// The topics the vehicle file names, read whole.
struct Topics {
  Series position, velocity, attitude, rates;
  std::vector<Series> controls;  // one per control column, in the file's order

  std::vector<const Series*> all() const {
    std::vector<const Series*> out = {&position, &velocity, &attitude, &rates};
    for (const auto& c : controls) out.push_back(&c);
    return out;
  }
};

Topics read_topics(const UlogFile& ulog, const VehicleLogSpec& spec, const std::string& file) {
  // A vehicle file written for CSV logs names columns, not topics.
  const auto need_topic = [&](const std::string& topic, const std::string& key) {
    if (topic.empty())
      throw InputError(fmt::format("{}: {}.topic: missing; expected the ULog topic that holds the fields",
                                   spec.file, key));
  };
  need_topic(spec.position.topic, "log.position");
  need_topic(spec.velocity.topic, "log.velocity");
  need_topic(spec.attitude.topic, "log.attitude");
  need_topic(spec.rates.topic, "log.rates");
  for (std::size_t c = 0; c < 4; ++c) need_topic(spec.controls[c].topic, fmt::format("log.controls[{}]", c));
  Topics topics{series(ulog, file, spec.instance, spec.position.topic, spec.position.fields),
                series(ulog, file, spec.instance, spec.velocity.topic, spec.velocity.fields),
                series(ulog, file, spec.instance, spec.attitude.topic, spec.attitude.fields),
                series(ulog, file, spec.instance, spec.rates.topic, spec.rates.fields),
                {}};
  for (const auto& c : spec.controls)
    topics.controls.push_back(series(ulog, file, spec.instance, c.topic, {c.field}));
  return topics;
}

// The rows' times: from t0 every dt up to t1, inside the range every topic covers (which starts at
// common_start), cut by the options.
struct TimeRange {
  double common_start = 0, t0 = 0, t1 = 0, dt = 0;
  std::size_t rows() const { return static_cast<std::size_t>(std::floor((t1 - t0) / dt + 1e-9)) + 1; }
};

TimeRange time_range(const Topics& topics, const VehicleLogSpec& spec, const std::string& file,
                     const ImportOptions& options) {
  double t0 = -INFINITY, t1 = INFINITY;
  for (const Series* s : topics.all()) {
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
  return {common_start, t0, t1, dt};
}

// Gaps inside the range: interpolating across a long one would invent a flight. Returns each topic's
// records, rate and largest gap, for the provenance.
nlohmann::json check_gaps(const Topics& topics, const TimeRange& range, const VehicleLogSpec& spec,
                          const std::string& file) {
  const double t0 = range.t0, t1 = range.t1;
  nlohmann::json topics_json = nlohmann::json::array();
  for (const Series* s : topics.all()) {
    double gap = 0, gap_at = t0;
    std::size_t used = 0, gap_record = 0;
    for (std::size_t i = 0; i + 1 < s->time.size(); ++i) {
      if (s->time[i + 1] < t0 || s->time[i] > t1) continue;
      ++used;
      const double g = s->time[i + 1] - s->time[i];
      if (g > gap) {
        gap = g;
        gap_at = s->time[i];
        gap_record = i;
      }
    }
    if (gap > spec.max_gap_s)
      throw InputError(fmt::format(
          "{}: byte {}: topic {}: no record for {:.3f} s after this one's t = {:.3f} s; expected "
          "gaps of at most log.max_gap_s = {} s (cut the range with --start-s/--end-s or raise it "
          "in {})",
          file, s->bytes[gap_record], s->topic, gap, gap_at, spec.max_gap_s, spec.file));
    bool listed = false;
    for (const auto& j : topics_json) listed = listed || j["topic"] == s->topic;
    if (!listed)
      topics_json.push_back({{"topic", s->topic},
                             {"records", s->time.size()},
                             {"records_in_range", used},
                             {"rate_hz", used > 0 ? static_cast<double>(used) / (t1 - t0) : 0.0},
                             {"largest_gap_s", gap}});
  }
  return topics_json;
}

// Interpolates the topics at successive times: the records last used are where the next search starts.
class Resampler {
 public:
  Resampler(const Topics& topics, const VehicleLogSpec& spec, const std::string& file)
      : topics_(topics), spec_(spec), file_(file) {}

  // The pipeline's state at t, from the log's conventions (heli/vehicle_file.hpp; no arithmetic under the
  // defaults).
  std::array<double, sysid::kLogStates> state(double t) {
    ip_ = record_at(topics_.position, t, ip_);
    iv_ = record_at(topics_.velocity, t, iv_);
    ia_ = record_at(topics_.attitude, t, ia_);
    ir_ = record_at(topics_.rates, t, ir_);
    const Vec3 p_W =
        world_vector_of(spec_, interpolate3(topics_.position, ip_, weight_at(topics_.position, ip_, t)));
    const Euler e =
        euler_of(spec_, attitude_at(topics_.attitude, ia_, weight_at(topics_.attitude, ia_, t), spec_));
    Vec3 v = interpolate3(topics_.velocity, iv_, weight_at(topics_.velocity, iv_, t));
    v = spec_.velocity_frame == "body" ? heli::world_from_body(e, body_vector_of(spec_, v))
                                       : world_vector_of(spec_, v);
    Vec3 w = interpolate3(topics_.rates, ir_, weight_at(topics_.rates, ir_, t));
    if (spec_.rates_unit != "rad/s") w *= radians_per_rates_unit(spec_);
    w = spec_.rates_form == "body" ? heli::euler_rates_from_body_rates(e, body_vector_of(spec_, w))
                                   : euler_rates_of(spec_, w);
    std::array<double, sysid::kLogStates> s = {p_W.x(), p_W.y(), p_W.z(), e.roll, e.pitch, e.yaw,
                                               v.x(),   v.y(),   v.z(),   w.x(),  w.y(),   w.z()};
    for (std::size_t j = 0; j < s.size(); ++j)
      if (!std::isfinite(s[j]))
        throw InputError(
            fmt::format("{}: at t = {:.3f} s the {} column is not finite (a NaN in the log's topics)", file_,
                        t, sysid::kLogStateColumns[j]));
    return s;
  }

  // The controls at t (the last record at or before it), scaled and offset into [-1, 1].
  void controls(double t, std::array<double, 4>& out) {
    for (std::size_t c = 0; c < 4; ++c) {
      const Series& series = topics_.controls[c];
      ic_[c] = record_at(series, t, ic_[c]);
      const double raw = series.fields[0][ic_[c]];
      const double a = spec_.controls[c].scale * raw + spec_.controls[c].offset;
      const int column = spec_.controls[c].column(c);
      if (!(std::abs(a) <= 1 + 1e-6))
        throw InputError(
            fmt::format("{}: byte {}: {}.{} = {} at t = {:.3f} s gives a{} = {}; expected [-1, 1] after the "
                        "scale and offset of {}",
                        file_, series.bytes[ic_[c]], spec_.controls[c].topic, spec_.controls[c].field, raw, t,
                        column + 1, a, spec_.file));
      out[static_cast<std::size_t>(column)] = std::clamp(a, -1.0, 1.0);
    }
  }

 private:
  const Topics& topics_;
  const VehicleLogSpec& spec_;
  const std::string& file_;
  std::size_t ip_ = 0, iv_ = 0, ia_ = 0, ir_ = 0;
  std::array<std::size_t, 4> ic_{};
};

// What was imported, from where, and how the file looked (ImportProvenance).
nlohmann::json provenance_json(const UlogFile& ulog, const VehicleLogSpec& spec, const TimeRange& range,
                               std::size_t rows, nlohmann::json topics_json) {
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
    control_json.push_back({{"column", fmt::format("a{}", spec.controls[c].column(c) + 1)},
                            {"topic", spec.controls[c].topic},
                            {"field", spec.controls[c].field},
                            {"scale", spec.controls[c].scale},
                            {"offset", spec.controls[c].offset}});
  nlohmann::json out = {
      {"vehicle", spec.vehicle},
      {"vehicle_file", spec.file},
      {"instance", spec.instance},
      {"rate_hz", spec.rate_hz},
      {"rows", rows},
      {"time_range_s", {range.t0, range.t0 + static_cast<double>(rows - 1) * range.dt}},
      {"common_range_s", {range.common_start, range.t1}},
      {"topics", std::move(topics_json)},
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
    if (const auto it = ulog.info.find(key); it != ulog.info.end()) out["ulog"][key] = it->second.raw;
  return out;
}

}  // namespace

sysid::FlightLog import_ulog(const UlogFile& ulog, const VehicleLogSpec& spec, const std::string& file,
                             const ImportOptions& options, ImportProvenance* provenance) {
  const Topics topics = read_topics(ulog, spec, file);
  const TimeRange range = time_range(topics, spec, file, options);
  nlohmann::json topics_json = check_gaps(topics, range, spec, file);

  const std::size_t rows = range.rows();
  sysid::FlightLog log;
  log.time.resize(rows);
  log.states.resize(rows);
  log.controls.resize(rows);
  Resampler resample(topics, spec, file);
  for (std::size_t k = 0; k < rows; ++k) {
    const double t = range.t0 + static_cast<double>(k) * range.dt;
    log.time[k] = static_cast<double>(k) * range.dt;
    log.states[k] = resample.state(t);
    resample.controls(t, log.controls[k]);
  }
  if (provenance) provenance->json = provenance_json(ulog, spec, range, rows, std::move(topics_json));
  return log;
}

}  // namespace pegasus::logs
