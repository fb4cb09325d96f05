#include "pegasus/shaping/audit.hpp"

#include <fmt/format.h>

#include <Eigen/OrderingMethods>
#include <Eigen/Sparse>
#include <Eigen/SparseQR>
#include <algorithm>
#include <cmath>
#include <limits>
#include <tuple>
#include <unordered_map>

#include "pegasus/core/error.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/shaping/potential_shaping.hpp"

namespace pegasus {

namespace {

struct Triple {
  int s, a, n;
  double f;
};

// One (s, s') pair of the scope with the spread of F over the actions that reach it.
struct Pair {
  int s, n;
  double f;  // F under the lowest action (the value used off the scope)
  double fmax, fmin;
  int amax, amin;
};

class Scope {
 public:
  Scope(const FiniteMdp& m, const ShapingTable& table) : S_(m.num_states) {
    // Support triples come out of the CSR arrays sorted by (s, a, n), like the table's entries.
    std::vector<Triple> support;
    for (int s = 0; s < m.num_states; ++s) {
      if (m.is_absorbing(s)) continue;
      for (int a = 0; a < m.num_actions; ++a) {
        const std::size_t r = m.row(s, a);
        for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k)
          support.push_back({s, a, m.next_state[k], 0.0});
      }
    }
    auto less = [](const Triple& x, const Triple& y) {
      return std::tie(x.s, x.a, x.n) < std::tie(y.s, y.a, y.n);
    };
    std::vector<Triple> listed;
    for (const auto& e : table.entries())
      if (!m.is_absorbing(e.state)) listed.push_back({e.state, e.action, e.next, e.value});
    std::merge(support.begin(), support.end(), listed.begin(), listed.end(), std::back_inserter(triples_),
               less);
    triples_.erase(
        std::unique(triples_.begin(), triples_.end(),
                    [](const Triple& x, const Triple& y) { return x.s == y.s && x.a == y.a && x.n == y.n; }),
        triples_.end());
    for (auto& t : triples_) t.f = table(t.s, t.a, t.n);
    // Pairs, grouped by (s, n).
    std::vector<std::size_t> order(triples_.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
      const auto &x = triples_[i], &y = triples_[j];
      return std::tie(x.s, x.n, x.a) < std::tie(y.s, y.n, y.a);
    });
    for (std::size_t i : order) {
      const Triple& t = triples_[i];
      if (pairs_.empty() || pairs_.back().s != t.s || pairs_.back().n != t.n) {
        pairs_.push_back({t.s, t.n, t.f, t.f, t.f, t.a, t.a});
      } else {
        Pair& p = pairs_.back();
        if (t.f > p.fmax) p.fmax = t.f, p.amax = t.a;
        if (t.f < p.fmin) p.fmin = t.f, p.amin = t.a;
      }
    }
    for (std::size_t i = 0; i < pairs_.size(); ++i) pair_index_.emplace(key(pairs_[i].s, pairs_[i].n), i);
  }

  const std::vector<Triple>& triples() const { return triples_; }
  const std::vector<Pair>& pairs() const { return pairs_; }
  bool has_pair(int s, int n) const { return pair_index_.count(key(s, n)) != 0; }
  bool has_triple(int s, int a, int n) const {
    const Triple probe{s, a, n, 0.0};
    return std::binary_search(triples_.begin(), triples_.end(), probe, [](const Triple& x, const Triple& y) {
      return std::tie(x.s, x.a, x.n) < std::tie(y.s, y.a, y.n);
    });
  }
  // F extended off the scope: the triple's own value, else the pair's, else 0.
  double f_ext(int s, int a, int n) const {
    const Triple probe{s, a, n, 0.0};
    const auto it = std::lower_bound(
        triples_.begin(), triples_.end(), probe,
        [](const Triple& x, const Triple& y) { return std::tie(x.s, x.a, x.n) < std::tie(y.s, y.a, y.n); });
    if (it != triples_.end() && it->s == s && it->a == a && it->n == n) return it->f;
    return f_pair(s, n);
  }
  double f_pair(int s, int n) const {
    const auto it = pair_index_.find(key(s, n));
    return it == pair_index_.end() ? 0.0 : pairs_[it->second].f;
  }

