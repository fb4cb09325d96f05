#include "pegasus/sysid/lwr.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>

namespace pegasus::sysid {

namespace {
// Points whose weight is below 1e-16 of the largest one seen before them are skipped: d^2 > d_min^2 + 2
// ln(1e16).
const double kCutoff = 2 * std::log(1e16);
constexpr double kFar = 1e150;  // padding coordinate: d^2 ~ 1e300, weight 0

constexpr int kNotForced = -1;
std::atomic<int> g_forced{kNotForced};

// The Jacobi-scaled inverse of a symmetric positive definite m x m matrix G (m <= kInputs; the X'WX of one
// output's free inputs): A = D^-1 G D^-1 with D = diag(sqrt(G_rr)), its Cholesky factor A = L L', A^-1 =
// L^-T L^-1, and the exact 1-norm reciprocal condition number rcond = 1 / (|A|_1 |A^-1|_1). Both paths (fit
// and fit_exact) solve through here, so they differ only by their Gram sums (fit's over the stored, scaled
// inputs, which Jacobi scaling cancels). The factorisation and the products with A^-1 run on the kernel's
// instruction set (lwr_kernel.hpp: Factor), with the same bits on each.
class ScaledInverse {
 public:
  // Scales G and inverts A, g(r, c) giving G's entries, and records rcond in fit (the smallest over the
  // calls; `first` starts it). False when G is singular to numerical precision: a diagonal entry too small to
  // scale by, a pivot that is not positive, or rcond < kSingularRcond.
  template <class Entry>
  bool factor(int m, Entry g, bool first, LocalFit* fit) {
    if (!scale(m, g)) return false;
    const double rc = invert();
    fit->rcond = first ? rc : std::min(fit->rcond, rc);
    return rc >= kSingularRcond;
  }

  // beta[o] = G^-1 b_o = D^-1 A^-1 D^-1 b_o for o < count, b_o given by b(o, r).
  template <class Entry>
  void solve(int count, Entry b, detail::Row* beta) const {
    alignas(64) detail::Row v[kBodyVars] = {};
    for (int o = 0; o < count; ++o)
      for (int c = 0; c < m_; ++c) v[o][c] = b(o, c) * dinv_[c];
    switch (path_) {
      case InstructionSet::kAvx512:
        detail::multiply_inverse_avx512(m_, f_, count, v, beta);
        break;
      case InstructionSet::kAvx2Fma:
        detail::multiply_inverse_avx2(m_, f_, count, v, beta);
        break;
      default:
        detail::multiply_inverse_scalar(m_, f_, count, v, beta);
        break;
    }
    for (int o = 0; o < count; ++o)
      for (int r = 0; r < m_; ++r) beta[o][r] *= dinv_[r];
  }

  // The leverage v'G^-1 v = |L^-1 D^-1 v|^2 (a sum of squares, so never negative), for v given by v(r):
  // forward substitution.
  template <class Entry>
  double leverage(Entry v) const {
    double y[kInputs];
    double sum = 0;
    for (int i = 0; i < m_; ++i) {
      double t = v(i) * dinv_[i];
      for (int k = 0; k < i; ++k) t -= f_.l[k][i] * y[k];
      y[i] = t * f_.inv_diag[i];
      sum += y[i] * y[i];
    }
    return sum;
  }

 private:
  // False when a diagonal entry is too small to scale by.
  template <class Entry>
  bool scale(int m, Entry g) {
    m_ = m;
    for (int r = 0; r < m; ++r) {
      const double d = std::sqrt(g(r, r));
      if (!(d > 1e-150)) return false;
      dinv_[r] = 1 / d;
    }
    for (int r = 0; r < kInputs; ++r)
      for (int c = 0; c < kInputs; ++c) f_.a[r][c] = r < m && c < m ? g(r, c) * dinv_[r] * dinv_[c] : 0.0;
    return true;
  }

