#include "pegasus/shaping/runs/shaping_audit_run.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/mdp/mdp_json.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/shaping/audit.hpp"

namespace pegasus {

namespace {

std::string actions_text(std::uint64_t mask) {
  std::string out;
  for (int a = 0; a < 64; ++a)
    if (mask >> a & 1U) out += (out.empty() ? "" : ", ") + std::to_string(a);
  return "{" + out + "}";
}

std::vector<int> actions_of(std::uint64_t mask) {
  std::vector<int> out;
  for (int a = 0; a < 64; ++a)
    if (mask >> a & 1U) out.push_back(a);
  return out;
}

nlohmann::json summary_json(const ShapingAudit& a, const FiniteMdp& m, const std::string& mdp_file,
                            const std::string& shaping_file) {
  nlohmann::json j = {{"mdp", mdp_file},
                      {"shaping", shaping_file},
                      {"num_states", m.num_states},
                      {"num_actions", m.num_actions},
                      {"gamma", m.gamma},
                      {"potential_based", a.potential_based},
                      {"max_residual", a.max_residual},
                      {"rms_residual", a.rms_residual},
                      {"tolerance", a.tolerance_used},
                      {"scope_size", a.scope_size},
                      {"potential", a.potential}};
  if (a.action_dependence) {
    const auto& d = *a.action_dependence;
    j["action_dependence"] = {
        {"state", d.state},           {"next_state", d.next_state}, {"action_high", d.action_high},
        {"action_low", d.action_low}, {"f_high", d.f_high},         {"f_low", d.f_low}};
  }
  if (a.cycle)
    j["cycle"] = {
        {"states", a.cycle->states}, {"actions", a.cycle->actions}, {"net_shaping", a.cycle->net_shaping}};
  if (a.counterexample) {
    const auto& cx = *a.counterexample;
    j["counterexample"] = {{"decision_state", cx.decision_state},
                           {"optimal_actions", actions_of(cx.optimal_actions)},
                           {"shaped_optimal_actions", actions_of(cx.shaped_optimal_actions)},
                           {"delta", cx.delta},
                           {"verified", cx.verified},
                           {"uses_only_scope", cx.uses_only_scope},
                           {"description", cx.description},
                           {"mdp_file", "counterexample.json"},
                           {"shaped_mdp_file", "counterexample_shaped.json"}};
  } else if (!a.potential_based) {
    j["counterexample"] = nullptr;
    j["counterexample_note"] = a.counterexample_note;
  }
  j["policy_change"] = {{"changes", a.policy_change.changes},
                        {"states", a.policy_change.states},
                        {"loss_under_initial", a.policy_change.loss_under_initial},
                        {"max_loss", a.policy_change.max_loss}};
  return j;
}

void print_report(std::ostream& out, const ShapingAudit& a, const FiniteMdp& m, int print_limit) {
  if (a.potential_based) {
    out << fmt::format(
        "verdict: F is potential-based: F(s, a, s') = gamma Phi(s') - Phi(s) on all {} transitions in "
        "scope (max residual {:.3g}, rms {:.3g}, tolerance {:.3g})\n",
        a.scope_size, a.max_residual, a.rms_residual, a.tolerance_used);
    out << "Phi (least squares over the transitions; 0 at absorbing states):\n";
    const int shown = std::min(m.num_states, print_limit);
    for (int s = 0; s < shown; ++s)
      out << fmt::format("  {:>6}  {:.10g}\n", s, a.potential[static_cast<std::size_t>(s)]);
    if (shown < m.num_states)
      out << fmt::format("  ... ({} more states; all of them in potential.csv with --out)\n",
                         m.num_states - shown);
  } else {
    out << fmt::format(
        "verdict: F is NOT potential-based: no Phi fits (least-squares residual max {:.6g}, rms {:.3g}, "
        "tolerance {:.3g}, {} transitions in scope)\n",
        a.max_residual, a.rms_residual, a.tolerance_used, a.scope_size);
    if (a.action_dependence) {
      const auto& d = *a.action_dependence;
      out << fmt::format(
          "witness (Lemma 4): F depends on the action: F({}, {}, {}) = {:.10g} but F({}, {}, {}) = {:.10g}\n",
          d.state, d.action_high, d.next_state, d.f_high, d.state, d.action_low, d.next_state, d.f_low);
    }
    if (a.cycle) {
      std::string path;
      const auto& c = *a.cycle;
      for (std::size_t i = 0; i < c.states.size(); ++i)
        path += fmt::format("{} -[a{}]-> ", c.states[i], c.actions[i]);
      path += std::to_string(c.states.front());
      out << fmt::format(
          "witness (cycle): {} collects net shaping {:+.10g} per lap; a potential-based F sums to 0 "
          "around every cycle when gamma = 1\n",
          path, c.net_shaping);
    }
    if (!a.action_dependence && !a.cycle)
      out << "witness: the transitions in scope admit no potential (the residual above)\n";
    if (a.counterexample) {
      const auto& cx = *a.counterexample;
      out << fmt::format("counterexample: {}\n", cx.description);
      out << fmt::format("  at state {} the optimal actions are {} in M and {} in M + F: {}\n",
                         cx.decision_state, actions_text(cx.optimal_actions),
                         actions_text(cx.shaped_optimal_actions),
                         cx.verified ? "verified by solving both (no optimal policy of M + F is optimal in M)"
                                     : "NOT verified");
      if (!cx.uses_only_scope)
        out << "  (the counterexample uses transitions the given MDP does not have; F is extended to them as "
               "documented in shaping/audit.hpp)\n";
    } else {
      out << fmt::format("counterexample: not built ({})\n", a.counterexample_note);
    }
  }
  const auto& pc = a.policy_change;
  if (pc.changes) {
    std::string states;
    for (std::size_t i = 0; i < pc.states.size() && i < 20; ++i)
      states += (i ? ", " : "") + std::to_string(pc.states[i]);
    if (pc.states.size() > 20) states += fmt::format(", ... ({} states)", pc.states.size());
    out << fmt::format(
        "given MDP: its optimal policy CHANGES under F at states {}; the optimal policy of M + F loses "
        "{:.6g} in M from the initial distribution (at most {:.6g} from any state)\n",
        states, pc.loss_under_initial, pc.max_loss);
  } else {
    out << "given MDP: its optimal policy does not change under F (M and M + F solved by policy iteration)\n";
  }
}

}  // namespace

bool run_shaping_audit(const ShapingAuditRunOptions& o, std::ostream& out, const RunDirectory* run_dir) {
  const std::string& mdp_file = o.mdp_file;
  const std::string& shaping_file = o.shaping_file;
  if (mdp_file.empty()) throw InputError("--mdp: expected a pegasus-mdp JSON file");
  if (shaping_file.empty()) throw InputError("--shaping: expected a pegasus-shaping JSON file");
  const FiniteMdp m = load_mdp(mdp_file);
  const ShapingTable f = load_shaping(shaping_file);
  if (f.num_states() != m.num_states || f.num_actions() != m.num_actions)
    throw InputError(fmt::format("{}: num_states/num_actions: the shaping table is {} x {} but {} is {} x {}",
                                 shaping_file, f.num_states(), f.num_actions(), mdp_file, m.num_states,
                                 m.num_actions));
  AuditOptions options;
  options.tolerance = o.tolerance;
  const ShapingAudit audit = audit_shaping(m, f, options);

  out << fmt::format("MDP {}: {} states, {} actions, gamma {}; shaping {}: {} listed transitions\n", mdp_file,
                     m.num_states, m.num_actions, m.gamma, shaping_file, f.entries().size());
  print_report(out, audit, m, o.print_limit);
  if (run_dir == nullptr) return audit.potential_based;
  const RunDirectory& dir = *run_dir;
  dir.write_json("summary.json", summary_json(audit, m, mdp_file, shaping_file));
  CsvWriter phi({"state", "phi"});
  for (int s = 0; s < m.num_states; ++s)
    phi.add_row({std::int64_t{s}, audit.potential[static_cast<std::size_t>(s)]});
  dir.write_csv("potential.csv", phi);
  dir.add_charts(ChartSection{
      .id = "potential",
      .title = "Recovered potential",
      .intro = "Phi found by least squares over the transitions, 0 at absorbing states (potential.csv).",
      .charts = {{.kind = ChartKind::kBar,
                  .title = "Potential Phi by state",
                  .x = {"state"},
                  .y = {"Phi"},
                  .traces = {{.file = "potential.csv", .x = "state", .y = "phi"}}}}});
  if (audit.counterexample) {
    dir.write_json("counterexample.json", mdp_to_json(audit.counterexample->mdp));
    dir.write_json("counterexample_shaped.json", mdp_to_json(audit.counterexample->shaped));
  }
  return audit.potential_based;
}

}  // namespace pegasus