 private:
  std::uint64_t key(int s, int n) const {
    return static_cast<std::uint64_t>(s) * static_cast<std::uint64_t>(S_) + static_cast<std::uint64_t>(n);
  }
  int S_;
  std::vector<Triple> triples_;
  std::vector<Pair> pairs_;
  std::unordered_map<std::uint64_t, std::size_t> pair_index_;
};

// Least-squares Phi over the scope triples, Phi(absorbing) = 0. A tiny ridge row per unknown keeps the
// system full rank (potentials of components that no triple constrains stay near 0); its bias on
// determined components is O(ridge^2).
void fit_potential(const FiniteMdp& m, const Scope& scope, ShapingAudit* out) {
  constexpr double kRidge = 1e-8;
  const int S = m.num_states;
  std::vector<int> index(static_cast<std::size_t>(S), -1);
  int n = 0;
  for (int s = 0; s < S; ++s)
    if (!m.is_absorbing(s)) index[static_cast<std::size_t>(s)] = n++;
  out->potential.assign(static_cast<std::size_t>(S), 0.0);
  const auto& tr = scope.triples();
  if (n > 0) {
    const auto rows = static_cast<Eigen::Index>(tr.size()) + n;
    std::vector<Eigen::Triplet<double>> trip;
    trip.reserve(2 * tr.size() + static_cast<std::size_t>(n));
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(rows);
    for (std::size_t i = 0; i < tr.size(); ++i) {
      const auto row = static_cast<Eigen::Index>(i);
      const int is = index[static_cast<std::size_t>(tr[i].s)], in = index[static_cast<std::size_t>(tr[i].n)];
      trip.emplace_back(row, is, -1.0);
      if (in >= 0) trip.emplace_back(row, in, m.gamma);  // duplicates (self-loops) are summed
      rhs[row] = tr[i].f;
    }
    for (int j = 0; j < n; ++j) trip.emplace_back(static_cast<Eigen::Index>(tr.size()) + j, j, kRidge);
    Eigen::SparseMatrix<double> a(rows, n);
    a.setFromTriplets(trip.begin(), trip.end());
    a.makeCompressed();
    Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::COLAMDOrdering<int>> qr;
    qr.compute(a);
    if (qr.info() != Eigen::Success) throw InputError("shaping audit: least-squares factorisation failed");
    const Eigen::VectorXd x = qr.solve(rhs);
    for (int s = 0; s < S; ++s)
      if (index[static_cast<std::size_t>(s)] >= 0)
        out->potential[static_cast<std::size_t>(s)] = x[index[static_cast<std::size_t>(s)]];
  }
  double worst = 0.0, sq = 0.0;
  for (const auto& t : tr) {
    const double e = m.gamma * out->potential[static_cast<std::size_t>(t.n)] -
                     out->potential[static_cast<std::size_t>(t.s)] - t.f;
    worst = std::max(worst, std::abs(e));
    sq += e * e;
  }
  out->max_residual = worst;
  out->rms_residual = tr.empty() ? 0.0 : std::sqrt(sq / static_cast<double>(tr.size()));
}