  // rcond, 0 when a pivot of the factorisation is not positive.
  double invert() {
    switch (path_) {
      case InstructionSet::kAvx512:
        return detail::invert_avx512(m_, &f_);
      case InstructionSet::kAvx2Fma:
        return detail::invert_avx2(m_, &f_);
      default:
        return detail::invert_scalar(m_, &f_);
    }
  }

  InstructionSet path_ = lwr_instruction_set();
  int m_ = 0;
  double dinv_[kInputs];
  detail::Factor f_;
};

}  // namespace

void force_lwr_instruction_set(std::optional<InstructionSet> isa) {
  g_forced.store(isa ? static_cast<int>(*isa) : kNotForced, std::memory_order_relaxed);
}

InstructionSet lwr_instruction_set() {
  const int forced = g_forced.load(std::memory_order_relaxed);
  if (forced == kNotForced || !instruction_set_supported(static_cast<InstructionSet>(forced)))
    return best_instruction_set();
  return static_cast<InstructionSet>(forced);
}

LocalRegression::Column LocalRegression::aligned_columns(std::size_t count) {
  return Column(new (std::align_val_t{64}) double[std::max<std::size_t>(count, 1)]);
}

LocalRegression::LocalRegression(const Dataset* data, const std::array<OutputTemplate, kBodyVars>& templates,
                                 const std::array<double, kInputs>& inv_bandwidth)
    : data_(data), templates_(templates), inv_h_(inv_bandwidth) {
  inv_h_[kOne] = 0;
  for (int j = 0; j < kInputs; ++j)
    if (inv_h_[static_cast<std::size_t>(j)] > 0) dims_.push_back(j);
  const auto n = static_cast<int>(data_->rows());
  perm_.resize(static_cast<std::size_t>(n));
  std::iota(perm_.begin(), perm_.end(), 0);
  lay_out_gram();
  if (is_global()) {
    add_global_sums(0, data_->rows(), 1.0, &global_g_, &global_b_);
    return;
  }
  const std::vector<double> z = kernel_coordinates();
  build(0, n, 0, z);
  leaf_begin_.push_back(n);
  store_blocked(z);
}

// Gram rows: the inputs some output regresses on; columns: those, then the outputs that regress on
// something. Outputs with the same free inputs form one group.
void LocalRegression::lay_out_gram() {
  row_of_input_.fill(-1);
  for (int j = 0; j < kInputs; ++j) {
    bool used = false;
    for (const auto& t : templates_) used = used || t.free[static_cast<std::size_t>(j)];
    if (used) {
      row_of_input_[static_cast<std::size_t>(j)] = gram_m_;
      gram_inputs_[static_cast<std::size_t>(gram_m_++)] = j;
    }
  }
  for (int k = 0; k < kBodyVars; ++k) {
    const auto& t = templates_[static_cast<std::size_t>(k)];
    if (t.free_count() == 0) continue;
    gram_outputs_[static_cast<std::size_t>(gram_outputs_count_++)] = k;
    int g = 0;
    while (g < group_count_ &&
           templates_[static_cast<std::size_t>(groups_[static_cast<std::size_t>(g)].outputs[0])].free !=
               t.free)
      ++g;
    Group& grp = groups_[static_cast<std::size_t>(g)];
    if (g == group_count_) {
      ++group_count_;
      for (int j = 0; j < kInputs; ++j)
        if (t.free[static_cast<std::size_t>(j)]) {
          grp.inputs[static_cast<std::size_t>(grp.size)] = j;
          grp.rows[static_cast<std::size_t>(grp.size++)] = row_of_input_[static_cast<std::size_t>(j)];
        }
    }
    grp.columns[static_cast<std::size_t>(grp.count)] = gram_m_ + gram_outputs_count_ - 1;
    grp.outputs[static_cast<std::size_t>(grp.count++)] = k;
  }
}

// Each row's kernel coordinates (the inputs over their bandwidths), row-major in data order.
std::vector<double> LocalRegression::kernel_coordinates() const {
  const auto n = static_cast<std::size_t>(data_->rows());
  const std::size_t und = dims_.size();
  std::vector<double> z(n * und);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t d = 0; d < und; ++d)
      z[i * und + d] =
          data_->x(static_cast<Eigen::Index>(i), dims_[d]) * inv_h_[static_cast<std::size_t>(dims_[d])];
  return z;
}

