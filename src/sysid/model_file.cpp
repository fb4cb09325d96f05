// The model file (model.json, "pegasus-heli-model" version 1): the identified model written out, and read
// back with every field checked for meaning where it is read.
#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <string>

#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/sysid/identify.hpp"

namespace pegasus::sysid {

nlohmann::json IdentifiedModel::to_json() const {
  nlohmann::json j;
  j["format"] = "pegasus-heli-model";
  j["version"] = 1;
  j["structure"] = {{"rate_hz", structure_.rate_hz},
                    {"extra_states", structure_.extra_states},
                    {"intercept", structure_.intercept},
                    {"templates", structure_.templates},
                    {"gravity", structure_.gravity},
                    {"tau_flap", structure_.extra.tau_flap},
                    {"flap_per_a1", structure_.extra.flap_per_a1},
                    {"flap_per_a2", structure_.extra.flap_per_a2},
                    {"gyro_tau", structure_.extra.gyro_tau}};
  for (int c = 0; c < kInputs; ++c)
    if (structure_.constant_inputs[static_cast<std::size_t>(c)])
      j["structure"]["constant_inputs"].push_back(kInputNames[static_cast<std::size_t>(c)]);
  if (!vehicle_.empty()) j["vehicle"] = vehicle_;  // files without a vehicle stay as they were
  j["dt"] = dt();
  j["inputs"] = kInputNames;
  j["outputs"] = kBodyVarNames;
  j["inv_bandwidth"] = inv_bandwidth();
  j["sigma2"] = std::vector<double>(sigma2_.data(), sigma2_.data() + kBodyVars);
  const auto values = [](const BodyVec& v) { return std::vector<double>(v.data(), v.data() + kBodyVars); };
  if (correlation_.any()) {  // only then: white-noise model files stay as they were
    j["noise"] = {{"model", correlation_.has_measurement() ? "ar1+measurement" : "ar1"},
                  {"share", values(correlation_.share)},
                  {"rho", values(correlation_.rho)}};
    if (correlation_.has_measurement()) {
      j["noise"]["measurement_share"] = values(correlation_.measurement_share);
      j["noise"]["measurement_rho"] = values(correlation_.measurement_rho);
      j["noise"]["measurement_persistence"] = values(correlation_.measurement_persistence);
      // Only when the calibration added one: other files stay as they were.
      if ((correlation_.measurement_white_share.array() > 0).any())
        j["noise"]["measurement_white_share"] = values(correlation_.measurement_white_share);
    }
  }
  if (!horizon_sd_factors_.empty()) {  // only then: files without them stay as they were
    nlohmann::json factors = nlohmann::json::array();
    for (const BodyVec& f : horizon_sd_factors_) factors.push_back(values(f));
    j["horizon_sd_factors"] = factors;
  }
  if (!model_choice_.is_null()) {  // only when identify chose the class: other files stay as they were
    j["model_choice"] = model_choice_;
    if (alternative_inv_bandwidth_)
      j["model_choice"]["alternative_inv_bandwidth"] = *alternative_inv_bandwidth_;
  }
  nlohmann::json xs = nlohmann::json::array(), ys = nlohmann::json::array();
  for (Eigen::Index i = 0; i < data_->rows(); ++i) {
    std::vector<double> xr(kInputs), yr(kBodyVars);
    for (int c = 0; c < kInputs; ++c) xr[static_cast<std::size_t>(c)] = data_->x(i, c);
    for (int c = 0; c < kBodyVars; ++c) yr[static_cast<std::size_t>(c)] = data_->y(i, c);
    xs.push_back(xr);
    ys.push_back(yr);
  }
  j["x"] = xs;
  j["y"] = ys;
  j["time"] = data_->time;
  return j;
}

namespace {

// The fields of a model.json, each checked for meaning where it is read: a model that passes trains to
// finite values (issue 16: gravity 1e308 trained to U-hat -inf; version 4294967297 read as 1).
class ModelFields {
 public:
  explicit ModelFields(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }

  // The member a dotted field names (its last component) of the object j.
  const nlohmann::json& at(const nlohmann::json& j, const std::string& field) const {
    if (!j.is_object()) json_field_error(file_, field, "an object holding it", j);
    return json_member(j, field.substr(field.rfind('.') + 1).c_str(), file_, field);
  }
  double number(const nlohmann::json& j, const std::string& field, double lo, double hi,
                bool open_lo = false) const {
    return json_number_in(at(j, field), file_, field, lo, hi, open_lo);
  }
  bool flag(const nlohmann::json& j, const std::string& field) const {
    return json_flag(at(j, field), file_, field);
  }
  // An array of exactly `size` finite numbers (any size when size is 0), each at least `lo`.
  std::vector<double> numbers(const nlohmann::json& v, const std::string& field, std::size_t size,
                              double lo = -std::numeric_limits<double>::max()) const {
    std::vector<double> out = json_finite_numbers(v, file_, field, size);
    for (std::size_t i = 0; i < out.size(); ++i)
      if (out[i] < lo)
        json_field_error(file_, fmt::format("{}[{}]", field, i), fmt::format("a number >= {}", lo), v[i]);
    return out;
  }

 private:
  std::string file_;
};

// model.json's "structure".
ModelStructure read_model_structure(const ModelFields& f, const nlohmann::json& j) {
  constexpr double kMax = std::numeric_limits<double>::max();
  ModelStructure m;
  const auto& s = f.at(j, "structure");
  m.rate_hz = f.number(s, "structure.rate_hz", 0, 1000, true);
  m.extra_states = f.flag(s, "structure.extra_states");
  m.intercept = f.flag(s, "structure.intercept");
  m.templates = f.flag(s, "structure.templates");
  m.gravity = f.number(s, "structure.gravity", 0, 100);  // m/s^2: Earth's 9.81, room for other bodies
  m.extra.tau_flap = f.number(s, "structure.tau_flap", 0, 100, true);  // s, a first-order lag
  m.extra.flap_per_a1 = f.number(s, "structure.flap_per_a1", -kMax, kMax);
  m.extra.flap_per_a2 = f.number(s, "structure.flap_per_a2", -kMax, kMax);
  m.extra.gyro_tau = f.number(s, "structure.gyro_tau", 0, 100, true);
  if (s.contains("constant_inputs"))
    for (const auto& name : s.at("constant_inputs")) {
      const auto it = std::find(kInputNames.begin(), kInputNames.end(), name.get<std::string>());
      if (it == kInputNames.end() || it == kInputNames.end() - 1)
        throw InputError(fmt::format("model: unknown constant input '{}'", name.get<std::string>()));
      m.constant_inputs[static_cast<std::size_t>(it - kInputNames.begin())] = true;
    }
  return m;
}

// model.json's data: "dt", the rows "x" and "y", and their "time".
Dataset read_model_data(const ModelFields& f, const nlohmann::json& j) {
  const std::string& file = f.file();
  Dataset d;
  d.dt = f.number(j, "dt", 0, 100, true);
  const auto& xs = f.at(j, "x");
  const auto& ys = f.at(j, "y");
  if (!xs.is_array() || xs.empty()) json_field_error(file, "x", "a non-empty array of rows", xs);
  if (!ys.is_array() || ys.size() != xs.size())
    json_field_error(file, "y", fmt::format("an array of {} rows, as many as x", xs.size()), ys);
  const auto n = static_cast<Eigen::Index>(xs.size());
  d.x.resize(n, kInputs);
  d.y.resize(n, kBodyVars);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto row = static_cast<std::size_t>(i);
    const auto xr = f.numbers(xs[row], fmt::format("x[{}]", i), kInputs);
    const auto yr = f.numbers(ys[row], fmt::format("y[{}]", i), kBodyVars);
    for (int c = 0; c < kInputs; ++c) d.x(i, c) = xr[static_cast<std::size_t>(c)];
    for (int c = 0; c < kBodyVars; ++c) d.y(i, c) = yr[static_cast<std::size_t>(c)];
  }
  d.time = f.numbers(f.at(j, "time"), "time", xs.size());
  // The regression finds its window by binary search over time (window_rows).
  for (std::size_t i = 1; i < d.time.size(); ++i) {
    if (d.time[i] < d.time[i - 1])
      json_field_error(file, fmt::format("time[{}]", i), fmt::format("a time >= time[{}]", i - 1), d.time[i]);
  }
  return d;
}

// A share in [0, 1] and a correlation in [0, 1) per output, noise.<name> and noise.<rho_name>.
void read_share_and_rho(const ModelFields& f, const nlohmann::json& noise, const char* name,
                        BodyVec& share_out, const char* rho_name, BodyVec& rho_out) {
  const std::string& file = f.file();
  const std::string share_field = fmt::format("noise.{}", name),
                    rho_field = fmt::format("noise.{}", rho_name);
  const auto share = f.numbers(f.at(noise, share_field), share_field, kBodyVars, 0);
  const auto rho = f.numbers(f.at(noise, rho_field), rho_field, kBodyVars, 0);
  for (int k = 0; k < kBodyVars; ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (share[i] > 1)
      json_field_error(file, fmt::format("{}[{}]", share_field, k), "a number in [0, 1]", share[i]);
    if (!(rho[i] < 1))
      json_field_error(file, fmt::format("{}[{}]", rho_field, k), "a number in [0, 1)", rho[i]);
    share_out[k] = share[i];
    rho_out[k] = rho[i];
  }
}

// An "ar1+measurement" model's logged error: its share and correlation, its persistence, and a calibrated
// model's white logged error, each within what the shares before it leave.
void read_measurement_noise(const ModelFields& f, const nlohmann::json& noise,
                            NoiseCorrelation& correlation) {
  const std::string& file = f.file();
  read_share_and_rho(f, noise, "measurement_share", correlation.measurement_share, "measurement_rho",
                     correlation.measurement_rho);
  const auto persistence =
      f.numbers(f.at(noise, "noise.measurement_persistence"), "noise.measurement_persistence", kBodyVars, 0);
  for (int k = 0; k < kBodyVars; ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (persistence[i] > 1)
      json_field_error(file, fmt::format("noise.measurement_persistence[{}]", k), "a number in [0, 1]",
                       persistence[i]);
    correlation.measurement_persistence[k] = persistence[i];
  }
  for (int k = 0; k < kBodyVars; ++k)
    if (1 - correlation.share[k] - correlation.measurement_share[k] < 0)  // the white part, as flown
      json_field_error(file, fmt::format("noise.measurement_share[{}]", k),
                       fmt::format("a number in [0, {}] (1 - noise.share[{}])", 1 - correlation.share[k], k),
                       correlation.measurement_share[k]);
  if (noise.contains("measurement_white_share")) {  // a calibrated model's white logged error
    const auto white =
        f.numbers(noise.at("measurement_white_share"), "noise.measurement_white_share", kBodyVars, 0);
    for (int k = 0; k < kBodyVars; ++k) {
      const double left = 1 - correlation.share[k] - correlation.measurement_share[k];
      const auto i = static_cast<std::size_t>(k);
      if (white[i] > left)
        json_field_error(
            file, fmt::format("noise.measurement_white_share[{}]", k),
            fmt::format("a number in [0, {}] (1 - noise.share[{}] - noise.measurement_share[{}])", left, k,
                        k),
            white[i]);
      correlation.measurement_white_share[k] = white[i];
    }
  }
}

// model.json's "noise" (absent: white noise).
NoiseCorrelation read_noise_correlation(const ModelFields& f, const nlohmann::json& j) {
  NoiseCorrelation correlation;
  if (!j.contains("noise")) return correlation;
  const auto& noise = j.at("noise");
  const nlohmann::json& model = f.at(noise, "noise.model");
  if (model != "ar1" && model != "ar1+measurement")
    json_field_error(f.file(), "noise.model", "\"ar1\" or \"ar1+measurement\"", model);
  read_share_and_rho(f, noise, "share", correlation.share, "rho", correlation.rho);
  if (model == "ar1+measurement") read_measurement_noise(f, noise, correlation);
  return correlation;
}

// A calibrated model's "horizon_sd_factors" (absent: none).
std::vector<BodyVec> read_horizon_sd_factors(const ModelFields& f, const nlohmann::json& j) {
  const std::string& file = f.file();
  std::vector<BodyVec> sd_factors;
  if (const auto it = j.find("horizon_sd_factors"); it != j.end()) {  // a calibrated model's
    if (!it->is_array() || it->empty())
      json_field_error(file, "horizon_sd_factors", "a non-empty array of steps", *it);
    for (std::size_t t = 0; t < it->size(); ++t) {
      const std::string field = fmt::format("horizon_sd_factors[{}]", t);
      const auto factors = f.numbers((*it)[t], field, kBodyVars);
      BodyVec step;
      for (int k = 0; k < kBodyVars; ++k) {
        const auto i = static_cast<std::size_t>(k);
        if (!(factors[i] > 0))
          json_field_error(file, fmt::format("{}[{}]", field, k), "a number > 0", factors[i]);
        step[k] = factors[i];
      }
      sd_factors.push_back(step);
    }
  }
  return sd_factors;
}

// model.json read as `file`: every field checked where it is read.
IdentifiedModel model_from_json(const nlohmann::json& j, const std::string& file) {
  const ModelFields f(file);
  json_format_header(j, file, "pegasus-heli-model", 1);
  const ModelStructure m = read_model_structure(f, j);
  std::string vehicle;
  if (const auto it = j.find("vehicle"); it != j.end()) vehicle = json_nonempty_string(*it, file, "vehicle");
  Dataset d = read_model_data(f, j);
  const auto ih = f.numbers(f.at(j, "inv_bandwidth"), "inv_bandwidth", kInputs, 0);
  const auto s2 = f.numbers(f.at(j, "sigma2"), "sigma2", kBodyVars, 0);
  std::array<double, kInputs> inv{};
  std::copy(ih.begin(), ih.end(), inv.begin());
  BodyVec sigma2;
  for (int k = 0; k < kBodyVars; ++k) sigma2[k] = s2[static_cast<std::size_t>(k)];
  const NoiseCorrelation correlation = read_noise_correlation(f, j);
  std::vector<BodyVec> sd_factors = read_horizon_sd_factors(f, j);
  nlohmann::json choice;
  std::optional<std::array<double, kInputs>> alternative;
  if (const auto it = j.find("model_choice"); it != j.end()) {
    if (!it->is_object()) json_field_error(file, "model_choice", "an object", *it);
    choice = *it;
    if (const auto alt = it->find("alternative_inv_bandwidth"); alt != it->end()) {
      const auto values = f.numbers(*alt, "model_choice.alternative_inv_bandwidth", kInputs, 0);
      alternative.emplace();
      std::copy(values.begin(), values.end(), alternative->begin());
      choice.erase("alternative_inv_bandwidth");
    }
  }
  IdentifiedModel model(m, std::move(d), inv, sigma2, correlation);
  model.set_model_choice(std::move(choice), alternative);
  model.set_vehicle(std::move(vehicle));
  model.set_horizon_sd_factors(std::move(sd_factors));
  return model;
}

}  // namespace

IdentifiedModel IdentifiedModel::from_json(const nlohmann::json& j) {
  return model_from_json(j, "model.json");
}

void IdentifiedModel::save(const std::filesystem::path& file) const {
  write_file_atomic(file, to_json().dump() + "\n");
}

IdentifiedModel IdentifiedModel::load(const std::filesystem::path& file) {
  return model_from_json(read_json_input(file, "model"), file.string());
}

}  // namespace pegasus::sysid
