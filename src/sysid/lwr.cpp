#include "pegasus/sysid/lwr.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numeric>

namespace pegasus::sysid {

namespace {
constexpr int kLeafSize = 24;
constexpr int kBlock = 32;
// Points whose weight is below 1e-16 of the largest one are skipped: d^2 > d_min^2 + 2 ln(1e16).
const double kCutoff = 2 * std::log(1e16);
}  // namespace

LocalRegression::LocalRegression(const Dataset* data, const std::array<OutputTemplate, kBodyVars>& templates,
                                 const std::array<double, kInputs>& inv_bandwidth)
    : data_(data), templates_(templates), inv_h_(inv_bandwidth) {
  inv_h_[kOne] = 0;
  for (int j = 0; j < kInputs; ++j)
    if (inv_h_[static_cast<std::size_t>(j)] > 0) dims_.push_back(j);
  const auto n = static_cast<int>(data_->rows());
  perm_.resize(static_cast<std::size_t>(n));
  std::iota(perm_.begin(), perm_.end(), 0);
  if (is_global()) {
    global_g_ = data_->x.transpose() * data_->x;
    global_b_ = data_->x.transpose() * data_->y;
    return;
  }
  z_.resize(n, static_cast<Eigen::Index>(dims_.size()));
  for (int i = 0; i < n; ++i)
    for (std::size_t d = 0; d < dims_.size(); ++d)
      z_(i, static_cast<Eigen::Index>(d)) = data_->x(i, dims_[d]) * inv_h_[static_cast<std::size_t>(dims_[d])];
  nodes_.reserve(static_cast<std::size_t>(4 * n / kLeafSize + 4));
  build(0, n, 0);
  // Store everything in tree order so that leaves are contiguous.
  decltype(z_) z2(z_.rows(), z_.cols());
  xp_.resize(n, kInputs);
  yp_.resize(n, kBodyVars);
  for (int i = 0; i < n; ++i) {
    z2.row(i) = z_.row(perm_[static_cast<std::size_t>(i)]);
    xp_.row(i) = data_->x.row(perm_[static_cast<std::size_t>(i)]);
    yp_.row(i) = data_->y.row(perm_[static_cast<std::size_t>(i)]);
  }
  z_ = std::move(z2);
}

int LocalRegression::build(int begin, int end, int depth) {
  const int id = static_cast<int>(nodes_.size());
  nodes_.push_back(Node{begin, end});
  Node node{begin, end};
  const auto nd = dims_.size();
  int widest = 0;
  double width = -1;
  for (std::size_t d = 0; d < nd; ++d) {
    double lo = INFINITY, hi = -INFINITY;
    for (int i = begin; i < end; ++i) {
      const double v = z_(perm_[static_cast<std::size_t>(i)], static_cast<Eigen::Index>(d));
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    node.lo[d] = lo;
    node.hi[d] = hi;
    if (hi - lo > width) {
      width = hi - lo;
      widest = static_cast<int>(d);
    }
  }
  if (end - begin > kLeafSize && width > 0 && depth < 60) {
    const int mid = begin + (end - begin) / 2;
    std::nth_element(perm_.begin() + begin, perm_.begin() + mid, perm_.begin() + end, [&](int a, int b) {
      return z_(a, widest) < z_(b, widest);
    });
    node.left = build(begin, mid, depth + 1);
    node.right = build(mid, end, depth + 1);
  }
  nodes_[static_cast<std::size_t>(id)] = node;
  return id;
}

double LocalRegression::box_distance2(const Node& node, const double* zq) const {
  double s = 0;
  for (std::size_t d = 0; d < dims_.size(); ++d) {
    const double v = zq[d];
    const double e = v < node.lo[d] ? node.lo[d] - v : (v > node.hi[d] ? v - node.hi[d] : 0.0);
    s += e * e;
  }
  return s;
}

void LocalRegression::solve(const Gram& g, const Cross& b, const InputVec& q, LocalFit* fit) const {
  for (int k = 0; k < kBodyVars; ++k) {
    const auto& tmpl = templates_[static_cast<std::size_t>(k)];
    auto& beta = fit->beta[static_cast<std::size_t>(k)];
    beta.setZero();
    int idx[kInputs];
    int m = 0;
    for (int j = 0; j < kInputs; ++j)
      if (tmpl.free[static_cast<std::size_t>(j)]) idx[m++] = j;
    if (m == 0) continue;
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kInputs, kInputs> gs(m, m);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kInputs, 1> bs(m), dq(m), d(m);
    for (int r = 0; r < m; ++r) {
      d[r] = std::sqrt(g(idx[r], idx[r]));
      if (!(d[r] > 1e-150)) {
        fit->singular = true;
        return;
      }
    }
    for (int r = 0; r < m; ++r) {
      for (int c = 0; c < m; ++c) gs(r, c) = g(idx[r], idx[c]) / (d[r] * d[c]);
      bs[r] = b(idx[r], k) / d[r];
      dq[r] = q[idx[r]] / d[r];
    }
    Eigen::LLT<decltype(gs)> llt(gs);
    if (llt.info() != Eigen::Success || !(llt.rcond() >= kSingularRcond)) {
      fit->singular = true;
      return;
    }
    const auto sol = llt.solve(bs).eval();
    for (int r = 0; r < m; ++r) beta[idx[r]] = sol[r] / d[r];
    fit->leverage[k] = dq.dot(llt.solve(dq));
  }
}

LocalFit LocalRegression::fit(const InputVec& q, Eigen::Index exclude_begin, Eigen::Index exclude_end) const {
  LocalFit fit;
  Gram g;
  Cross b;
  if (is_global()) {
    g = global_g_;
    b = global_b_;
    if (exclude_end > exclude_begin) {
      const auto len = exclude_end - exclude_begin;
      const auto xs = data_->x.middleRows(exclude_begin, len);
      g -= xs.transpose() * xs;
      b -= xs.transpose() * data_->y.middleRows(exclude_begin, len);
    }
    fit.points = static_cast<int>(data_->rows() - std::max<Eigen::Index>(0, exclude_end - exclude_begin));
    fit.weight_sum = fit.points;
    fit.max_weight = 1;
    solve(g, b, q, &fit);
    return fit;
  }
  const std::size_t nd = dims_.size();
  double zq[kInputs];
  for (std::size_t d = 0; d < nd; ++d) zq[d] = q[dims_[d]] * inv_h_[static_cast<std::size_t>(dims_[d])];
  auto excluded = [&](int i) {
    const int row = perm_[static_cast<std::size_t>(i)];
    return row >= exclude_begin && row < exclude_end;
  };
  auto dist2 = [&](int i) {
    const double* zi = z_.data() + static_cast<std::ptrdiff_t>(i) * static_cast<std::ptrdiff_t>(nd);
    double s = 0;
    for (std::size_t d = 0; d < nd; ++d) {
      const double e = zq[d] - zi[d];
      s += e * e;
    }
    return s;
  };
  // One pass, nearer child first: a point enters the sums unless its squared distance exceeds the smallest one
  // seen so far by more than kCutoff. The final smallest distance is no larger, so every point skipped weighs
  // less than 1e-16 of the largest weight; points admitted early with a looser bound only add exact terms.
  g.setZero();
  b.setZero();
  Eigen::Matrix<double, kBlock, kInputs, Eigen::RowMajor> xb;
  Eigen::Matrix<double, kBlock, kBodyVars, Eigen::RowMajor> yb;
  int filled = 0;
  auto flush = [&] {
    if (filled == 0) return;
    if (filled < kBlock) {
      xb.bottomRows(kBlock - filled).setZero();
      yb.bottomRows(kBlock - filled).setZero();
    }
    g.selfadjointView<Eigen::Upper>().rankUpdate(xb.transpose());
    b.noalias() += xb.transpose() * yb;
    filled = 0;
  };
  int stack[128];
  double best = INFINITY;
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[--top])];
    if (box_distance2(node, zq) > best + kCutoff) continue;
    if (node.left >= 0) {
      const double dl = box_distance2(nodes_[static_cast<std::size_t>(node.left)], zq);
      const double dr = box_distance2(nodes_[static_cast<std::size_t>(node.right)], zq);
      if (dl < dr) {
        stack[top++] = node.right;
        stack[top++] = node.left;
      } else {
        stack[top++] = node.left;
        stack[top++] = node.right;
      }
      continue;
    }
    for (int i = node.begin; i < node.end; ++i) {
      if (excluded(i)) continue;
      const double d2 = dist2(i);
      if (d2 < best) best = d2;
      if (d2 > best + kCutoff) continue;
      const double sw = std::exp(-0.25 * d2);
      const double w = sw * sw;
      fit.weight_sum += w;
      fit.max_weight = std::max(fit.max_weight, w);
      ++fit.points;
      xb.row(filled) = sw * xp_.row(i);
      yb.row(filled) = sw * yp_.row(i);
      if (++filled == kBlock) flush();
    }
  }
  if (!std::isfinite(best)) {
    fit.singular = true;
    return fit;
  }
  flush();
  g.triangularView<Eigen::StrictlyLower>() = g.transpose();
  solve(g, b, q, &fit);
  return fit;
}

LocalFit LocalRegression::fit_exact(const InputVec& q, Eigen::Index exclude_begin, Eigen::Index exclude_end) const {
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
