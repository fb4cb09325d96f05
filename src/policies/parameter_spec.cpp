#include "pegasus/policies/parameter_spec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "pegasus/core/error.hpp"

namespace pegasus {

ParameterSpec::ParameterSpec(std::vector<Parameter> parameters) {
  for (auto& p : parameters) add(std::move(p));
}

ParameterSpec& ParameterSpec::add(Parameter p) {
  if (p.name.empty()) throw InputError("parameter: expected a non-empty name");
  if (index_of(p.name) != size()) throw InputError("parameter " + p.name + ": name already used");
  if (!(p.lower <= p.initial && p.initial <= p.upper))
    throw InputError("parameter " + p.name + ": expected lower <= initial <= upper");
  // An optimizer starts from the initial value: an infinite one gives every method U-hat -inf.
  if (!std::isfinite(p.initial))
    throw InputError(fmt::format("parameter {}: expected a finite initial value, got {}", p.name, p.initial));
  if (p.integer && p.initial != std::floor(p.initial))
    throw InputError(fmt::format(
        "parameter {}: expected a whole initial value (an integer parameter), got {}", p.name, p.initial));
  if (!(p.scale > 0.0) || !std::isfinite(p.scale))
    throw InputError("parameter " + p.name + ": expected a finite scale > 0");
  parameters_.push_back(std::move(p));
  return *this;
}

Theta ParameterSpec::initial() const {
  Theta t;
  for (const auto& p : parameters_) t.push_back(p.initial);
  return t;
}
Theta ParameterSpec::lower() const {
  Theta t;
  for (const auto& p : parameters_) t.push_back(p.lower);
  return t;
}
Theta ParameterSpec::upper() const {
  Theta t;
  for (const auto& p : parameters_) t.push_back(p.upper);
  return t;
}
Theta ParameterSpec::scales() const {
  Theta t;
  for (const auto& p : parameters_) t.push_back(p.scale);
  return t;
}

std::size_t ParameterSpec::index_of(const std::string& name) const {
  for (std::size_t i = 0; i < parameters_.size(); ++i)
    if (parameters_[i].name == name) return i;
  return parameters_.size();
}

void ParameterSpec::clamp(std::span<double> theta) const {
  for (std::size_t i = 0; i < theta.size() && i < parameters_.size(); ++i)
    theta[i] = std::clamp(theta[i], parameters_[i].lower, parameters_[i].upper);
}

std::size_t ParameterSpec::first_integer() const {
  for (std::size_t i = 0; i < parameters_.size(); ++i)
    if (parameters_[i].integer) return i;
  return parameters_.size();
}

std::string ParameterSpec::integer_violation(std::span<const double> theta) const {
  for (std::size_t i = 0; i < theta.size() && i < parameters_.size(); ++i) {
    const Parameter& p = parameters_[i];
    const double x = theta[i];
    if (p.integer && !(x >= p.lower && x <= p.upper && x == std::floor(x)))
      return fmt::format("{}: expected an integer in [{}, {}], got {}", p.name, p.lower, p.upper, x);
  }
  return {};
}

bool ParameterSpec::contains(std::span<const double> theta) const {
  if (theta.size() != parameters_.size()) return false;
  for (std::size_t i = 0; i < theta.size(); ++i)
    if (!(theta[i] >= parameters_[i].lower && theta[i] <= parameters_[i].upper)) return false;
  return true;
}

}  // namespace pegasus
