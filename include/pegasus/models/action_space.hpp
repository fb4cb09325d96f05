#pragma once
// The action space of a model: finite (actions 0..count-1) or a box of real vectors.
#include <string>
#include <vector>

namespace pegasus {

class ActionSpace {
 public:
  static ActionSpace finite(int count);
  static ActionSpace box(std::vector<double> low, std::vector<double> high);

  bool is_finite() const { return count_ > 0; }
  // Number of actions of a finite space (0 for a box).
  int count() const { return count_; }
  // Dimension of a box (1 for a finite space: the action index).
  int dim() const { return is_finite() ? 1 : static_cast<int>(low_.size()); }
  const std::vector<double>& low() const { return low_; }
  const std::vector<double>& high() const { return high_; }
  std::string describe() const;

 private:
  int count_ = 0;
  std::vector<double> low_, high_;
};

}  // namespace pegasus