// Blocked copies in tree order (lwr_kernel.hpp): the Gram columns, then the kernel-only inputs; the kernel
// coordinates divided by their bandwidths (stored_scale). Then each leaf's bounding box, and the kernel's
// view of them with its tile shapes.
void LocalRegression::store_blocked(const std::vector<double>& z) {
  const int n = static_cast<int>(data_->rows());
  const int n_pad = (n + detail::kLanes - 1) / detail::kLanes * detail::kLanes;
  const int leaves = static_cast<int>(leaf_begin_.size()) - 1;
  const int leaves_pad = (leaves + detail::kLanes - 1) / detail::kLanes * detail::kLanes;
  const int ncols = gram_m_ + gram_outputs_count_;
  // The constant input, when some output regresses on it, is the last Gram row (kOne is the last input); the
  // kernel weighs it without storing it.
  static_assert(kOne == kInputs - 1, "the constant input is the last Gram row (KernelData::weight_row)");
  kd_.weight_row = gram_m_ > 0 && gram_inputs_[static_cast<std::size_t>(gram_m_ - 1)] == kOne;
  const int kernel_cols = ncols - (kd_.weight_row ? 1 : 0);
  const std::vector<int> source = stored_columns();
  const auto np = static_cast<std::size_t>(n_pad);
  const auto lp = static_cast<std::size_t>(leaves_pad);
  a_ = aligned_columns(source.size() * np);
  row_ = aligned_columns(np);
  const std::size_t stride = source.size() * detail::kLanes;
  for (std::size_t i = 0; i < np; ++i) {
    const bool real = i < static_cast<std::size_t>(n);
    const int r = real ? perm_[i] : -1;
    row_[i] = r;
    for (std::size_t c = 0; c < source.size(); ++c)
      a_[i / detail::kLanes * stride + c * detail::kLanes + i % detail::kLanes] =
          !real            ? 0.0
          : source[c] >= 0 ? data_->x(r, source[c]) * stored_scale(source[c])
                           : data_->y(r, ~source[c]);
  }
  store_leaf_boxes(z, leaves, lp);
  kd_.n = n;
  kd_.n_pad = n_pad;
  kd_.stride = static_cast<int>(stride);
  kd_.nd = static_cast<int>(dims_.size());
  kd_.m = gram_m_;
  kd_.ncols = ncols;
  kd_.leaves = leaves;
  kd_.leaves_pad = leaves_pad;
  kd_.a = a_.get();
  kd_.row = row_.get();
  kd_.box_lo = box_lo_.get();
  kd_.box_hi = box_hi_.get();
  kd_.leaf_begin = leaf_begin_.data();
  // Tile shapes per instruction set (registers: 16 of 4 doubles for AVX2, 32 of 8 for AVX-512).
  plans_[static_cast<std::size_t>(InstructionSet::kBaseline)] =
      detail::tile_plan(gram_m_, kernel_cols, 1, 4, kd_.weight_row);
  plans_[static_cast<std::size_t>(InstructionSet::kAvx2Fma)] =
      detail::tile_plan(gram_m_, kernel_cols, 2, 2, kd_.weight_row);
  plans_[static_cast<std::size_t>(InstructionSet::kAvx512)] =
      detail::tile_plan(gram_m_, kernel_cols, 4, 12, kd_.weight_row);
}

