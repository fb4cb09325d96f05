#pragma once
// Exact policy evaluation for the finite-MDP solvers (internal to src/mdp; solvers.cpp): the linear solve of
// Eq 2.8 that policy iteration and evaluate_policy make, apart from the iterative algorithms around it.
#include <Eigen/Core>
#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <Eigen/SparseLU>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/mdp/finite_mdp.hpp"

namespace pegasus::detail {

// Exact policy evaluation, (I - gamma P_pi) V = R_pi over the non-absorbing states (Eq 2.8), set up once
// per MDP so that policy iteration pays only for the numeric factorisation at each step: the matrix is
// assembled on the union of all actions' sparsity patterns, so its structure never changes and the
// fill-reducing ordering and symbolic analysis (SparseLU::analyzePattern) are done once. Dense MDPs
// (one action's pattern above a quarter full on average) use a dense partial-pivoting LU instead, and
// MDPs whose pattern is a narrow band in the state numbering (gridworlds numbered row by row: bandwidth =
// the grid's width) a band LU, which fills in nothing outside the band.
//
// The band LU does not pivot. It needs none: I - gamma P_pi is a nonsingular M-matrix for gamma < 1
// (strictly diagonally dominant by rows) and for a proper policy with gamma = 1 (Bertsekas & Tsitsiklis
// 1996, Prop 2.1: its spectral radius on the transient states is below 1), and Gaussian elimination on a
// nonsingular M-matrix needs no row exchanges: every pivot is positive and every Schur complement is again
// an M-matrix (Berman & Plemmons 1994, Thm 6.2.3 (E17); Higham 2002, §9.5 for diagonal dominance and a
// growth factor of at most 2). A pivot that is not positive therefore means a singular matrix (an
// improper policy), reported like SparseLU's failure.
class BandLu {
 public:
  // Half-bandwidths: a(i, j) may be nonzero only for i - kl <= j <= i + ku.
  void reset(int n, int kl, int ku) {
    n_ = n;
    kl_ = kl;
    ku_ = ku;
    w_ = kl + ku + 1;
    a_.assign(static_cast<std::size_t>(n) * static_cast<std::size_t>(w_), 0.0);
  }
  std::int64_t position(int i, int j) const { return static_cast<std::int64_t>(i) * w_ + (j - i + kl_); }
  double* values() { return a_.data(); }
  std::size_t size() const { return a_.size(); }

  // In place: unit lower L below the diagonal, U on and above it. False on a non-positive pivot.
  bool factorize() {
    double* a = a_.data();
    for (int k = 0; k < n_; ++k) {
      double* rk = a + static_cast<std::ptrdiff_t>(k) * w_ + kl_;  // rk[d] = a(k, k + d)
      const double pivot = rk[0];
      if (!(pivot > 0.0)) return false;
      const int right = std::min(ku_, n_ - 1 - k);
      const int below = std::min(kl_, n_ - 1 - k);
      const double inv = 1.0 / pivot;
      for (int di = 1; di <= below; ++di) {
        double* ri = a + static_cast<std::ptrdiff_t>(k + di) * w_ + kl_ - di;  // ri[d] = a(k + di, k + d)
        if (ri[0] == 0.0) continue;
        const double l = ri[0] * inv;
        ri[0] = l;
        for (int d = 1; d <= right; ++d) ri[d] -= l * rk[d];
      }
    }
    return true;
  }
  // Solves L U x = b in place.
  void solve(double* x) const {
    const double* a = a_.data();
    for (int i = 0; i < n_; ++i) {
      const double* ri = a + static_cast<std::ptrdiff_t>(i) * w_ + kl_;  // ri[d] = a(i, i + d)
      const int left = std::min(kl_, i);
      double acc = x[i];
      for (int d = 1; d <= left; ++d) acc -= ri[-d] * x[i - d];
      x[i] = acc;
    }
    for (int i = n_ - 1; i >= 0; --i) {
      const double* ri = a + static_cast<std::ptrdiff_t>(i) * w_ + kl_;
      const int right = std::min(ku_, n_ - 1 - i);
      double acc = x[i];
      for (int d = 1; d <= right; ++d) acc -= ri[d] * x[i + d];
      x[i] = acc / ri[0];
    }
  }

