#include "pegasus/mujoco/mujoco_policy.hpp"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "pegasus/core/error.hpp"
#include "pegasus/core/named_registry.hpp"
#include "pegasus/core/or_list.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/optimizers/run_progress.hpp"

namespace pegasus {

void ObservationNormalizer::apply(std::span<const double> observation, std::span<double> z) const {
  for (std::size_t k = 0; k < observation.size(); ++k)
    z[k] = std::clamp((observation[k] - mean[k]) * inverse_std[k], -clip, clip);
}

void ObservationMoments::reset() {
  count = 0.0;
  std::fill(mean.begin(), mean.end(), 0.0);
  std::fill(m2.begin(), m2.end(), 0.0);
}

void ObservationMoments::add(std::span<const double> observation) {
  count += 1.0;
  for (std::size_t k = 0; k < observation.size(); ++k) {
    const double delta = observation[k] - mean[k];
    mean[k] += delta / count;
    m2[k] += delta * (observation[k] - mean[k]);
  }
}

void ObservationMoments::merge(const ObservationMoments& other) {
  if (other.count == 0.0) return;
  const double total = count + other.count;
  for (std::size_t k = 0; k < mean.size(); ++k) {
    const double delta = other.mean[k] - mean[k];
    mean[k] += delta * other.count / total;
    m2[k] += other.m2[k] + delta * delta * count * other.count / total;
  }
  count = total;
}

void ObservationMoments::freeze_into(ObservationNormalizer* normalizer) const {
  for (std::size_t k = 0; k < mean.size(); ++k) {
    normalizer->mean[k] = mean[k];
    const double variance = count > 1.0 ? m2[k] / count : 0.0;
    normalizer->inverse_std[k] = variance < 1e-8 ? 1.0 : 1.0 / std::sqrt(variance);
  }
}

nlohmann::json ObservationMoments::to_json() const {
  return {{"count", DoubleToJson(count)}, {"mean", VectorToJson(mean)}, {"m2", VectorToJson(m2)}};
}

ObservationMoments ObservationMoments::from_json(const nlohmann::json& state, int dim) {
  ObservationMoments out(dim);
  out.count = DoubleFromJson(StateField(state, "count"), "normalizer.count");
  out.mean = VectorFromJson(StateField(state, "mean"), "normalizer.mean");
  out.m2 = VectorFromJson(StateField(state, "m2"), "normalizer.m2");
  if (out.mean.size() != static_cast<std::size_t>(dim) || out.m2.size() != static_cast<std::size_t>(dim))
    throw InputError(fmt::format("normalizer: expected {} observation dimensions", dim));
  return out;
}

namespace {

using MatrixMap = Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
using VectorMap = Eigen::Map<const Eigen::VectorXd>;

class LinearPolicy final : public MujocoPolicy {
 public:
  LinearPolicy(int d, int nu) : d_(d), nu_(nu) {
    for (int k = 0; k < nu; ++k) {
      for (int f = 0; f < d; ++f) spec_.add({.name = fmt::format("W[{}][{}]", k, f)});
      spec_.add({.name = fmt::format("b[{}]", k)});
    }
  }
  const ParameterSpec& parameters() const override { return spec_; }
  void act(std::span<const double> theta, std::span<const double>, std::span<const double> z,
           std::span<double> action, std::span<double>) const override {
    // Row k of theta is (W_k, b_k).
    for (int k = 0; k < nu_; ++k) {
      const double* w = theta.data() + static_cast<std::size_t>(k) * static_cast<std::size_t>(d_ + 1);
      double a = w[d_];
      for (int f = 0; f < d_; ++f) a += w[f] * z[static_cast<std::size_t>(f)];
      action[static_cast<std::size_t>(k)] = std::clamp(a, -1.0, 1.0);
    }
  }
  nlohmann::json describe() const override {
    return {{"class", "linear"}, {"hidden", nlohmann::json::array()}};
  }

