// The fast local-regression refit (lwr_kernel.hpp) against the plain reference: agreement within 1e-9
// relative at random queries, bandwidths (wide, chosen-like, narrow where leaves are skipped), windows and
// templates; singular cases; the shared solve against an independent one; the same bits from every
// instruction set and any thread count; the kernel's exp.
#include "pegasus/sysid/lwr.hpp"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <random>
#include <vector>

#include "pegasus/heli/aircraft.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/parallel/thread_pool.hpp"
#include "pegasus/sysid/lwr_kernel.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::sysid;

const FlightLog& train_log() {
  static const FlightLog log = [] {
    const heli::Aircraft heli;
    heli::PilotOptions o;
    o.hover_seconds = 4;
    return heli::fly_pilot(heli, o, 150, 31).log;
  }();
  return log;
}

std::array<double, kInputs> inverse_bandwidth(const Dataset& d, double scale, bool extra_states = true) {
  std::array<double, kInputs> inv{};
  for (int j = 0; j < kOne; ++j) {
    if (!extra_states && (j == kFlapLon || j == kFlapLat || j == kGyro)) continue;
    const double sd = std::sqrt((d.x.col(j).array() - d.x.col(j).mean()).square().mean());
    inv[static_cast<std::size_t>(j)] = sd > 0 ? 1 / (scale * sd) : 0;
  }
  return inv;
}

double rel(double a, double b) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-300}); }

// Compares fast and exact at one query; returns the reciprocal condition number, -1 when both are singular.
double expect_agree(const LocalRegression& lwr, const InputVec& q, Eigen::Index lo, Eigen::Index hi,
                    const std::string& where) {
  const LocalFit fast = lwr.fit(q, lo, hi);
  const LocalFit exact = lwr.fit_exact(q, lo, hi);
  EXPECT_EQ(fast.singular, exact.singular) << where;
  if (fast.singular || exact.singular) return -1;
  EXPECT_LT(rel(fast.weight_sum, exact.weight_sum), 1e-12) << where;
  EXPECT_LT(rel(fast.max_weight, exact.max_weight), 1e-12) << where;
  EXPECT_LE(fast.points, exact.points) << where;
  // Within 1e-9 relative wherever the Jacobi-scaled X'WX is reasonably conditioned; near the singular
  // threshold no two summation orders agree better than about cond * 1e-15 (measured here: below 60 eps /
  // rcond).
  const double tol = std::max(1e-9, 1e-13 / exact.rcond);
  for (int k = 0; k < kBodyVars; ++k) {
    const auto& bf = fast.beta[static_cast<std::size_t>(k)];
    const auto& be = exact.beta[static_cast<std::size_t>(k)];
    EXPECT_LT(rel(fast.predict(k, q), exact.predict(k, q)), tol) << where << " output " << k;
    EXPECT_LT(rel(fast.leverage[k], exact.leverage[k]), tol) << where << " output " << k;
    EXPECT_LE((bf - be).cwiseAbs().maxCoeff(), tol * be.cwiseAbs().maxCoeff() + 1e-300)
        << where << " output " << k;
  }
  return true;
}