// A directed cycle of scope pairs between non-absorbing states whose net F is positive (sign = +1) or
// negative (sign = -1): Bellman-Ford on sign * F from a virtual source; a relaxation in round |S| lies
// downstream of such a cycle.
std::optional<ShapingCycle> find_cycle(const FiniteMdp& m, const Scope& scope, double sign, double tol) {
  struct Edge {
    int u, v, a;
    double w;
  };
  std::vector<Edge> edges;
  for (const auto& p : scope.pairs()) {
    if (m.is_absorbing(p.n)) continue;
    const bool up = sign > 0;
    edges.push_back({p.s, p.n, up ? p.amax : p.amin, sign * (up ? p.fmax : p.fmin)});
  }
  const int S = m.num_states;
  std::vector<double> dist(static_cast<std::size_t>(S), 0.0);
  std::vector<int> pred(static_cast<std::size_t>(S), -1), pred_action(static_cast<std::size_t>(S), -1);
  int last = -1;
  for (int round = 0; round <= S; ++round) {
    last = -1;
    for (const auto& e : edges) {
      if (dist[static_cast<std::size_t>(e.u)] + e.w > dist[static_cast<std::size_t>(e.v)] + tol) {
        dist[static_cast<std::size_t>(e.v)] = dist[static_cast<std::size_t>(e.u)] + e.w;
        pred[static_cast<std::size_t>(e.v)] = e.u;
        pred_action[static_cast<std::size_t>(e.v)] = e.a;
        last = e.v;
      }
    }
    if (last < 0) return std::nullopt;
  }
  int x = last;
  for (int i = 0; i < S; ++i) x = pred[static_cast<std::size_t>(x)];  // now on the cycle
  ShapingCycle c;
  std::vector<int> rev_states, rev_actions;
  int y = x;
  do {
    const int p = pred[static_cast<std::size_t>(y)];
    rev_states.push_back(p);
    rev_actions.push_back(pred_action[static_cast<std::size_t>(y)]);
    y = p;
  } while (y != x && rev_states.size() <= static_cast<std::size_t>(S));
  c.states.assign(rev_states.rbegin(), rev_states.rend());
  c.actions.assign(rev_actions.rbegin(), rev_actions.rend());
  for (std::size_t i = 0; i < c.states.size(); ++i) {
    const int u = c.states[i], v = c.states[(i + 1) % c.states.size()];
    c.net_shaping += scope.f_ext(u, c.actions[i], v);
  }
  if (!(sign * c.net_shaping > tol)) return std::nullopt;
  return c;
}

// Solves the counterexample with and without F and compares the optimal actions at the decision state.
void verify(const Scope& scope, Counterexample* cx) {
  cx->shaped = add_shaping(cx->mdp, [&scope](int s, int a, int n) { return scope.f_ext(s, a, n); });
  auto mask_at = [&](const FiniteMdp& m) {
    const auto sol = policy_iteration(m);
    const auto q = q_from_values(m, sol.value);
    double scale = 1.0;
    for (double x : q) scale = std::max(scale, std::abs(x));
    // The flip margin is about |Delta|/2; the tie tolerance must stay well below it.
    const double tie = std::min(1e-9 * scale, std::abs(cx->delta) / 8.0);
    return near_optimal_actions(m, q, tie)[static_cast<std::size_t>(cx->decision_state)];
  };
  cx->optimal_actions = mask_at(cx->mdp);
  cx->shaped_optimal_actions = mask_at(cx->shaped);
  cx->verified = (cx->optimal_actions & cx->shaped_optimal_actions) == 0;
}

// Everything else in a counterexample: non-absorbing states other than the ones the flip uses go to the
// anchor (or stay put when there is none), absorbing states stay absorbing.
void fill_rest(const FiniteMdp& m, FiniteMdpBuilder& b, int anchor, const std::vector<int>& used) {
  for (int t = 0; t < m.num_states; ++t) {
    if (m.is_absorbing(t)) {
      b.set_absorbing(t);
      continue;
    }
    if (std::find(used.begin(), used.end(), t) != used.end()) continue;
    for (int a = 0; a < m.num_actions; ++a) b.add_transition(t, a, anchor >= 0 ? anchor : t, 1.0, 0.0);
  }
}

int first_absorbing(const FiniteMdp& m) {
  for (int s = 0; s < m.num_states; ++s)
    if (m.is_absorbing(s)) return s;
  return -1;
}

