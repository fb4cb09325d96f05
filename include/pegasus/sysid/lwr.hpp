#pragma once
// Locally weighted linear regression (thesis §5.2.1, Eqs 5.2-5.4) over a Dataset, all outputs at once.
//
// The weight of training point i at query q is w_i = exp(-1/2 sum_j ((q_j - x_ij) / h_j)^2) with a diagonal
// bandwidth h (an input with h_j = infinity, inverse 0, is ignored by the kernel). For each output k the
// coefficients on the template's free inputs solve (X'WX) beta = X'Wy. Read as a Bayesian regression with a
// flat prior where point i has noise variance sigma^2 / w_i, the posterior covariance is
// Sigma_beta = sigma^2 (X'WX)^{-1}, so the predictive variance is sigma^2 (1 + x'(X'WX)^{-1}x) (Eq 5.4).
//
// Two paths that agree within 1e-9 relative wherever the Jacobi-scaled X'WX is reasonably conditioned (rcond
// >= 1e-4; at the shipped bandwidths the smallest rcond over the hold-out queries is reported by
// bench/sysid_bench.cpp); nearer the singular threshold they agree within about 1e-13 / rcond, since no two
// summation orders of the Gram sums agree better than the condition number times the rounding (tests/sysid):
//   fit_exact: the plain reference: every point, std::exp, one normal-equation system per output;
//   fit:       the fast one (lwr_kernel.hpp): the weighted Gram matrix of the inputs some output regresses on
//              and the outputs, accumulated once for all outputs over data blocked by 8 points in k-d tree
//              order, 8 points per vector (AVX-512, AVX2+FMA or scalar, chosen at run time; all give the same
//              bits), with its own exp, as sum_i (w_i a_i) a_i'; the upper triangle only;
//              outputs that regress on the same inputs (all six free outputs of the §5.2.2 template) share
//              one inverse. Points whose weight
//              is below 1e-16 of the largest weight seen before them (d^2 > d_min^2 + 2 ln 1e16, d_min over
//              the query's own leaf and the chunks before) are skipped, by whole leaves where a leaf's
//              bounding box is that far; at the bandwidths cross-validation picks on the shipped flights
//              every point counts. fit allocates nothing; fit_exact does.
// A refit depends only on the query (and the window), never on earlier refits or on threads.
// Both paths solve through one explicit inverse of the Jacobi-scaled X'WX (Cholesky, then L^-T L^-1), which
// also gives its exact 1-norm reciprocal condition number rcond = 1 / (|A|_1 |A^-1|_1). X'WX counts as
// singular to numerical precision when a diagonal entry is 0, the Cholesky factorisation fails, or rcond <
// kSingularRcond.
#include <array>
#include <cstddef>
#include <memory>
#include <new>
#include <optional>
#include <vector>

#include "pegasus/core/instruction_set.hpp"
#include "pegasus/sysid/body_model.hpp"
#include "pegasus/sysid/lwr_kernel.hpp"

namespace pegasus::sysid {

inline constexpr double kSingularRcond = 1e-12;

// Which instruction set fit uses: best_instruction_set() unless one is forced (for tests and benchmarks; all
// give the same bits; std::nullopt returns to the best). A set the CPU lacks falls back to the best it has.
// Not meant to be changed while fits run.
void force_lwr_instruction_set(std::optional<InstructionSet> isa);
InstructionSet lwr_instruction_set();

struct LocalFit {
  std::array<InputVec, kBodyVars> beta{};  // 0 at inputs the template fixes
  BodyVec leverage = BodyVec::Zero();      // x'(X'WX)^{-1}x on the free inputs, per output
  double weight_sum = 0;                   // sum of the weights used
  double max_weight = 0;                   // largest weight (exp(-d_min^2 / 2))
  int points = 0;                          // points that entered the sums
  bool singular = false;                   // some output's X'WX is singular to numerical precision
  double rcond = 0;  // smallest 1-norm reciprocal condition number of the Jacobi-scaled X'WX
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
  struct AlignedFree {
    void operator()(double* p) const { ::operator delete[](p, std::align_val_t{64}); }
  };
  using Column = std::unique_ptr<double[], AlignedFree>;
  static Column aligned_columns(std::size_t count);
  struct SplitNode {
    int dim = -1;      // kernel coordinate split on; -1 for a leaf
    double value = 0;  // points with z[dim] < value went left
    int left = -1, right = -1, leaf = -1;
  };
  // Outputs that regress on the same inputs share one factorisation.
  struct Group {
    std::array<int, kInputs> rows{};    // Gram rows of the free inputs
    std::array<int, kInputs> inputs{};  // the free inputs
    int size = 0;
    std::array<int, kBodyVars> outputs{};
    std::array<int, kBodyVars> columns{};  // Gram column of each output
    int count = 0;
  };
  using Gram = Eigen::Matrix<double, kInputs, kInputs>;
  using Cross = Eigen::Matrix<double, kInputs, kBodyVars>;
  // Adds sign * (x' x, x' y) over the rows [begin, end) to *g and *b, in a summation order that is the same
  // on every machine.
  void add_global_sums(Eigen::Index begin, Eigen::Index end, double sign, Gram* g, Cross* b) const;
  // The constructor's steps: the Gram's layout and groups, the kernel coordinates, the tree's blocked copies
  // and their bounding boxes (lwr_kernel.hpp).
  void lay_out_gram();
  std::vector<double> kernel_coordinates() const;
  void store_blocked(const std::vector<double>& z);
  std::vector<int> stored_columns();
  void store_leaf_boxes(const std::vector<double>& z, int leaves, std::size_t lp);
  int build(int begin, int end, int depth, const std::vector<double>& z);
  void solve(const Gram& g, const Cross& b, const InputVec& q, LocalFit* fit) const;
  void solve_groups(const detail::KernelResult& k, const InputVec& q, LocalFit* fit) const;
  bool solve_group(const detail::KernelResult& k, const Group& grp, const InputVec& q, bool first,
                   LocalFit* fit) const;
  // The factor the kernel's copy of an input carries: 1 / bandwidth for a kernel coordinate (so that
  // distances need no multiply), else 1.
  double stored_scale(int input) const {
    const double s = inv_h_[static_cast<std::size_t>(input)];
    return s > 0 ? s : 1.0;
  }

  const Dataset* data_;
  std::array<OutputTemplate, kBodyVars> templates_;
  std::array<double, kInputs> inv_h_{};
  std::vector<int> dims_;                      // inputs the kernel uses
  std::vector<int> perm_;                      // storage order -> data row
  std::array<int, kInputs> gram_inputs_{};     // input of each Gram row
  std::array<int, kBodyVars> gram_outputs_{};  // output of each Gram column past the inputs
  std::array<int, kInputs> row_of_input_{};    // -1 where no output regresses on the input
  int gram_m_ = 0, gram_outputs_count_ = 0;
  std::array<Group, kBodyVars> groups_{};
  int group_count_ = 0;
  Column a_, row_, box_lo_, box_hi_;
  std::vector<int> leaf_begin_;
  std::vector<SplitNode> tree_;
  detail::KernelData kd_;
  std::array<detail::TilePlan, 3> plans_;  // per InstructionSet
  Gram global_g_ = Gram::Zero();           // for the global model: sums over all points
  Cross global_b_ = Cross::Zero();
};

}  // namespace pegasus::sysid
