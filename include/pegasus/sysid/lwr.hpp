#pragma once
// Locally weighted linear regression (thesis §5.2.1, Eqs 5.2-5.4) over a Dataset, all outputs at once.
//
// The weight of training point i at query q is w_i = exp(-1/2 sum_j ((q_j - x_ij) / h_j)^2) with a diagonal
// bandwidth h (an input with h_j = infinity, inverse 0, is ignored by the kernel). For each output k the
// coefficients on the template's free inputs solve (X'WX) beta = X'Wy. Read as a Bayesian regression with a
// flat prior where point i has noise variance sigma^2 / w_i, the posterior covariance is
// Sigma_beta = sigma^2 (X'WX)^{-1}, so the predictive variance is sigma^2 (1 + x'(X'WX)^{-1}x) (Eq 5.4).
//
// Two paths that agree within 1e-9 relative:
//   fit_exact: the plain reference: every point, one normal-equation system per output;
//   fit:       the fast one: the weighted Gram matrix X'WX and X'WY accumulated once for all outputs (each
//              output solves its sub-block), in blocks of 32 rows through Eigen's symmetric rank updates,
//              skipping points whose weight is below 1e-16 of the largest weight (d^2 > d_min^2 + 2 ln 1e16)
//              by a k-d tree over the bandwidth-scaled inputs.
// The skipping only pays when the bandwidths are narrow compared with the data's spread (bench/sysid_bench.cpp:
// at the bandwidths cross-validation picks on the shipped flights every point counts, and both paths are
// compute-bound on the same ~3400 x 16 x 24 multiply-adds). fit allocates nothing; fit_exact does.
// X'WX counts as singular to numerical precision when a diagonal entry is 0 or the Jacobi-scaled matrix has
// reciprocal condition number below kSingularRcond.
#include <array>
#include <vector>

#include "pegasus/sysid/body_model.hpp"

namespace pegasus::sysid {

inline constexpr double kSingularRcond = 1e-12;

struct LocalFit {
  std::array<InputVec, kBodyVars> beta{};  // 0 at inputs the template fixes
  BodyVec leverage = BodyVec::Zero();      // x'(X'WX)^{-1}x on the free inputs, per output
  double weight_sum = 0;                   // sum of the weights used
  double max_weight = 0;                   // largest weight (exp(-d_min^2 / 2))
  int points = 0;                          // points that entered the sums
  bool singular = false;                   // some output's X'WX is singular to numerical precision
  // beta' x for output k.
  double predict(int k, const InputVec& x) const { return beta[static_cast<std::size_t>(k)].dot(x); }
};

class LocalRegression {
 public:
  // `data` must outlive this object. inv_bandwidth[j] = 1 / h_j (0: input ignored by the kernel); the
  // constant input's entry is ignored.
  LocalRegression(const Dataset* data, const std::array<OutputTemplate, kBodyVars>& templates,
                  const std::array<double, kInputs>& inv_bandwidth);

  // Points with index in [exclude_begin, exclude_end) are left out (the cross-validation window).
  LocalFit fit(const InputVec& q, Eigen::Index exclude_begin = 0, Eigen::Index exclude_end = 0) const;
  LocalFit fit_exact(const InputVec& q, Eigen::Index exclude_begin = 0, Eigen::Index exclude_end = 0) const;

  bool is_global() const { return dims_.empty(); }
  const std::array<double, kInputs>& inv_bandwidth() const { return inv_h_; }
  const Dataset& data() const { return *data_; }
  const std::array<OutputTemplate, kBodyVars>& templates() const { return templates_; }

 private:
  struct Node {
    int begin, end;        // range in the permuted order
    int left = -1, right = -1;
    std::array<double, kInputs> lo{}, hi{};  // bounding box over dims_, in scaled coordinates
  };
  using Gram = Eigen::Matrix<double, kInputs, kInputs>;
  using Cross = Eigen::Matrix<double, kInputs, kBodyVars>;
  int build(int begin, int end, int depth);
  double box_distance2(const Node& node, const double* zq) const;
  void solve(const Gram& g, const Cross& b, const InputVec& q, LocalFit* fit) const;

  const Dataset* data_;
  std::array<OutputTemplate, kBodyVars> templates_;
  std::array<double, kInputs> inv_h_{};
  std::vector<int> dims_;        // inputs the kernel uses
  std::vector<int> perm_;        // permuted order -> data row
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> z_;  // scaled coordinates, permuted
  Eigen::Matrix<double, Eigen::Dynamic, kInputs, Eigen::RowMajor> xp_;        // inputs, permuted
  Eigen::Matrix<double, Eigen::Dynamic, kBodyVars, Eigen::RowMajor> yp_;      // targets, permuted
  std::vector<Node> nodes_;
  Gram global_g_ = Gram::Zero();   // for the global model: sums over all points
  Cross global_b_ = Cross::Zero();
};

}  // namespace pegasus::sysid