// Lemma 4: all actions lead from s to the same place, R(s, b) = (g_max - g_b)/2 makes the actions with the
// smallest shaping g_b optimal in M and those with the largest optimal in M + F.
std::optional<Counterexample> lemma4_counterexample(const FiniteMdp& m, const Scope& scope,
                                                    const ActionDependence& w, double tol) {
  const int s = w.state, n = w.next_state, A = m.num_actions;
  const int z = first_absorbing(m);
  for (double q : {0.5, 0.25}) {
    std::vector<double> g(static_cast<std::size_t>(A));
    for (int b = 0; b < A; ++b) {
      if (n != s)
        g[static_cast<std::size_t>(b)] = scope.f_ext(s, b, n);
      else if (z >= 0)
        g[static_cast<std::size_t>(b)] = q * scope.f_ext(s, b, s) + (1 - q) * scope.f_ext(s, b, z);
      else
        g[static_cast<std::size_t>(b)] = scope.f_ext(s, b, s);
    }
    const double gmax = *std::max_element(g.begin(), g.end()), gmin = *std::min_element(g.begin(), g.end());
    if (!(gmax - gmin > tol)) continue;
    FiniteMdpBuilder b(m.num_states, A, m.gamma);
    for (int a = 0; a < A; ++a) {
      const double r = (gmax - g[static_cast<std::size_t>(a)]) / 2.0;
      if (n != s) {
        b.add_transition(s, a, n, 1.0, r);
      } else if (z >= 0) {
        b.add_transition(s, a, s, q, r);
        b.add_transition(s, a, z, 1.0 - q, r);
      } else {
        b.add_transition(s, a, s, 1.0, r);
      }
    }
    fill_rest(m, b, z, {s});
    b.set_initial(s, 1.0);
    Counterexample cx{b.build(), {}, s, 0, 0, gmax - gmin, false, false, {}};
    cx.uses_only_scope = n != s ? scope.has_pair(s, n) : (z < 0 || scope.has_pair(s, z));
    cx.description = fmt::format(
        "Lemma 4: every action takes state {} to {}{}; R(s, b) = (max_b' g - g_b)/2 for the shaping g_b each "
        "action "
        "collects, so M prefers the actions F rewards least and M + F those it rewards most (spread {:.6g})",
        s, n, n == s && z >= 0 ? fmt::format(" (probability {}, else absorbing {})", q, z) : "", gmax - gmin);
    verify(scope, &cx);
    return cx;
  }
  return std::nullopt;
}