TEST(FastRefit, AgreesWithExactAtRandomQueriesBandwidthsAndWindows) {
  const Dataset data = build_dataset(train_log(), ModelStructure{});
  const auto templates = output_templates(ModelStructure{});
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_int_distribution<Eigen::Index> pick(0, data.rows() - 1);
  int compared = 0, strict = 0, pruned = 0;
  for (double scale : {16.0, 2.0, 1.0, 0.5, 0.25, 0.1}) {
    const auto inv = inverse_bandwidth(data, scale);
    const LocalRegression lwr(&data, templates, inv);
    for (int t = 0; t < 24; ++t) {
      const Eigen::Index i = pick(rng);
      InputVec q = data.x.row(i).transpose();
      // Off the data: a random step of up to about one bandwidth in each kernel input.
      for (int j = 0; j < kOne; ++j)
        if (inv[static_cast<std::size_t>(j)] > 0)
          q[j] += 0.5 * normal(rng) / inv[static_cast<std::size_t>(j)];
      const Eigen::Index lo = t % 3 == 0 ? 0 : std::max<Eigen::Index>(0, i - 80);
      const Eigen::Index hi = t % 3 == 0 ? 0 : std::min(data.rows(), i + 80);
      const double rc =
          expect_agree(lwr, q, lo, hi, "scale " + std::to_string(scale) + " row " + std::to_string(i));
      compared += rc >= 0 ? 1 : 0;
      strict += rc >= 1e-4 ? 1 : 0;  // compared at 1e-9
      pruned += lwr.fit(q, lo, hi).points < data.rows() - (hi - lo) ? 1 : 0;
    }
  }
  EXPECT_GT(compared, 100);
  EXPECT_GT(strict, 60);
  EXPECT_GT(pruned, 20);  // narrow bandwidths skip leaves
}

TEST(FastRefit, AgreesWithExactForEveryModelStructure) {
  for (int variant = 0; variant < 4; ++variant) {
    ModelStructure m;
    m.templates = variant != 1;
    m.intercept = variant != 2;
    m.extra_states = variant != 3;
    const Dataset data = build_dataset(train_log(), m);
    const LocalRegression lwr(&data, output_templates(m), inverse_bandwidth(data, 1.5, m.extra_states));
    int compared = 0;
    for (Eigen::Index i = 5; i < data.rows(); i += 173) {
      InputVec q = data.x.row(i).transpose();
      q[kV] += 0.1;
      compared += expect_agree(lwr, q, i - 40, i + 40, m.describe()) >= 0 ? 1 : 0;
    }
    EXPECT_GT(compared, 5) << m.describe();
  }
}

TEST(FastRefit, SingularCasesAgree) {
  Dataset data = build_dataset(train_log(), ModelStructure{});
  const auto templates = output_templates(ModelStructure{});
  // Far from every point at narrow bandwidths: every weight underflows.
  {
    const LocalRegression lwr(&data, templates, inverse_bandwidth(data, 0.05));
    InputVec q = data.x.row(10).transpose();
    q[kU] += 50;
    q[kW] -= 50;
    EXPECT_TRUE(lwr.fit(q).singular);
    EXPECT_TRUE(lwr.fit_exact(q).singular);
    // Every point excluded.
    EXPECT_TRUE(lwr.fit(data.x.row(10).transpose(), 0, data.rows()).singular);
    EXPECT_TRUE(lwr.fit_exact(data.x.row(10).transpose(), 0, data.rows()).singular);
  }
  // A regressor that is zero everywhere: X'WX has a zero diagonal entry.
  data.x.col(kA4).setZero();
  const LocalRegression lwr(&data, templates, inverse_bandwidth(data, 2));
  const InputVec q = data.x.row(200).transpose();
  EXPECT_TRUE(lwr.fit(q).singular);
  EXPECT_TRUE(lwr.fit_exact(q).singular);
  // Two identical regressors: rank deficient.
  data.x.col(kA4) = data.x.col(kA3);
  const LocalRegression twin(&data, templates, inverse_bandwidth(data, 2));
  EXPECT_TRUE(twin.fit(q).singular);
  EXPECT_TRUE(twin.fit_exact(q).singular);
}

