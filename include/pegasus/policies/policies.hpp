#pragma once
// Policy classes (thesis §4.1): a ParameterSpec plus act(theta, observation) -> action.
//   TablePolicy          a finite observation set mapped to finite actions (one integer parameter each)
//   LinearPolicy<N, F>   a = clip(W phi(o)) on a box action space
//   SigmoidPolicy<N, F>  a_k = low_k + (high_k - low_k) sigmoid(w_k . phi(o))   (§4.6, the bicycle)
//   ProgramPolicy        any C++ callable with named tunable parameters ("partial programs", §4.1):
//       auto pi = make_program_policy<double>(ParameterSpec({{.name = "gain", .initial = 1.0}}),
//           [](std::span<const double> w, const double& x) { return -w[0] * x; });
#include <algorithm>
#include <array>
#include <cmath>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/models/action_space.hpp"
#include "pegasus/policies/parameter_spec.hpp"

namespace pegasus {

template <class P, class Observation, class Action>
concept PolicyFor = requires(const P& pi, std::span<const double> theta, const Observation& o) {
  { pi.parameters() } -> std::convertible_to<const ParameterSpec&>;
  { pi.act(theta, o) } -> std::convertible_to<Action>;
};

class TablePolicy {
 public:
  // One integer parameter per observation, "action[o]" in [0, actions - 1], initially `initial_action`.
  TablePolicy(int observations, int actions, int initial_action = 0)
      : observations_(observations), actions_(actions) {
    if (observations < 1 || actions < 1)
      throw InputError("table policy: expected >= 1 observation and action");
    for (int o = 0; o < observations; ++o)
      spec_.add({.name = "action[" + std::to_string(o) + "]",
                 .initial = static_cast<double>(initial_action),
                 .lower = 0.0,
                 .upper = static_cast<double>(actions - 1),
                 .scale = 1.0,
                 .integer = true});
  }
  const ParameterSpec& parameters() const { return spec_; }
  int observations() const { return observations_; }
  int actions() const { return actions_; }
  // theta's entry, kept within [0, actions - 1] (so a theta outside the bounds never indexes past a table;
  // ParameterSpec::integer_violation names it for callers that check).
  int act(std::span<const double> theta, int observation) const {
    const double a = theta[static_cast<std::size_t>(observation)];
    return a >= 0 ? static_cast<int>(std::min(a, static_cast<double>(actions_ - 1))) : 0;
  }
  // The theta of policy number `index` in the mixed-radix enumeration (observation 0 least significant).
  std::vector<double> theta_of_index(std::uint64_t index) const {
    std::vector<double> theta(static_cast<std::size_t>(observations_));
    for (auto& a : theta) {
      a = static_cast<double>(index % static_cast<std::uint64_t>(actions_));
      index /= static_cast<std::uint64_t>(actions_);
    }
    return theta;
  }

 private:
  int observations_, actions_;
  ParameterSpec spec_;
};

// Features: a callable  void(const Observation&, std::span<double> phi)  plus  int size() const.
template <class Features>
concept FeatureMap = requires(const Features& f) {
  { f.size() } -> std::convertible_to<int>;
};

namespace detail {
inline ParameterSpec weight_spec(int outputs, int features, const std::vector<std::string>& output_names,
                                 const std::vector<std::string>& feature_names, double scale) {
  ParameterSpec spec;
  for (int k = 0; k < outputs; ++k)
    for (int f = 0; f < features; ++f) {
      const std::string out =
          k < static_cast<int>(output_names.size()) ? output_names[k] : "a" + std::to_string(k);
      const std::string in =
          f < static_cast<int>(feature_names.size()) ? feature_names[f] : "x" + std::to_string(f);
      spec.add({.name = "w." + out + "." + in, .initial = 0.0, .scale = scale});
    }
  return spec;
}
}  // namespace detail

// a = squash(W phi(o)) on a box action space: the shared body of LinearPolicy and SigmoidPolicy.
template <int N, FeatureMap Features, class Squash>
class FeaturePolicy {
 public:
  using Action = std::array<double, N>;
  FeaturePolicy(Features features, ActionSpace space, const std::vector<std::string>& output_names = {},
                const std::vector<std::string>& feature_names = {}, double scale = 1.0)
      : features_(std::move(features)), space_(std::move(space)) {
    if (space_.is_finite() || space_.dim() != N)
      throw InputError("feature policy: expected a box action space of dimension " + std::to_string(N));
    spec_ = detail::weight_spec(N, features_.size(), output_names, feature_names, scale);
  }
  const ParameterSpec& parameters() const { return spec_; }
  const Features& features() const { return features_; }
  template <class Observation>
  Action act(std::span<const double> theta, const Observation& o) const {
    std::array<double, 64> phi;
    const auto n = static_cast<std::size_t>(features_.size());
    features_(o, std::span<double>(phi.data(), n));
    Action a;
    for (std::size_t k = 0; k < static_cast<std::size_t>(N); ++k) {
      double z = 0;
      for (std::size_t f = 0; f < n; ++f) z += theta[k * n + f] * phi[f];
      a[k] = Squash{}(z, space_.low()[k], space_.high()[k]);
    }
    return a;
  }

 private:
  Features features_;
  ActionSpace space_;
  ParameterSpec spec_;
};

struct ClipToBox {
  double operator()(double z, double lo, double hi) const { return std::clamp(z, lo, hi); }
};
// low + (high - low) sigmoid(z), as the bicycle policy of §4.6.
struct SigmoidToBox {
  double operator()(double z, double lo, double hi) const { return lo + (hi - lo) / (1.0 + std::exp(-z)); }
};

template <int N, FeatureMap Features>
using LinearPolicy = FeaturePolicy<N, Features, ClipToBox>;
template <int N, FeatureMap Features>
using SigmoidPolicy = FeaturePolicy<N, Features, SigmoidToBox>;

template <class Observation, class Program>
class ProgramPolicy {
 public:
  ProgramPolicy(ParameterSpec spec, Program program) : spec_(std::move(spec)), program_(std::move(program)) {}
  const ParameterSpec& parameters() const { return spec_; }
  auto act(std::span<const double> theta, const Observation& o) const { return program_(theta, o); }

 private:
  ParameterSpec spec_;
  Program program_;
};

template <class Observation, class Program>
ProgramPolicy<Observation, Program> make_program_policy(ParameterSpec spec, Program program) {
  return ProgramPolicy<Observation, Program>(std::move(spec), std::move(program));
}

}  // namespace pegasus