 private:
  int d_, nu_;
  ParameterSpec spec_;
};

class TanhMlpPolicy final : public MujocoPolicy {
 public:
  TanhMlpPolicy(int d, int nu, std::vector<int> hidden) : hidden_(std::move(hidden)) {
    widths_.push_back(d);
    widths_.insert(widths_.end(), hidden_.begin(), hidden_.end());
    widths_.push_back(nu);
    for (std::size_t layer = 0; layer + 1 < widths_.size(); ++layer) {
      for (int o = 0; o < widths_[layer + 1]; ++o)
        for (int i = 0; i < widths_[layer]; ++i)
          spec_.add({.name = fmt::format("L{}.W[{}][{}]", layer, o, i)});
      for (int o = 0; o < widths_[layer + 1]; ++o) spec_.add({.name = fmt::format("L{}.b[{}]", layer, o)});
    }
    for (int w : hidden_) scratch_ += 2 * w;
  }
  const ParameterSpec& parameters() const override { return spec_; }
  int scratch_size() const override { return scratch_; }
  void act(std::span<const double> theta, std::span<const double>, std::span<const double> z,
           std::span<double> action, std::span<double> scratch) const override {
    const double* input = z.data();
    const double* w = theta.data();
    double* buffers[2] = {scratch.data(), scratch.data() + (scratch.size() / 2)};
    for (std::size_t layer = 0; layer + 1 < widths_.size(); ++layer) {
      const int in = widths_[layer], out = widths_[layer + 1];
      const bool last = layer + 2 == widths_.size();
      double* output = last ? action.data() : buffers[layer % 2];
      const MatrixMap weights(w, out, in);
      const VectorMap bias(w + static_cast<std::ptrdiff_t>(out) * in, out);
      Eigen::Map<Eigen::VectorXd> y(output, out);
      y.noalias() = weights * VectorMap(input, in);
      y = (y + bias).array().tanh().matrix();
      w += static_cast<std::ptrdiff_t>(out) * (in + 1);
      input = output;
    }
  }
  nlohmann::json describe() const override { return {{"class", "mlp"}, {"hidden", hidden_}}; }

 private:
  std::vector<int> hidden_, widths_;
  int scratch_ = 0;
  ParameterSpec spec_;
};

// Two policies of one class: theta is the "below" half, then the "above" half; the raw observation number at
// phase.position chooses the half of each step (so the switch does not move with the normaliser).
class PhasedPolicy final : public MujocoPolicy {
 public:
  PhasedPolicy(std::unique_ptr<MujocoPolicy> below, std::unique_ptr<MujocoPolicy> above, PolicyPhase phase)
      : below_(std::move(below)), above_(std::move(above)), phase_(std::move(phase)) {
    half_ = below_->parameters().size();
    for (const auto& [half, prefix] : {std::pair{below_.get(), "below."}, std::pair{above_.get(), "above."}})
      for (Parameter p : half->parameters().all()) {
        p.name = prefix + p.name;
        spec_.add(std::move(p));
      }
  }
  const ParameterSpec& parameters() const override { return spec_; }
  int scratch_size() const override { return below_->scratch_size(); }
  void act(std::span<const double> theta, std::span<const double> observation, std::span<const double> z,
           std::span<double> action, std::span<double> scratch) const override {
    const bool above = observation[static_cast<std::size_t>(phase_.position)] > phase_.above;
    (above ? above_ : below_)->act(theta.subspan(above ? half_ : 0, half_), observation, z, action, scratch);
  }
  nlohmann::json describe() const override {
    nlohmann::json out = below_->describe();
    out["phase"] = policy_phase_json(phase_);
    return out;
  }