// Both paths solve through one shared inverse (lwr.cpp), so their agreement cannot catch a fault in it. Here
// X'WX is rebuilt from the weights and solved independently (full-pivoting LU), at chosen-like and narrow
// bandwidths: rcond is its exact 1-norm reciprocal condition number (lwr.hpp), and the coefficients and
// leverages x'(X'WX)^-1 x of every output match.
TEST(FastRefit, SolveMatchesAnIndependentInverseOfTheScaledGram) {
  const Dataset data = build_dataset(train_log(), ModelStructure{});
  const auto templates = output_templates(ModelStructure{});
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<Eigen::Index> pick(0, data.rows() - 1);
  int checked = 0;
  for (double scale : {1.0, 0.3}) {
    const auto inv = inverse_bandwidth(data, scale);
    const LocalRegression lwr(&data, templates, inv);
    for (int t = 0; t < 6; ++t) {
      const InputVec q = data.x.row(pick(rng)).transpose();
      Eigen::VectorXd w(data.rows());
      for (Eigen::Index i = 0; i < data.rows(); ++i) {
        double d2 = 0;
        for (int j = 0; j < kInputs; ++j) {
          const double e = (q[j] - data.x(i, j)) * inv[static_cast<std::size_t>(j)];
          d2 += j == kOne ? 0.0 : e * e;
        }
        w[i] = std::exp(-0.5 * d2);
      }
      const Eigen::MatrixXd gram = data.x.transpose() * w.asDiagonal() * data.x;
      const Eigen::MatrixXd cross = data.x.transpose() * w.asDiagonal() * data.y;
      const LocalFit exact = lwr.fit_exact(q);
      const LocalFit fast = lwr.fit(q);
      if (exact.singular) continue;
      double expected = INFINITY;
      std::array<Eigen::VectorXd, kBodyVars> beta;
      std::array<double, kBodyVars> leverage{};
      for (int k = 0; k < kBodyVars; ++k) {
        const auto& tmpl = templates[static_cast<std::size_t>(k)];
        beta[static_cast<std::size_t>(k)] = Eigen::VectorXd::Zero(kInputs);
        if (tmpl.free_count() == 0) continue;
        std::vector<int> idx;
        for (int j = 0; j < kInputs; ++j)
          if (tmpl.free[static_cast<std::size_t>(j)]) idx.push_back(j);
        const auto m = static_cast<Eigen::Index>(idx.size());
        Eigen::MatrixXd g(m, m), a(m, m);
        Eigen::VectorXd b(m), x(m);
        for (Eigen::Index r = 0; r < m; ++r) {
          b[r] = cross(idx[r], k);
          x[r] = q[idx[r]];
          for (Eigen::Index c = 0; c < m; ++c) {
            g(r, c) = gram(idx[r], idx[c]);
            a(r, c) = g(r, c) / std::sqrt(gram(idx[r], idx[r]) * gram(idx[c], idx[c]));
          }
        }
        const Eigen::MatrixXd a_inv = a.fullPivLu().inverse();
        expected = std::min(expected, 1 / (a.cwiseAbs().colwise().sum().maxCoeff() *
                                           a_inv.cwiseAbs().colwise().sum().maxCoeff()));
        const auto lu = g.fullPivLu();
        const Eigen::VectorXd sol = lu.solve(b);
        for (Eigen::Index r = 0; r < m; ++r) beta[static_cast<std::size_t>(k)][idx[r]] = sol[r];
        leverage[static_cast<std::size_t>(k)] = x.dot(lu.solve(x));
      }
      // Two inverses of the same matrix agree within about cond * eps.
      const double tol = std::max(1e-9, 1e-13 / expected);
      for (const LocalFit* fit : {&exact, &fast}) {
        const char* path = fit == &exact ? "exact" : "fast";
        EXPECT_LT(rel(fit->rcond, expected), tol) << path << " scale " << scale << " query " << t;
        for (int k = 0; k < kBodyVars; ++k) {
          const Eigen::VectorXd got = fit->beta[static_cast<std::size_t>(k)];
          const auto& want = beta[static_cast<std::size_t>(k)];
          EXPECT_LE((got - want).cwiseAbs().maxCoeff(), tol * want.cwiseAbs().maxCoeff() + 1e-300)
              << path << " scale " << scale << " query " << t << " output " << k;
          EXPECT_LT(rel(fit->leverage[k], leverage[static_cast<std::size_t>(k)]), tol)
              << path << " scale " << scale << " query " << t << " output " << k;
        }
      }
      ++checked;
    }
  }
  EXPECT_GE(checked, 10);
}

