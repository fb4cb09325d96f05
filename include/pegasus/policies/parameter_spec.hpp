#pragma once
// The tunable parameters of a policy class (thesis §4.1): names, initial values, bounds and scales.
#include <cstddef>
#include <limits>
#include <span>
#include <string>
#include <vector>

namespace pegasus {

using Theta = std::vector<double>;

struct Parameter {
  std::string name;
  double initial = 0.0;
  double lower = -std::numeric_limits<double>::infinity();
  double upper = std::numeric_limits<double>::infinity();
  // Typical size of a useful change; optimizers scale derivatives and steps by it (thesis §5.3).
  double scale = 1.0;
  // Integer-valued (e.g. the action chosen by a table entry); only exhaustive search enumerates these.
  bool integer = false;
};

class ParameterSpec {
 public:
  ParameterSpec() = default;
  explicit ParameterSpec(std::vector<Parameter> parameters);

  // Adds a parameter; names must be unique and lower <= initial <= upper, scale > 0.
  ParameterSpec& add(Parameter parameter);

  std::size_t size() const { return parameters_.size(); }
  const Parameter& operator[](std::size_t i) const { return parameters_[i]; }
  const std::vector<Parameter>& all() const { return parameters_; }

  Theta initial() const;
  Theta lower() const;
  Theta upper() const;
  Theta scales() const;
  // Index of the named parameter, or size() when absent.
  std::size_t index_of(const std::string& name) const;
  // The first integer parameter, or size() when there is none (only exhaustive search then keeps theta in
  // whole numbers).
  std::size_t first_integer() const;

  // Clamps theta into the bounds in place.
  void clamp(std::span<double> theta) const;
  // True when theta has the right size and lies within the bounds.
  bool contains(std::span<const double> theta) const;
  // Empty when each integer parameter's value in theta (of this spec's size) is a whole number within its
  // bounds, else what was expected of the first that is not ("action[3]: expected an integer in [0, 3], got
  // 7"): a table entry beyond its bounds would index past the table.
  std::string integer_violation(std::span<const double> theta) const;

 private:
  std::vector<Parameter> parameters_;
};

}  // namespace pegasus