 private:
  std::unique_ptr<MujocoPolicy> below_, above_;
  PolicyPhase phase_;
  std::size_t half_ = 0;
  ParameterSpec spec_;
};

constexpr int kMaxHiddenLayers = 16;
constexpr int kMaxWidth = 4096;

// The classes every build knows, in the order that lists of them give.
std::vector<MujocoPolicyClass> builtin_classes() {
  return {
      {.name = "linear",
       .doc = "a = clip(W z + b, -1, 1) on the normalised observation z",
       .hidden_layers = false,
       .make = [](int d, int nu, const std::vector<int>&) { return std::make_unique<LinearPolicy>(d, nu); }},
      {.name = "mlp",
       .doc = "tanh layers of the `hidden` widths, then a tanh output layer",
       .hidden_layers = true,
       .make = [](int d, int nu, const std::vector<int>& hidden) {
         return std::make_unique<TanhMlpPolicy>(d, nu, hidden);
       }}};
}

NamedRegistry<MujocoPolicyClass>& class_registry() {
  static NamedRegistry<MujocoPolicyClass> r(builtin_classes());
  return r;
}

std::optional<MujocoPolicyClass> find_policy_class(const std::string& name) {
  return class_registry().find(name);
}

std::unique_ptr<MujocoPolicy> make_unphased_policy(const std::string& kind, int observation_dim,
                                                   int action_dim, const std::vector<int>& hidden) {
  const std::optional<MujocoPolicyClass> c = find_policy_class(kind);
  if (!c)
    throw InputError(fmt::format("policy: expected {}, got \"{}\"", or_list(mujoco_policy_class_names()),
                                 printable(kind)));
  if (c->hidden_layers) {
    if (hidden.empty())
      throw InputError(fmt::format("hidden: expected at least one hidden layer for policy = {}", kind));
    for (int w : hidden)
      if (w < 1 || w > kMaxWidth)
        throw InputError(fmt::format("hidden: expected widths in [1, {}], got {}", kMaxWidth, w));
  }
  std::unique_ptr<MujocoPolicy> policy =
      c->make(observation_dim, action_dim, c->hidden_layers ? hidden : std::vector<int>{});
  if (!policy || policy->describe().value("class", std::string()) != kind)
    throw std::logic_error(
        fmt::format("MuJoCo policy class {}: its factory's policy describes another class", printable(kind)));
  return policy;
}

}  // namespace

nlohmann::json policy_phase_json(const PolicyPhase& phase) {
  if (!phase.phased()) return nullptr;
  return {{"observation", phase.observation}, {"above", phase.above}};
}

std::unique_ptr<MujocoPolicy> make_mujoco_policy(const std::string& kind, int observation_dim, int action_dim,
                                                 const std::vector<int>& hidden, const PolicyPhase& phase) {
  if (!phase.phased()) return make_unphased_policy(kind, observation_dim, action_dim, hidden);
  if (phase.position < 0 || phase.position >= observation_dim)
    throw InputError(fmt::format("phase_observation: \"{}\" is not resolved in an observation of {} numbers",
                                 printable(phase.observation), observation_dim));
  if (!std::isfinite(phase.above))
    throw InputError(fmt::format("phase_above: expected a finite number, got {}", phase.above));
  return std::make_unique<PhasedPolicy>(make_unphased_policy(kind, observation_dim, action_dim, hidden),
                                        make_unphased_policy(kind, observation_dim, action_dim, hidden),
                                        phase);
}

void register_mujoco_policy_class(MujocoPolicyClass policy_class) {
  class_registry().add(std::move(policy_class));
}

std::vector<MujocoPolicyClass> mujoco_policy_classes() { return class_registry().entries(); }

std::vector<std::string> mujoco_policy_class_names() {
  std::vector<std::string> names;
  for (const MujocoPolicyClass& c : mujoco_policy_classes()) names.push_back(c.name);
  return names;
}

nlohmann::json mujoco_policy_file_json(const MujocoPolicyFile& f) {
  nlohmann::json j = {{"format", kMujocoPolicyFormat},
                      {"version", kMujocoPolicyVersion},
                      {"model", f.model},
                      {"task", f.task},
                      {"class", f.policy_class},
                      {"hidden", f.hidden},
                      {"phase", policy_phase_json(f.phase)},
                      {"theta", f.theta},
                      {"normalizer",
                       {{"mean", f.normalizer.mean},
                        {"inverse_std", f.normalizer.inverse_std},
                        {"clip", f.normalizer.clip}}}};
  if (!f.model_digest.empty()) j["model_digest"] = f.model_digest;
  if (!f.task_digest.empty()) j["task_digest"] = f.task_digest;
  if (!f.task_content_digest.empty()) j["task_content_digest"] = f.task_content_digest;
  return j;
}

namespace {

// The registered class that a policy file's "class" names.
MujocoPolicyClass class_of_file(const nlohmann::json& name, const std::string& file) {
  std::optional<MujocoPolicyClass> found;
  if (name.is_string()) found = find_policy_class(name.get<std::string>());
  if (!found) {
    std::vector<std::string> quoted;
    for (const std::string& n : mujoco_policy_class_names()) quoted.push_back(fmt::format("\"{}\"", n));
    json_field_error(file, "class", or_list(quoted), name);
  }
  return *found;
}

// A policy file's "hidden": 1 to kMaxHiddenLayers widths for a class with hidden layers, else [].
std::vector<int> hidden_of_file(const nlohmann::json& hidden, const MujocoPolicyClass& policy_class,
                                const std::string& file) {
  const bool layers = policy_class.hidden_layers;
  if (!hidden.is_array() || hidden.size() > static_cast<std::size_t>(layers ? kMaxHiddenLayers : 0) ||
      (layers && hidden.empty()))
    json_field_error(file, "hidden",
                     layers ? fmt::format("an array of 1 to {} layer widths", kMaxHiddenLayers)
                            : fmt::format("[] (a {} policy has no hidden layer)", policy_class.name),
                     hidden);
  std::vector<int> widths;
  for (std::size_t i = 0; i < hidden.size(); ++i) {
    const nlohmann::json& w = hidden[i];
    if (!w.is_number_integer() || w.get<std::int64_t>() < 1 || w.get<std::int64_t>() > kMaxWidth)
      json_field_error(file, fmt::format("hidden[{}]", i), fmt::format("a width in [1, {}]", kMaxWidth), w);
    widths.push_back(w.get<int>());
  }
  return widths;
}

}  // namespace

MujocoPolicyFile parse_mujoco_policy_file(const nlohmann::json& j, const std::string& file) {
  json_format_header(j, file, kMujocoPolicyFormat, kMujocoPolicyVersion,
                     "policy.json of `pegasus mujoco train`");
  MujocoPolicyFile f;
  f.model = json_nonempty_string(json_member(j, "model", file, "model"), file, "model");
  f.task = json_nonempty_string(json_member(j, "task", file, "task"), file, "task");
  for (const auto& [key, digest] : {std::pair{"model_digest", &f.model_digest},
                                    {"task_digest", &f.task_digest},
                                    {"task_content_digest", &f.task_content_digest}})
    if (j.contains(key)) *digest = json_nonempty_string(j.at(key), file, key);
  const MujocoPolicyClass policy_class = class_of_file(json_member(j, "class", file, "class"), file);
  f.policy_class = policy_class.name;
  f.hidden = hidden_of_file(json_member(j, "hidden", file, "hidden"), policy_class, file);
  // "phase" came with phased policies: a file without it (or with null) holds an unphased one.
  if (const auto phase = j.find("phase"); phase != j.end() && !phase->is_null()) {
    if (!phase->is_object())
      json_field_error(file, "phase", "null or an object (observation, above)", *phase);
    f.phase.observation = json_nonempty_string(json_member(*phase, "observation", file, "phase.observation"),
                                               file, "phase.observation");
    const nlohmann::json& above = json_member(*phase, "above", file, "phase.above");
    if (!above.is_number() || !std::isfinite(above.get<double>()))
      json_field_error(file, "phase.above", "a finite number", above);
    f.phase.above = above.get<double>();
  }
  f.theta = json_finite_numbers(json_member(j, "theta", file, "theta"), file, "theta");
  // What the hidden layers alone need (any observation and action have at least one dimension): a file
  // whose theta cannot hold them is refused here, before a policy of that shape is built.
  std::size_t least = 0;
  for (std::size_t l = 0; l < f.hidden.size(); ++l) {
    const std::size_t inputs = l == 0 ? 1 : static_cast<std::size_t>(f.hidden[l - 1]);
    least += (inputs + 1) * static_cast<std::size_t>(f.hidden[l]);
  }
  if (!f.hidden.empty()) least += static_cast<std::size_t>(f.hidden.back()) + 1;
  if (f.theta.size() < std::max<std::size_t>(least, 2))
    json_field_error(
        file, "theta",
        fmt::format("at least {} numbers for this class and hidden layers", std::max<std::size_t>(least, 2)),
        f.theta.size());
  const nlohmann::json& normalizer = json_member(j, "normalizer", file, "normalizer");
  if (!normalizer.is_object())
    json_field_error(file, "normalizer", "an object (mean, inverse_std, clip)", normalizer);
  f.normalizer.mean =
      json_finite_numbers(json_member(normalizer, "mean", file, "normalizer.mean"), file, "normalizer.mean");
  f.normalizer.inverse_std = json_finite_numbers(
      json_member(normalizer, "inverse_std", file, "normalizer.inverse_std"), file, "normalizer.inverse_std");
  if (f.normalizer.inverse_std.size() != f.normalizer.mean.size())
    json_field_error(file, "normalizer.inverse_std",
                     fmt::format("{} numbers, as many as normalizer.mean", f.normalizer.mean.size()),
                     normalizer.at("inverse_std").size());
  for (std::size_t k = 0; k < f.normalizer.inverse_std.size(); ++k)
    if (!(f.normalizer.inverse_std[k] > 0))
      json_field_error(file, fmt::format("normalizer.inverse_std[{}]", k), "a positive number",
                       f.normalizer.inverse_std[k]);
  const nlohmann::json& clip = json_member(normalizer, "clip", file, "normalizer.clip");
  if (!clip.is_number() || !(clip.get<double>() > 0) || !std::isfinite(clip.get<double>()))
    json_field_error(file, "normalizer.clip", "a positive finite number", clip);
  f.normalizer.clip = clip.get<double>();
  return f;
}

MujocoPolicyFile read_mujoco_policy_file(const std::filesystem::path& file) {
  return parse_mujoco_policy_file(read_json_input(file, "policy"), file.string());
}

void check_mujoco_policy_file(const MujocoPolicyFile& f, const MujocoPolicy& policy, int dim,
                              const std::string& file) {
  if (f.theta.size() != policy.parameters().size())
    throw InputError(
        fmt::format("{}: theta: expected {} numbers for this model, task and policy class, got {}",
                    printable(file), policy.parameters().size(), f.theta.size()));
  if (f.normalizer.mean.size() != static_cast<std::size_t>(dim))
    throw InputError(fmt::format("{}: normalizer.mean: expected {} observation dimensions, got {}",
                                 printable(file), dim, f.normalizer.mean.size()));
}

}  // namespace pegasus
