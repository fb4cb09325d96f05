// Finite MDPs (thesis §2.1) from transition triplets (python/pegasus/mdp.py builds them from numpy arrays or
// scipy.sparse), their solvers (§2.2-2.3), potential shaping (§3.3, Eq 3.1) and the shaping audit.
#include <fmt/format.h>

#include "common.hpp"
#include "pegasus/mdp/finite_mdp.hpp"
#include "pegasus/mdp/solvers.hpp"
#include "pegasus/shaping/audit.hpp"
#include "pegasus/shaping/potential_shaping.hpp"
#include "pegasus/shaping/shaping_table.hpp"

namespace pegasus::python {

namespace {

std::vector<int> as_indices(py::handle object, const std::string& name, py::ssize_t size, int bound) {
  const Array a = as_vector(object, name, size);
  std::vector<int> out(static_cast<std::size_t>(a.size()));
  for (py::ssize_t k = 0; k < a.size(); ++k) {
    const double x = a.data()[k];
    if (!(x >= 0 && x < bound && x == std::floor(x)))
      throw py::value_error(
          fmt::format("{}: expected integers in [0, {}), got {} at index {}", name, bound, x, k));
    out[static_cast<std::size_t>(k)] = static_cast<int>(x);
  }
  return out;
}

FiniteMdp from_triplets(std::int64_t num_states, std::int64_t num_actions, double gamma, ArrayLikeArg state,
                        ArrayLikeArg action, ArrayLikeArg next, ArrayLikeArg probability, ArrayLikeArg reward,
                        ArrayLikeArg state_reward, ArrayLikeArg state_action_reward, ArrayLikeArg absorbing,
                        ArrayLikeArg initial) {
  if (num_states < 1 || num_states > (1 << 30))
    throw py::value_error(fmt::format("num_states: expected an integer in [1, 2^30], got {}", num_states));
  if (num_actions < 1 || num_actions > 64)
    throw py::value_error(fmt::format("num_actions: expected an integer in [1, 64], got {}", num_actions));
  const int S = static_cast<int>(num_states), A = static_cast<int>(num_actions);
  const Array p = as_vector(probability, "P", -1);
  require_finite(p, "P");
  const auto nnz = p.shape(0);
  const auto s = as_indices(state, "P (states)", nnz, S), a = as_indices(action, "P (actions)", nnz, A),
             n = as_indices(next, "P (next states)", nnz, S);
  const Array r = as_vector(reward, "R", nnz);
  require_finite(r, "R");
  FiniteMdpBuilder builder(S, A, gamma);
  std::vector<std::uint8_t> is_absorbing(static_cast<std::size_t>(S), 0);
  if (!absorbing.is_none())
    for (int x : as_indices(absorbing, "absorbing", -1, S)) {
      builder.set_absorbing(x);
      is_absorbing[static_cast<std::size_t>(x)] = 1;
    }
  for (py::ssize_t k = 0; k < nnz; ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (is_absorbing[static_cast<std::size_t>(s[i])] || p.data()[k] == 0.0) continue;
    builder.add_transition(s[i], a[i], n[i], p.data()[k], r.data()[k]);
  }
  if (!state_reward.is_none()) {
    const Array x = as_vector(state_reward, "R", S);
    require_finite(x, "R");
    for (int i = 0; i < S; ++i) builder.set_state_reward(i, x.data()[i]);
  }
  if (!state_action_reward.is_none()) {
    const Array x = as_matrix(state_action_reward, "R", S, A);
    require_finite(x, "R");
    for (int i = 0; i < S; ++i)
      for (int j = 0; j < A; ++j) builder.set_state_action_reward(i, j, x.data()[i * A + j]);
  }
  if (!initial.is_none()) {
    const Array x = as_vector(initial, "initial", S);
    require_finite(x, "initial");
    for (int i = 0; i < S; ++i)
      if (x.data()[i] != 0.0) builder.set_initial(i, x.data()[i]);
  }
  return builder.build();
}

ShapingTable shaping_table(const FiniteMdp& mdp, ArrayLikeArg state, ArrayLikeArg action, ArrayLikeArg next,
                           ArrayLikeArg value) {
  const Array v = as_vector(value, "F", -1);
  require_finite(v, "F");
  const auto nnz = v.shape(0);
  const auto s = as_indices(state, "F (states)", nnz, mdp.num_states),
             a = as_indices(action, "F (actions)", nnz, mdp.num_actions),
             n = as_indices(next, "F (next states)", nnz, mdp.num_states);
  std::vector<ShapingEntry> entries;
  for (std::size_t k = 0; k < s.size(); ++k)
    if (v.data()[k] != 0.0) entries.push_back({s[k], a[k], n[k], v.data()[k]});
  return ShapingTable(mdp.num_states, mdp.num_actions, std::move(entries));
}

}  // namespace

void bind_mdp(py::module_& m) {
  py::class_<FiniteMdp>(m, "FiniteMdp", R"doc(
A finite MDP (S, D, A, P, gamma, R) of thesis §2.1, stored as sparse rows. Build it with pegasus.finite_mdp(P, R,
gamma, absorbing=..., initial=...) from numpy arrays or scipy.sparse matrices.)doc")
      .def_static("_from_triplets", &from_triplets, py::arg("num_states"), py::arg("num_actions"),
                  py::arg("gamma"), py::arg("state"), py::arg("action"), py::arg("next"),
                  py::arg("probability"), py::arg("reward"), py::arg("state_reward") = py::none(),
                  py::arg("state_action_reward") = py::none(), py::arg("absorbing") = py::none(),
                  py::arg("initial") = py::none())
      .def_readonly("num_states", &FiniteMdp::num_states, "Number of states S.")
      .def_readonly("num_actions", &FiniteMdp::num_actions, "Number of actions A, the same in every state.")
      .def_readonly("gamma", &FiniteMdp::gamma,
                    "Discount factor in [0, 1] (1: the MDP must be proper, thesis §2.1).")
      .def_property_readonly(
          "absorbing",
          [](const FiniteMdp& mdp) {
            std::vector<int> out;
            for (int s = 0; s < mdp.num_states; ++s)
              if (mdp.is_absorbing(s)) out.push_back(s);
            return out;
          },
          "The absorbing states, ascending: an episode ends there (no further reward, value 0).")
      .def_property_readonly(
          "initial", [](const FiniteMdp& mdp) { return vector_array(mdp.initial); },
          "The initial distribution D, one probability per state (uniform over the non-absorbing states "
          "unless given).")
      .def_property_readonly(
          "expected_reward",
          [](const FiniteMdp& mdp) {
            Array out = matrix(mdp.num_states, mdp.num_actions);
            std::copy(mdp.expected_reward.begin(), mdp.expected_reward.end(), out.mutable_data());
            return out;
          },
          "R(s, a) = sum_s' P_sa(s') R(s, a, s'), shape (S, A).")
      .def(
          "value_iteration",
          [](const FiniteMdp& mdp, double epsilon, bool gauss_seidel, int max_iterations) {
            ValueIterationOptions o;
            o.epsilon = epsilon, o.gauss_seidel = gauss_seidel, o.max_iterations = max_iterations;
            std::string error;
            if (!o.IsValid(mdp, &error)) throw py::value_error(error);
            ReleaseGilInterruptibly release;
            return value_iteration(mdp, o);
          },
          py::arg("epsilon") = 1e-8, py::arg("gauss_seidel") = false, py::arg("max_iterations") = 1'000'000,
          "Value iteration with a certified epsilon-optimal greedy policy; returns a SolveSummary.")
      .def(
          "policy_iteration",
          [](const FiniteMdp& mdp, int max_iterations) {
            PolicyIterationOptions o;
            o.max_iterations = max_iterations;
            std::string error;
            if (!o.IsValid(mdp, &error)) throw py::value_error(error);
            ReleaseGilInterruptibly release;
            return policy_iteration(mdp, o);
          },
          py::arg("max_iterations") = 10'000,
          "Policy iteration with exact evaluation; returns a SolveSummary.")
      .def(
          "evaluate_policy",
          [](const FiniteMdp& mdp, ArrayLikeArg policy) {
            const Array a = as_array(policy, "policy");
            if (a.ndim() == 2) {
              const Array probs = as_matrix(a, "policy", mdp.num_states, mdp.num_actions);
              require_finite(probs, "policy");
              StochasticPolicy pi{mdp.num_states, mdp.num_actions,
                                  std::vector<double>(probs.data(), probs.data() + probs.size())};
              std::vector<double> v;
              {
                ReleaseGilInterruptibly release;
                v = evaluate_policy(mdp, pi);
              }
              return vector_array(v);
            }
            const std::vector<int> pi = as_indices(a, "policy", mdp.num_states, mdp.num_actions);
            std::vector<double> v;
            {
              ReleaseGilInterruptibly release;
              v = evaluate_policy(mdp, std::span<const int>(pi));
            }
            return vector_array(v);
          },
          py::arg("policy"),
          "V^pi exactly (Eq 2.8) of a deterministic policy (S actions) or a stochastic one (S x A "
          "probabilities).")
      .def(
          "shape_with_potential",
          [](const FiniteMdp& mdp, ArrayLikeArg phi) {
            const Array p = as_vector(phi, "phi", mdp.num_states);
            require_finite(p, "phi");
            return shape_with_potential(
                mdp, std::span<const double>(p.data(), static_cast<std::size_t>(p.size())));
          },
          py::arg("phi"), "M' = M + F with F = gamma Phi(s') - Phi(s) (Eq 3.1; Phi of absorbing states 0).")
      .def("_add_shaping", [](const FiniteMdp& mdp, ArrayLikeArg s, ArrayLikeArg a, ArrayLikeArg n,
                              ArrayLikeArg v) { return add_shaping(mdp, shaping_table(mdp, s, a, n, v)); })
      .def("_audit_shaping", [](const FiniteMdp& mdp, ArrayLikeArg s, ArrayLikeArg a, ArrayLikeArg n,
                                ArrayLikeArg v, double tolerance) {
        AuditOptions o;
        o.tolerance = tolerance;
        std::string error;
        if (!o.IsValid(&error)) throw py::value_error(error);
        const ShapingTable f = shaping_table(mdp, s, a, n, v);
        ReleaseGilInterruptibly release;
        return audit_shaping(mdp, f, o);
      });

  py::class_<SolveSummary>(m, "SolveSummary", "A finite-MDP solver's result: value, policy and bounds.")
      .def_property_readonly(
          "value", [](const SolveSummary& s) { return vector_array(s.value); },
          "V, one per state: the certified iterate (value iteration) or V^pi exactly (policy iteration).")
      .def_property_readonly(
          "policy",
          [](const SolveSummary& s) {
            py::array_t<std::int64_t> p(static_cast<py::ssize_t>(s.policy.size()));
            std::copy(s.policy.begin(), s.policy.end(), p.mutable_data());
            return p;
          },
          "The greedy deterministic policy: one action per state (0 at absorbing states).")
      .def_readonly("iterations", &SolveSummary::iterations,
                    "Sweeps (value iteration) or improvement steps (policy iteration).")
      .def_readonly("polish_iterations", &SolveSummary::polish_iterations,
                    "Policy-iteration steps after the sweeps (value iteration with gamma = 1).")
      .def_readonly("residual", &SolveSummary::residual, "max_s |(T V)(s) - V(s)| at the end.")
      .def_readonly("policy_loss_bound", &SolveSummary::policy_loss_bound,
                    "Certified max_s V*(s) - V^pi(s) of the returned policy (inf when not certified).")
      .def_readonly("value_error_bound", &SolveSummary::value_error_bound,
                    "Certified max_s |V(s) - V*(s)| of the returned value.")
      .def_property_readonly("converged", &SolveSummary::converged,
                             "Whether the solver converged (False: it stopped at max_iterations).")
      .def_readonly("message", &SolveSummary::message, "Why the solver stopped, in words.")
      .def("brief_report", &SolveSummary::BriefReport,
           "One line: termination, iterations, residual, policy-loss bound and time.");

  py::class_<PolicyChange>(m, "PolicyChange", R"doc(
Whether shaping changed what is optimal (ShapingAudit.policy_change): changes (some action optimal in M + F is
not optimal in M), states (where), loss_under_initial (sum over starts D(s) of V*_M(s) - V_M^pi'(s) for pi'
optimal in M + F) and max_loss (the largest such loss over states).)doc")
      .def_readonly("changes", &PolicyChange::changes,
                    "Whether some action optimal in M + F is not optimal in M.")
      .def_readonly("states", &PolicyChange::states, "The states where that happens.")
      .def_readonly("loss_under_initial", &PolicyChange::loss_under_initial,
                    "sum_s D(s) (V*_M(s) - V_M^pi'(s)) for pi' optimal in M + F: the expected loss from the "
                    "start.")
      .def_readonly("max_loss", &PolicyChange::max_loss,
                    "max_s (V*_M(s) - V_M^pi'(s)): the largest loss over states.");
  py::class_<ShapingAudit>(m, "ShapingAudit", R"doc(
The shaping audit: is F potential-based (least-squares Phi and residuals), and if not, the evidence of thesis
§3.A (an action dependence, a cycle with net shaping, a verified counterexample) and whether this MDP's
optimal policy changes under F.)doc")
      .def_readonly("potential_based", &ShapingAudit::potential_based,
                    "Whether F(s, a, s') = gamma Phi(s') - Phi(s) on every scope triple, within tolerance * "
                    "(1 + max |F|) (thesis §3.3, Theorem 1).")
      .def_property_readonly(
          "potential", [](const ShapingAudit& a) { return vector_array(a.potential); },
          "The least-squares Phi over the scope, one per state (0 at absorbing states).")
      .def_readonly("max_residual", &ShapingAudit::max_residual,
                    "max over the scope triples of |gamma Phi(s') - Phi(s) - F(s, a, s')|.")
      .def_readonly("rms_residual", &ShapingAudit::rms_residual,
                    "Root mean square of that residual over the scope triples.")
      .def_readonly("scope_size", &ShapingAudit::scope_size,
                    "Triples (s, a, s') judged: s non-absorbing, and P_sa(s') > 0 or the triple listed in F.")
      .def_property_readonly(
          "has_action_dependence", [](const ShapingAudit& a) { return a.action_dependence.has_value(); },
          "Whether a Lemma 4 witness was found: F(s, a, s') != F(s, a', s').")
      .def_property_readonly(
          "has_cycle", [](const ShapingAudit& a) { return a.cycle.has_value(); },
          "Whether a cycle of scope transitions with nonzero net shaping was found (searched only at "
          "gamma = 1).")
      .def_property_readonly(
          "counterexample_verified",
          [](const ShapingAudit& a) { return a.counterexample && a.counterexample->verified; },
          "Whether a counterexample MDP (Appendix 3.A) was built whose optimal action flips under F, checked "
          "by policy iteration.")
      .def_readonly("counterexample_note", &ShapingAudit::counterexample_note,
                    "Why no counterexample was built, when none was; else empty.")
      .def_readonly("policy_change", &ShapingAudit::policy_change,
                    "Whether this MDP's own optimal policy changes under F (a PolicyChange).")
      .def("brief_report", &ShapingAudit::BriefReport,
           "One line: potential-based or not, the residuals, why not, and whether the optimal policy "
           "changes.");
}

}  // namespace pegasus::python