// The source of each stored column, an input (>= 0) or ~output: the Gram rows but the constant, the Gram's
// outputs, then the kernel coordinates no output regresses on; kd_.kernel_col gets each kernel coordinate's
// column.
std::vector<int> LocalRegression::stored_columns() {
  std::vector<int> source;
  for (int c = 0; c < gram_m_; ++c)
    if (gram_inputs_[static_cast<std::size_t>(c)] != kOne)
      source.push_back(gram_inputs_[static_cast<std::size_t>(c)]);
  for (int c = 0; c < gram_outputs_count_; ++c) source.push_back(~gram_outputs_[static_cast<std::size_t>(c)]);
  for (std::size_t d = 0; d < dims_.size(); ++d) {
    const int j = dims_[d];
    if (row_of_input_[static_cast<std::size_t>(j)] >= 0) {
      kd_.kernel_col[d] = row_of_input_[static_cast<std::size_t>(j)];
    } else {
      kd_.kernel_col[d] = static_cast<int>(source.size());
      source.push_back(j);
    }
  }
  return source;
}

// Each leaf's bounding box in the kernel coordinates z, blocked by kernel coordinate (lp leaves each, the
// padding far away).
void LocalRegression::store_leaf_boxes(const std::vector<double>& z, int leaves, std::size_t lp) {
  const std::size_t und = dims_.size();
  box_lo_ = aligned_columns(und * lp);
  box_hi_ = aligned_columns(und * lp);
  for (std::size_t l = 0; l < lp; ++l)
    for (std::size_t d = 0; d < und; ++d) {
      double lo = kFar, hi = kFar;
      if (l < static_cast<std::size_t>(leaves)) {
        lo = INFINITY;
        hi = -INFINITY;
        for (int i = leaf_begin_[l]; i < leaf_begin_[l + 1]; ++i) {
          const double v = z[static_cast<std::size_t>(perm_[static_cast<std::size_t>(i)]) * und + d];
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      }
      box_lo_[d * lp + l] = lo;
      box_hi_[d * lp + l] = hi;
    }
}

// Splits [begin, end) of perm_ at a multiple of 8 (leaves start on whole vectors) along the widest kernel
// coordinate, down to leaves of at most kLeaf points; leaves are numbered in storage order.
int LocalRegression::build(int begin, int end, int depth, const std::vector<double>& z) {
  const int id = static_cast<int>(tree_.size());
  tree_.push_back(SplitNode{});
  const auto nd = dims_.size();
  std::size_t widest = 0;
  double width = -1;
  for (std::size_t d = 0; d < nd; ++d) {
    double lo = INFINITY, hi = -INFINITY;
    for (int i = begin; i < end; ++i) {
      const double v = z[static_cast<std::size_t>(perm_[static_cast<std::size_t>(i)]) * nd + d];
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    if (hi - lo > width) {
      width = hi - lo;
      widest = d;
    }
  }
  const int mid = begin + (end - begin) / 2 / detail::kLanes * detail::kLanes;
  if (end - begin <= detail::kLeaf || !(width > 0) || depth >= 60 || mid == begin) {
    SplitNode leaf;
    leaf.leaf = static_cast<int>(leaf_begin_.size());
    leaf_begin_.push_back(begin);
    tree_[static_cast<std::size_t>(id)] = leaf;
    return id;
  }
  auto key = [&](int r) { return z[static_cast<std::size_t>(r) * nd + widest]; };
  std::nth_element(perm_.begin() + begin, perm_.begin() + mid, perm_.begin() + end,
                   [&](int a, int b) { return key(a) < key(b); });
  SplitNode node;
  node.dim = static_cast<int>(widest);
  node.value = key(perm_[static_cast<std::size_t>(mid)]);
  const int left = build(begin, mid, depth + 1, z);
  const int right = build(mid, end, depth + 1, z);
  node.left = left;
  node.right = right;
  tree_[static_cast<std::size_t>(id)] = node;
  return id;
}

void LocalRegression::solve(const Gram& g, const Cross& b, const InputVec& q, LocalFit* fit) const {
  bool first = true;
  for (int k = 0; k < kBodyVars; ++k) {
    const auto& tmpl = templates_[static_cast<std::size_t>(k)];
    auto& beta = fit->beta[static_cast<std::size_t>(k)];
    beta.setZero();
    int idx[kInputs];
    int m = 0;
    for (int j = 0; j < kInputs; ++j)
      if (tmpl.free[static_cast<std::size_t>(j)]) idx[m++] = j;
    if (m == 0) continue;
    ScaledInverse inverse;
    if (!inverse.factor(
            m, [&](int r, int c) { return g(idx[r], idx[c]); }, first, fit)) {
      fit->singular = true;
      return;
    }
    first = false;
    detail::Row sol;
    inverse.solve(
        1, [&](int, int r) { return b(idx[r], k); }, &sol);
    for (int r = 0; r < m; ++r) beta[idx[r]] = sol[r];
    fit->leverage[k] = inverse.leverage([&](int r) { return q[idx[r]]; });
  }
}

bool LocalRegression::solve_group(const detail::KernelResult& k, const Group& grp, const InputVec& q,
                                  bool first, LocalFit* fit) const {
  auto g = [&](int r, int c) {
    return k.sum[static_cast<std::size_t>(std::min(r, c) * detail::kMaxCols + std::max(r, c))];
  };
  const auto row = [&](int r) { return grp.rows[static_cast<std::size_t>(r)]; };
  const auto input = [&](int r) { return grp.inputs[static_cast<std::size_t>(r)]; };
  // The kernel's sums are those of the stored inputs S x (S = diag(stored_scale)): X'WX is S G S, its
  // right-hand sides S b, so beta = S beta_s, and the leverage is q'G^-1 q = (S q)'(S G S)^-1 (S q).
  ScaledInverse inverse;
  if (!inverse.factor(
          grp.size, [&](int r, int c) { return g(row(r), row(c)); }, first, fit))
    return false;
  const double leverage = inverse.leverage([&](int r) { return q[input(r)] * stored_scale(input(r)); });
  detail::Row sol[kBodyVars];
  inverse.solve(
      grp.count, [&](int o, int r) { return g(row(r), grp.columns[static_cast<std::size_t>(o)]); }, sol);
  for (int o = 0; o < grp.count; ++o) {
    const int out = grp.outputs[static_cast<std::size_t>(o)];
    auto& beta = fit->beta[static_cast<std::size_t>(out)];
    for (int r = 0; r < grp.size; ++r) beta[input(r)] = sol[o][r] * stored_scale(input(r));
    fit->leverage[out] = leverage;
  }
  return true;
}

// The fast path's solve: one Jacobi-scaled inverse per group of outputs with the same free inputs (the same
// arithmetic as solve() for each output).
void LocalRegression::solve_groups(const detail::KernelResult& k, const InputVec& q, LocalFit* fit) const {
  for (auto& beta : fit->beta) beta.setZero();
  for (int gi = 0; gi < group_count_; ++gi) {
    const Group& grp = groups_[static_cast<std::size_t>(gi)];
    if (!solve_group(k, grp, q, gi == 0, fit)) {
      fit->singular = true;
      return;
    }
  }
}

void LocalRegression::add_global_sums(Eigen::Index begin, Eigen::Index end, double sign, Gram* g,
                                      Cross* b) const {
  // Row by row in data order, each row's products added as they come. Not Eigen's x' x: its product blocks
  // the sum over rows by the cache sizes it reads from the CPU at run time, so the global model's bits (and
  // every summary that reports it) differed between two machines with the same instruction set.
  const auto& x = data_->x;
  const auto& y = data_->y;
  for (Eigen::Index i = begin; i < end; ++i)
    for (int c = 0; c < kInputs; ++c) {
      const double xc = sign * x(i, c);
      for (int r = 0; r < kInputs; ++r) (*g)(r, c) += x(i, r) * xc;
      for (int k = 0; k < kBodyVars; ++k) (*b)(c, k) += xc * y(i, k);
    }
}

LocalFit LocalRegression::fit(const InputVec& q, Eigen::Index exclude_begin, Eigen::Index exclude_end) const {
  LocalFit fit;
  if (is_global()) {
    Gram g = global_g_;
    Cross b = global_b_;
    if (exclude_end > exclude_begin) {
      add_global_sums(exclude_begin, exclude_end, -1.0, &g, &b);
    }
    fit.points = static_cast<int>(data_->rows() - std::max<Eigen::Index>(0, exclude_end - exclude_begin));
    fit.weight_sum = fit.points;
    fit.max_weight = 1;
    solve(g, b, q, &fit);
    return fit;
  }
  detail::KernelQuery kq;
  for (std::size_t d = 0; d < dims_.size(); ++d) {
    kq.zq[d] = q[dims_[d]] * inv_h_[static_cast<std::size_t>(dims_[d])];
  }
  kq.exclude_begin = static_cast<double>(exclude_begin);
  kq.exclude_end = static_cast<double>(exclude_end);
  kq.cutoff = kCutoff;
  std::size_t node = 0;
  while (tree_[node].dim >= 0)
    node = static_cast<std::size_t>(kq.zq[static_cast<std::size_t>(tree_[node].dim)] < tree_[node].value
                                        ? tree_[node].left
                                        : tree_[node].right);
  kq.seed_leaf = tree_[node].leaf;
  detail::KernelResult k;
  switch (lwr_instruction_set()) {
    case InstructionSet::kAvx512:
      detail::gram_avx512(kd_, plans_[static_cast<std::size_t>(InstructionSet::kAvx512)], kq, &k);
      break;
    case InstructionSet::kAvx2Fma:
      detail::gram_avx2(kd_, plans_[static_cast<std::size_t>(InstructionSet::kAvx2Fma)], kq, &k);
      break;
    default:
      detail::gram_scalar(kd_, plans_[static_cast<std::size_t>(InstructionSet::kBaseline)], kq, &k);
      break;
  }
  fit.weight_sum = k.weight_sum;
  fit.max_weight = k.max_weight;
  fit.points = k.points;
  if (k.points == 0) {
    fit.singular = true;
    return fit;
  }
  solve_groups(k, q, &fit);
  return fit;
}

LocalFit LocalRegression::fit_exact(const InputVec& q, Eigen::Index exclude_begin,
                                    Eigen::Index exclude_end) const {
  LocalFit fit;
  const Eigen::Index n = data_->rows();
  std::vector<double> w(static_cast<std::size_t>(n), 0.0);
  for (Eigen::Index i = 0; i < n; ++i) {
    if (i >= exclude_begin && i < exclude_end) continue;
    double s = 0;
    for (int j : dims_) {
      const double e = (q[j] - data_->x(i, j)) * inv_h_[static_cast<std::size_t>(j)];
      s += e * e;
    }
    w[static_cast<std::size_t>(i)] = std::exp(-0.5 * s);
    fit.weight_sum += w[static_cast<std::size_t>(i)];
    fit.max_weight = std::max(fit.max_weight, w[static_cast<std::size_t>(i)]);
    ++fit.points;
  }
  // One weighted normal-equation system per output, as in Eq 5.2.
  Gram g = Gram::Zero();
  Cross b = Cross::Zero();
  for (Eigen::Index i = 0; i < n; ++i) {
    const double wi = w[static_cast<std::size_t>(i)];
    if (wi == 0) continue;
    for (int r = 0; r < kInputs; ++r) {
      for (int c = 0; c < kInputs; ++c) g(r, c) += wi * data_->x(i, r) * data_->x(i, c);
      for (int k = 0; k < kBodyVars; ++k) b(r, k) += wi * data_->x(i, r) * data_->y(i, k);
    }
  }
  solve(g, b, q, &fit);
  return fit;
}

}  // namespace pegasus::sysid