// Appendix 3.A, Fig 3.4: from s1, action 0 goes straight to the anchor z with reward Delta/2; every other
// action goes through s2 (or, when s2 = s1, loops with probability 1/2) and then to z, with reward 0.
// Delta is the extra shaping of the second route. For potential-based F both routes collect -Phi(s1)
// (Phi(z) = 0 or the self-loop's stationary value), so Delta = 0; otherwise some (s1, s2) in the scope has
// Delta != 0 (for an absorbing anchor, Phi(s) = -F(s, z) would be a potential otherwise).
std::optional<Counterexample> appendix_counterexample(const FiniteMdp& m, const Scope& scope,
                                                      const AuditOptions& o, double tol, std::string* note) {
  if (m.num_actions < 2) {
    *note = "with a single action every policy is the same, so no shaping can change it";
    return std::nullopt;
  }
  const double g = m.gamma;
  std::vector<int> anchors;
  for (int s = 0; s < m.num_states && static_cast<int>(anchors.size()) < o.max_anchors; ++s)
    if (m.is_absorbing(s)) anchors.push_back(s);
  if (anchors.empty())
    for (int s = 0; s < m.num_states && static_cast<int>(anchors.size()) < o.max_anchors; ++s)
      anchors.push_back(s);
  constexpr double q = 0.5;
  struct Best {
    int z = -1, s1 = -1, s2 = -1, off = 1 << 30;
    double delta = 0.0;
  } best;
  for (int z : anchors) {
    const bool z_abs = m.is_absorbing(z);
    const double tz = z_abs ? 0.0 : scope.f_pair(z, z) / (1.0 - g);  // g < 1 when z is not absorbing
    for (const auto& p : scope.pairs()) {
      const int s1 = p.s, s2 = p.n;
      if (s1 == z || s2 == z) continue;
      const double ga = scope.f_pair(s1, z) + g * tz;
      double gb;
      int off = (scope.has_pair(s1, z) ? 0 : 1) + (z_abs || scope.has_pair(z, z) ? 0 : 1);
      if (m.is_absorbing(s2)) {
        gb = p.f;
      } else if (s2 != s1) {
        gb = p.f + g * (scope.f_pair(s2, z) + g * tz);
        off += scope.has_pair(s2, z) ? 0 : 1;
      } else {
        gb = (q * p.f + (1 - q) * ga) / (1.0 - g * q);
      }
      const double delta = gb - ga;
      if (!(std::abs(delta) > tol)) continue;
      if (off < best.off || (off == best.off && std::abs(delta) > std::abs(best.delta)))
        best = {z, s1, s2, off, delta};
    }
  }
  if (best.z < 0) {
    *note = fmt::format("no (s1, s2, anchor) triple with a non-zero Delta among {} anchors", anchors.size());
    return std::nullopt;
  }
  const int z = best.z, s1 = best.s1, s2 = best.s2;
  FiniteMdpBuilder b(m.num_states, m.num_actions, g);
  b.add_transition(s1, 0, z, 1.0, best.delta / 2.0);
  for (int a = 1; a < m.num_actions; ++a) {
    if (s2 != s1) {
      b.add_transition(s1, a, s2, 1.0, 0.0);
    } else {
      b.add_transition(s1, a, s1, q, 0.0);
      b.add_transition(s1, a, z, 1.0 - q, 0.0);
    }
  }
  std::vector<int> used = {s1};
  if (s2 != s1 && !m.is_absorbing(s2)) {
    for (int a = 0; a < m.num_actions; ++a) b.add_transition(s2, a, z, 1.0, 0.0);
    used.push_back(s2);
  }
  if (!m.is_absorbing(z)) {
    for (int a = 0; a < m.num_actions; ++a) b.add_transition(z, a, z, 1.0, 0.0);
    used.push_back(z);
  }
  fill_rest(m, b, z, used);
  b.set_initial(s1, 1.0);
  Counterexample cx{b.build(), {}, s1, 0, 0, best.delta, false, best.off == 0, {}};
  cx.description = fmt::format(
      "Appendix 3.A: from state {}, action 0 goes to {} state {} with reward Delta/2; the other actions go "
      "{} "
      "with reward 0; Delta = {:.6g} is the extra shaping the second route collects, so M and M + F disagree",
      s1, m.is_absorbing(z) ? "absorbing" : "anchor", z,
      s2 == s1 ? fmt::format("back to {} with probability 1/2 (else to {})", s1, z)
               : fmt::format("to {} and then to {}", s2, z),
      best.delta);
  verify(scope, &cx);
  return cx;
}

PolicyChange policy_change(const FiniteMdp& m, const ShapingTable& f) {
  PolicyChange pc;
  const FiniteMdp shaped = add_shaping(m, f);
  const auto base = policy_iteration(m);
  const auto sh = policy_iteration(shaped);
  const auto qb = q_from_values(m, base.value), qs = q_from_values(shaped, sh.value);
  auto scale = [](const std::vector<double>& q) {
    double x = 1.0;
    for (double v : q) x = std::max(x, std::abs(v));
    return x;
  };
  const auto mb = near_optimal_actions(m, qb, 1e-9 * scale(qb));
  const auto ms = near_optimal_actions(shaped, qs, 1e-9 * scale(qs));
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) continue;
    if ((ms[static_cast<std::size_t>(s)] & ~mb[static_cast<std::size_t>(s)]) != 0) pc.states.push_back(s);
  }
  pc.changes = !pc.states.empty();
  const auto v_pi = evaluate_policy(m, sh.policy);
  for (int s = 0; s < m.num_states; ++s) {
    const double loss = base.value[static_cast<std::size_t>(s)] - v_pi[static_cast<std::size_t>(s)];
    pc.max_loss = std::max(pc.max_loss, loss);
    pc.loss_under_initial += m.initial[static_cast<std::size_t>(s)] * loss;
  }
  return pc;
}

}  // namespace