TEST(FastRefit, EveryInstructionSetGivesTheSameBits) {
  const Dataset data = build_dataset(train_log(), ModelStructure{});
  const LocalRegression lwr(&data, output_templates(ModelStructure{}), inverse_bandwidth(data, 1));
  const LocalRegression narrow(&data, output_templates(ModelStructure{}), inverse_bandwidth(data, 0.2));
  std::vector<LocalFit> reference;
  for (const InstructionSet path : supported_instruction_sets()) {
    force_lwr_instruction_set(path);
    std::size_t n = 0;
    for (const LocalRegression* r : {&lwr, &narrow})
      for (Eigen::Index i = 1; i < data.rows(); i += 101) {
        InputVec q = data.x.row(i).transpose();
        q[kPitchRate] += 0.05;
        // fit_exact too: its solve runs on the same instruction set.
        const LocalFit f = i % 4 == 1 ? r->fit_exact(q, i - 30, i + 30) : r->fit(q, i - 30, i + 30);
        if (path == InstructionSet::kBaseline) {
          reference.push_back(f);
          continue;
        }
        const LocalFit& e = reference[n++];
        SCOPED_TRACE(instruction_set_name(lwr_instruction_set()));
        EXPECT_EQ(f.singular, e.singular);
        EXPECT_EQ(f.points, e.points);
        EXPECT_EQ(f.weight_sum, e.weight_sum);
        EXPECT_EQ(f.max_weight, e.max_weight);
        EXPECT_EQ(f.rcond, e.rcond);
        for (int k = 0; k < kBodyVars; ++k) {
          EXPECT_EQ(f.beta[static_cast<std::size_t>(k)], e.beta[static_cast<std::size_t>(k)]) << k;
          EXPECT_EQ(f.leverage[k], e.leverage[k]);
        }
      }
  }
  force_lwr_instruction_set(std::nullopt);
  EXPECT_GT(reference.size(), 20u);
}

TEST(FastRefit, ResultsDoNotDependOnThreads) {
  const Dataset data = build_dataset(train_log(), ModelStructure{});
  const LocalRegression lwr(&data, output_templates(ModelStructure{}), inverse_bandwidth(data, 1));
  const std::size_t n = 64;
  auto run = [&](int threads) {
    ThreadPool pool(threads);
    std::vector<LocalFit> fits(n);
    pool.parallel_for(n, [&](std::size_t p) {
      const auto i = static_cast<Eigen::Index>(p * 37 % static_cast<std::size_t>(data.rows()));
      fits[p] = lwr.fit(data.x.row(i).transpose(), i - 50, i + 50);
    });
    return fits;
  };
  const auto one = run(1), three = run(3);
  for (std::size_t p = 0; p < n; ++p)
    for (int k = 0; k < kBodyVars; ++k) {
      EXPECT_EQ(one[p].beta[static_cast<std::size_t>(k)], three[p].beta[static_cast<std::size_t>(k)]);
      EXPECT_EQ(one[p].leverage[k], three[p].leverage[k]);
    }
}

TEST(FastRefit, KernelExpIsWithinOneUlpOfStdExp) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-708, 0);
  double worst = 0;
  for (int t = 0; t < 200000; ++t) {
    const double x = t < 1000 ? -1e-3 * t : u(rng);
    const double e = std::exp(x), k = sysid::detail::kernel_exp(x);
    worst = std::max(worst, std::abs(k - e) / (std::nextafter(e, INFINITY) - e));
  }
  EXPECT_LE(worst, 1.0);
  EXPECT_EQ(sysid::detail::kernel_exp(0.0), 1.0);
  EXPECT_EQ(sysid::detail::kernel_exp(-709.0), 0.0);
  EXPECT_EQ(sysid::detail::kernel_exp(-INFINITY), 0.0);
  EXPECT_EQ(sysid::detail::kernel_exp(NAN), 0.0);
}

}  // namespace