 private:
  int n_ = 0, kl_ = 0, ku_ = 0, w_ = 1;
  std::vector<double> a_;
};

class PolicyEvaluator {
 public:
  explicit PolicyEvaluator(const FiniteMdp& m) : m_(m), index_(static_cast<std::size_t>(m.num_states), -1) {
    for (int s = 0; s < m.num_states; ++s)
      if (!m.is_absorbing(s)) index_[static_cast<std::size_t>(s)] = n_++;
    if (n_ == 0) return;
    // Average pattern of one action above a quarter full: dense LU, no sparse structure needed.
    dense_ = static_cast<double>(m.num_entries()) / m.num_actions >
             0.25 * static_cast<double>(n_) * static_cast<double>(n_);
    if (dense_) return;
    if (try_band()) return;
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(m.num_entries() + static_cast<std::size_t>(n_));
    for (int s = 0; s < m.num_states; ++s) {
      const int i = index_[static_cast<std::size_t>(s)];
      if (i < 0) continue;
      trip.emplace_back(i, i, 1.0);
      for (int a = 0; a < m.num_actions; ++a) {
        const std::size_t r = m.row(s, a);
        for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k) {
          const int j = index_[static_cast<std::size_t>(m.next_state[k])];
          if (j >= 0) trip.emplace_back(i, j, 1.0);
        }
      }
    }
    pattern_.resize(n_, n_);
    pattern_.setFromTriplets(trip.begin(), trip.end());
    pattern_.makeCompressed();
    {
      // Where each MDP entry and each diagonal lands in the compressed column-major value array.
      auto position = [&](int i, int j) {
        const int* inner = pattern_.innerIndexPtr();
        const int b = pattern_.outerIndexPtr()[j], e = pattern_.outerIndexPtr()[j + 1];
        return static_cast<std::int64_t>(std::lower_bound(inner + b, inner + e, i) - inner);
      };
      entry_pos_.assign(m.num_entries(), -1);
      diag_pos_.resize(static_cast<std::size_t>(n_));
      for (int s = 0; s < m.num_states; ++s) {
        const int i = index_[static_cast<std::size_t>(s)];
        if (i < 0) continue;
        diag_pos_[static_cast<std::size_t>(i)] = position(i, i);
        for (int a = 0; a < m.num_actions; ++a) {
          const std::size_t r = m.row(s, a);
          for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k) {
            const int j = index_[static_cast<std::size_t>(m.next_state[k])];
            if (j >= 0) entry_pos_[k] = position(i, j);
          }
        }
      }
      lu_.analyzePattern(pattern_);
    }
  }

  // weight(s, a) = pi(a | s).
  template <class Weight>
  std::vector<double> evaluate(Weight weight) {
    std::vector<double> v(static_cast<std::size_t>(m_.num_states), 0.0);
    if (n_ == 0) return v;
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n_);
    Eigen::VectorXd x;
    if (dense_) {
      Eigen::MatrixXd a = Eigen::MatrixXd::Identity(n_, n_);
      assemble(weight, rhs, [&](int i, int j, std::int64_t, double val) { a(i, j) += val; });
      const Eigen::PartialPivLU<Eigen::MatrixXd> lu(a);
      if (!(lu.matrixLU().diagonal().cwiseAbs().minCoeff() > 0.0))
        throw InputError("policy evaluation: I - gamma P_pi is singular (is the policy proper?)");
      x = lu.solve(rhs);
    } else if (band_) {
      double* val = lu_band_.values();
      std::fill(val, val + lu_band_.size(), 0.0);
      for (int i = 0; i < n_; ++i) val[diag_pos_[static_cast<std::size_t>(i)]] = 1.0;
      assemble(weight, rhs, [&](int, int, std::int64_t pos, double value) { val[pos] += value; });
      if (!lu_band_.factorize())
        throw InputError("policy evaluation: I - gamma P_pi is singular (is the policy proper?)");
      lu_band_.solve(rhs.data());
      x = std::move(rhs);
    } else {
      double* val = pattern_.valuePtr();
      std::fill(val, val + pattern_.nonZeros(), 0.0);
      for (int i = 0; i < n_; ++i) val[diag_pos_[static_cast<std::size_t>(i)]] = 1.0;
      assemble(weight, rhs, [&](int, int, std::int64_t pos, double value) { val[pos] += value; });
      lu_.factorize(pattern_);
      if (lu_.info() != Eigen::Success)
        throw InputError("policy evaluation: I - gamma P_pi is singular (is the policy proper?)");
      x = lu_.solve(rhs);
    }
    for (int s = 0; s < m_.num_states; ++s) {
      const int i = index_[static_cast<std::size_t>(s)];
      if (i >= 0) v[static_cast<std::size_t>(s)] = x[i];
    }
    return v;
  }

 private:
  template <class Weight, class Add>
  void assemble(Weight& weight, Eigen::VectorXd& rhs, Add add) const {
    for (int s = 0; s < m_.num_states; ++s) {
      const int i = index_[static_cast<std::size_t>(s)];
      if (i < 0) continue;
      for (int a = 0; a < m_.num_actions; ++a) {
        const double w = weight(s, a);
        if (w == 0.0) continue;
        const std::size_t r = m_.row(s, a);
        rhs[i] += w * m_.expected_reward[r];
        for (std::uint32_t k = m_.row_start[r]; k < m_.row_start[r + 1]; ++k) {
          const int j = index_[static_cast<std::size_t>(m_.next_state[k])];
          if (j >= 0) add(i, j, dense_ ? 0 : entry_pos_[k], -m_.gamma * w * m_.probability[k]);
        }
      }
    }
  }

  // Chooses the band LU when its storage, n (kl + ku + 1) doubles, is at most 16 times the pattern's
  // nonzeros: then it fills in little more than a sparse LU would, without the sparse bookkeeping.
  bool try_band() {
    int kl = 0, ku = 0;
    std::size_t nnz = static_cast<std::size_t>(n_);
    for (int s = 0; s < m_.num_states; ++s) {
      const int i = index_[static_cast<std::size_t>(s)];
      if (i < 0) continue;
      for (std::uint32_t k = m_.row_start[m_.row(s, 0)]; k < m_.row_start[m_.row(s, m_.num_actions - 1) + 1];
           ++k) {
        const int j = index_[static_cast<std::size_t>(m_.next_state[k])];
        if (j < 0) continue;
        kl = std::max(kl, i - j);
        ku = std::max(ku, j - i);
        ++nnz;
      }
    }
    const double band = static_cast<double>(n_) * (kl + ku + 1);
    if (band > 16.0 * static_cast<double>(nnz) && band > 4096.0) return false;
    band_ = true;
    lu_band_.reset(n_, kl, ku);
    entry_pos_.assign(m_.num_entries(), -1);
    diag_pos_.resize(static_cast<std::size_t>(n_));
    for (int s = 0; s < m_.num_states; ++s) {
      const int i = index_[static_cast<std::size_t>(s)];
      if (i < 0) continue;
      diag_pos_[static_cast<std::size_t>(i)] = lu_band_.position(i, i);
      for (std::uint32_t k = m_.row_start[m_.row(s, 0)]; k < m_.row_start[m_.row(s, m_.num_actions - 1) + 1];
           ++k) {
        const int j = index_[static_cast<std::size_t>(m_.next_state[k])];
        if (j >= 0) entry_pos_[k] = lu_band_.position(i, j);
      }
    }
    return true;
  }

  const FiniteMdp& m_;
  std::vector<int> index_;
  int n_ = 0;
  bool dense_ = false, band_ = false;
  BandLu lu_band_;
  Eigen::SparseMatrix<double> pattern_;
  std::vector<std::int64_t> entry_pos_, diag_pos_;
  Eigen::SparseLU<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> lu_;
};

}  // namespace pegasus::detail