bool AuditOptions::IsValid(std::string* error) const {
  auto bad = [&](const std::string& msg) {
    if (error) *error = "audit options: " + msg;
    return false;
  };
  if (!(tolerance > 0.0)) return bad(fmt::format("tolerance must be > 0, got {}", tolerance));
  if (max_anchors < 1) return bad(fmt::format("max_anchors must be >= 1, got {}", max_anchors));
  if (!(max_cycle_search_work >= 0.0)) return bad("max_cycle_search_work must be >= 0");
  return true;
}

std::string ShapingAudit::BriefReport() const {
  if (potential_based)
    return fmt::format(
        "potential-based (least-squares residual max {:.3g}, rms {:.3g} over {} transitions); "
        "optimal policy {}",
        max_residual, rms_residual, scope_size, policy_change.changes ? "CHANGES" : "unchanged");
  std::string why = action_dependence ? fmt::format("F depends on the action at state {} -> {}",
                                                    action_dependence->state, action_dependence->next_state)
                    : cycle           ? fmt::format("a cycle of {} states collects net shaping {:.6g}",
                                                    cycle->states.size(), cycle->net_shaping)
                                      : std::string("no potential fits");
  return fmt::format(
      "NOT potential-based: {} (residual max {:.3g}); counterexample {}; optimal policy of the given "
      "MDP {}",
      why, max_residual,
      counterexample ? (counterexample->verified ? "flips (verified)" : "built but NOT verified")
                     : "not built",
      policy_change.changes ? "CHANGES" : "unchanged");
}

ShapingAudit audit_shaping(const FiniteMdp& m, const ShapingTable& f, const AuditOptions& o) {
  std::string err;
  if (!o.IsValid(&err)) throw InputError(err);
  if (f.num_states() != m.num_states || f.num_actions() != m.num_actions)
    throw InputError(
        fmt::format("shaping audit: the shaping table is {} states x {} actions but the MDP is {} x {}",
                    f.num_states(), f.num_actions(), m.num_states, m.num_actions));
  ShapingAudit out;
  const Scope scope(m, f);
  out.scope_size = scope.triples().size();
  double fmax = 0.0;
  for (const auto& t : scope.triples()) fmax = std::max(fmax, std::abs(t.f));
  const double tol = o.tolerance * (1.0 + fmax);
  out.tolerance_used = tol;
  fit_potential(m, scope, &out);
  out.potential_based = out.max_residual <= tol;
  out.policy_change = policy_change(m, f);
  if (out.potential_based) return out;

  // Lemma 4 witness: the pair with the largest spread over actions.
  const Pair* worst = nullptr;
  for (const auto& p : scope.pairs())
    if (p.fmax - p.fmin > tol && (!worst || p.fmax - p.fmin > worst->fmax - worst->fmin)) worst = &p;
  if (worst)
    out.action_dependence =
        ActionDependence{worst->s, worst->n, worst->amax, worst->amin, worst->fmax, worst->fmin};

  if (m.gamma == 1.0 && static_cast<double>(m.num_states) * static_cast<double>(scope.pairs().size()) <=
                            o.max_cycle_search_work) {
    out.cycle = find_cycle(m, scope, +1.0, tol);
    if (!out.cycle) out.cycle = find_cycle(m, scope, -1.0, tol);
  }

  if (out.action_dependence) {
    if (m.num_actions < 2) {
      out.counterexample_note = "a single action";
    } else {
      out.counterexample = lemma4_counterexample(m, scope, *out.action_dependence, tol);
      if (!out.counterexample)
        out.counterexample_note = "the action dependence cancels out in every construction tried";
    }
  } else {
    out.counterexample = appendix_counterexample(m, scope, o, tol, &out.counterexample_note);
  }
  return out;
}

}  // namespace pegasus
