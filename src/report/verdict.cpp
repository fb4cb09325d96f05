// Each command's verdict sentence, made from its summary.json alone (include/pegasus/report/verdict.hpp).
#include "pegasus/report/verdict.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "pegasus/sysid/identify.hpp"

namespace pegasus::report {

namespace {

using json = nlohmann::json;

// The number at a '/'-separated path of `j` (e.g. "pilot/rms_position_m", a JSON pointer without its first
// '/'), or nothing.
std::optional<double> number(const json& j, std::string_view path) {
  const json::json_pointer pointer("/" + std::string(path));
  if (!j.contains(pointer) || !j.at(pointer).is_number()) return std::nullopt;
  return j.at(pointer).get<double>();
}

std::string crashes_text(double crashes) {
  return crashes == 0 ? "no crash" : fmt::format("{:g} crash{}", crashes, crashes == 1 ? "" : "es");
}

// heli fly (and the pipeline's last stage): flights, crashes, and the RMS position error against the pilot's.
std::string flights_verdict(const json& s) {
  const auto flights = number(s, "flights"), crashes = number(s, "crashes");
  const auto rms = number(s, "rms_position_m");
  if (!flights || !crashes || !rms) return {};
  std::string text = fmt::format("{:g} flights, {}", *flights, crashes_text(*crashes));
  const auto pilot = number(s, "pilot/rms_position_m");
  if (!pilot || *pilot <= 0) return text + fmt::format("; RMS distance from the set point {:.3g} m", *rms);
  const double change = 1 - *rms / *pilot;
  text += fmt::format(
      "; {:.0f}% {} the set point than the scripted pilot (RMS position {:.3g} m against {:.3g} m",
      std::abs(change) * 100, change >= 0 ? "closer to" : "farther from", *rms, *pilot);
  if (const auto pilot_crashes = number(s, "pilot/crashes"); pilot_crashes && *pilot_crashes != *crashes)
    text += fmt::format("; the pilot: {}", crashes_text(*pilot_crashes));
  return text + ")";
}

std::string uhat_text(const json& s, std::string_view initial_key, std::string_view final_key) {
  const auto initial = number(s, initial_key), best = number(s, final_key);
  if (!initial || !best) return {};
  return fmt::format("U-hat {:.6g} -> {:.6g}", *initial, *best);
}

std::string hover_verdict(const json& s) {
  std::string text = uhat_text(s, "initial_uhat", "final_uhat");
  if (text.empty()) return {};
  text = "hover training: " + text;
  if (const auto iterations = number(s, "iterations"), evaluations = number(s, "evaluations");
      iterations && evaluations)
    text += fmt::format(" in {:g} iterations ({:g} evaluations)", *iterations, *evaluations);
  const auto crashed = number(s, "starting_policy/crashed_scenarios");
  const auto scenarios = number(s, "starting_policy/scenarios");
  if (crashed && scenarios && *crashed > 0)
    text += fmt::format("; the starting policy crashed in {:g} of {:g} scenarios", *crashed, *scenarios);
  return text;
}

// heli identify: whether the 2-sd bands of the noise check miss 3-7% of the hold-out steps, the worst
// output named with the horizons where its bands are too narrow.
std::string identify_verdict(const json& s) {
  const auto by_horizon = s.find("outside_2sigma_by_horizon");
  if (by_horizon == s.end() || !by_horizon->is_object() || by_horizon->empty()) return {};
  struct Miss {
    std::string output;
    std::vector<std::string> horizons;
    double worst = 0;
  };
  std::map<std::string, Miss> narrow;
  std::size_t cells = 0, honest = 0;
  for (const auto& [horizon, outputs] : by_horizon->items()) {
    if (!outputs.is_object()) continue;
    for (const auto& [output, outside] : outputs.items()) {
      if (!outside.is_number()) continue;
      ++cells;
      const double f = outside.get<double>();
      if (sysid::honest_misses(f)) {
        ++honest;
      } else if (f > sysid::kHonestMissHigh) {
        Miss& m = narrow[output];
        m.output = output;
        m.horizons.push_back(horizon);
        m.worst = std::max(m.worst, f);
      }
    }
  }
  if (cells == 0) return {};
  // The binomial test of each cell against 3-7% (sysid::cells_beyond_chance), where the summary has it.
  if (const auto passes = s.find("noise_check_passes"); passes != s.end() && passes->is_boolean()) {
    if (passes->get<bool>())
      return fmt::format(
          "the noise bands pass the hold-out check: {} of {} cells within 3-7% outside 2 sd, and the "
          "others within what chance gives on the hold-out steps",
          honest, cells);
    const auto beyond = number(s, "noise_check_cells_beyond_chance");
    if (narrow.empty() && beyond)
      return fmt::format(
          "the noise bands are too wide: {:g} of {} cells miss fewer than 3% of the hold-out steps beyond "
          "what chance gives (the learned model's noise is larger than the aircraft's)",
          *beyond, cells);
  }
  if (narrow.empty())
    return fmt::format(
        "the noise bands hold or are wide: {} of {} cells of the hold-out check within 3-7% "
        "outside 2 sd, none above",
        honest, cells);
  const Miss* worst = nullptr;
  for (const auto& [name, m] : narrow)
    if (!worst || m.worst > worst->worst) worst = &m;
  std::vector<double> seconds;
  for (const auto& h : worst->horizons) seconds.push_back(std::stod(h));
  const auto [lo, hi] = std::minmax_element(seconds.begin(), seconds.end());
  const std::string at = *lo == *hi ? fmt::format("{:g} s", *lo) : fmt::format("{:g}-{:g} s", *lo, *hi);
  std::string text = fmt::format(
      "the noise bands are too narrow for {} at {}: up to {:.0f}% outside 2 sd "
      "(3-7% expected)",
      worst->output, at, worst->worst * 100);
  if (narrow.size() > 1)
    text += fmt::format(", and for {} more output{}", narrow.size() - 1, narrow.size() == 2 ? "" : "s");
  const bool measured = s.value("noise", "") == "ar1+measurement";
  const bool calibrated = s.contains("noise_scale");
  if (!measured || !calibrated)
    text += fmt::format("; see {}", !measured && !calibrated ? "--noise ar1+measurement --calibrate-noise"
                                    : !measured              ? "--noise ar1+measurement"
                                                             : "--calibrate-noise");
  return text;
}

std::string pilot_verdict(const json& s) {
  const auto seconds = number(s, "seconds");
  if (!seconds) return {};
  if (s.value("crashed", false))
    return fmt::format("the pilot crashed after {:.3g} s ({})", number(s, "crash_time").value_or(0),
                       s.value("crash_reason", "unknown reason"));
  return fmt::format("the pilot flew {:g} s without a crash", *seconds);
}

std::string pipeline_verdict(const json& s) {
  const std::string fly = flights_verdict(s);
  if (fly.empty()) return {};
  const std::string hover = uhat_text(s, "hover/initial_uhat", "hover/final_uhat");
  return hover.empty() ? fly : fly + "; hover training " + hover;
}

std::string horizon_verdict(const json& s) {
  const auto h = number(s, "horizon");
  return h ? fmt::format("a horizon of {:g} steps", *h) : std::string();
}

std::string mujoco_train_verdict(const json& s) {
  std::string text = uhat_text(s, "initial_uhat", "final_uhat");
  if (text.empty()) return s.value("uhat_finite", true) ? std::string() : "no result: U-hat is not finite";
  if (const auto rate = number(s, "evaluation/success_rate"))
    text += fmt::format("; the policy succeeds in {:.0f}% of the evaluation episodes", *rate * 100);
  if (const auto mean = number(s, "evaluation/mean_return"))
    text += fmt::format(" (mean return {:.4g})", *mean);
  return text;
}

std::string mujoco_rollout_verdict(const json& s) {
  const auto episodes = number(s, "evaluation/episodes"), mean = number(s, "evaluation/mean_return");
  if (!episodes || !mean) return {};
  std::string text = fmt::format("{:g} episodes, mean return {:.4g}", *episodes, *mean);
  if (const auto rate = number(s, "evaluation/success_rate"))
    text += fmt::format(", {:.0f}% successful", *rate * 100);
  return text;
}

// bicycle ride (and train's "rides", experiment's policies): how many rides reached the goal, how far.
std::string rides_verdict(const json& s) {
  const auto rides = number(s, "rides"), reached = number(s, "reached"), falls = number(s, "falls");
  if (!rides || !reached || !falls) return {};
  std::string text = fmt::format("{:g} of {:g} rides reached the goal, {:g} fell", *reached, *rides, *falls);
  if (const auto median = number(s, "median_distance_km"))
    text += fmt::format("; median distance to it {:.3g} km", *median);
  return text;
}

std::string bicycle_train_verdict(const json& s) {
  std::string text = uhat_text(s, "initial_uhat", "final_uhat");
  if (text.empty()) return {};
  if (const auto rides = s.find("rides"); rides != s.end() && rides->is_object()) {
    if (const std::string after = rides_verdict(*rides); !after.empty()) text += "; " + after;
  }
  return text;
}

std::string bicycle_experiment_verdict(const json& s) {
  const auto policies = s.find("policies");
  if (policies == s.end() || !policies->is_array() || policies->empty()) return {};
  double reached = 0, falls = 0;
  for (const json& p : *policies) {
    reached += number(p, "reached").value_or(0);
    falls += number(p, "falls").value_or(0);
  }
  const double rides = number(s, "rides").value_or(0) * static_cast<double>(policies->size());
  std::string text = fmt::format("{} policies: {:g} of {:g} rides reached the goal, {:g} fell",
                                 policies->size(), reached, rides, falls);
  if (const auto median = number(s, "median_of_medians_km"))
    text += fmt::format("; median of the policies' median distances {:.3g} km", *median);
  return text;
}

std::string bicycle_variance_verdict(const json& s) {
  const auto sd = s.find("uhat_std");
  if (sd == s.end() || !sd->is_object() || sd->empty()) return {};
  std::string parts;
  for (const auto& [variant, value] : sd->items())
    if (value.is_number())
      parts += fmt::format("{}{} {:.3g}", parts.empty() ? "" : ", ", variant, value.get<double>());
  return parts.empty() ? std::string() : "sd of U-hat over scenario sets: " + parts;
}

std::string shaping_audit_verdict(const json& s) {
  if (!s.contains("potential_based") || !s["potential_based"].is_boolean()) return {};
  if (s["potential_based"].get<bool>())
    return fmt::format("F is potential-based (largest residual {:.3g}): it keeps the optimal policy",
                       number(s, "max_residual").value_or(0));
  return s.contains("counterexample")
             ? "F is not potential-based: a counterexample MDP whose optimal policy it "
               "changes is in the report"
             : "F is not potential-based";
}

std::string progress_bonus_verdict(const json& s) {
  const auto bonus = s.find("progress_bonus"), potential = s.find("potential");
  if (bonus == s.end() || potential == s.end() || !bonus->is_object() || !potential->is_object()) return {};
  const auto reaches = [](const json& o) { return o.value("reaches_goal", false); };
  return fmt::format(
      "the greedy policy learned with the progress bonus {}; with its potential-based version it {}",
      reaches(*bonus) ? "reaches the goal" : "cycles and never reaches the goal",
      reaches(*potential) ? "reaches the goal" : "does not reach it either");
}

std::string maneuver_verdict(const json& s) {
  const auto flights = number(s, "flights"), crashes = number(s, "crashes");
  const auto rms = number(s, "rms_path_deviation_m");
  if (!flights || !crashes || !rms) return {};
  return fmt::format("{}: {:g} flights, {}; RMS deviation from the path {:.3g} m",
                     s.value("maneuver", "manoeuvre"), *flights, crashes_text(*crashes), *rms);
}

std::string pendulum_verdict(const json& s) {
  const auto mean = number(s, "mean_return_100"), bar = number(s, "bar");
  if (!mean || !bar) return {};
  std::string text = fmt::format("mean return over 100 episodes {:.4g}, {} the bar of {:.4g}", *mean,
                                 *mean >= *bar ? "at or above" : "below", *bar);
  if (const auto evaluations = number(s, "evaluations_to_bar"))
    text += fmt::format(" (reached after {:g} U-hat evaluations)", *evaluations);
  return text;
}

// shaping gridworld / flags: for each potential, the trials until the learner's steps come within 25% of the
// optimum.
std::string shaping_learning_verdict(const json& s) {
  const auto curves = s.find("curves");
  if (curves == s.end() || !curves->is_array() || curves->empty()) return {};
  std::string parts;
  for (const json& c : *curves) {
    if (!c.is_object() || !c.contains("potential")) continue;
    const json& t = c.value("trials_to_within_25pct", json());
    parts += fmt::format("{}{} {}", parts.empty() ? "" : ", ", c["potential"].get<std::string>(),
                         t.is_number() ? fmt::format("{}", t.get<double>()) : std::string("never"));
  }
  return parts.empty() ? std::string() : "trials until within 25% of the optimal steps: " + parts;
}

// heli maneuver-pilot: the pilot's log is identification data for the manoeuvres; it is only that when it
// flew them all (a crash ends the log, and the run, there).
std::string maneuver_pilot_verdict(const json& s) {
  const auto seconds = number(s, "seconds"), rows = number(s, "rows");
  if (!seconds || !rows) return {};
  if (s.value("crashed", false))
    return fmt::format(
        "the pilot crashed after {:.3g} s ({}): the log stops before the manoeuvres it did not fly; "
        "try a smaller --sweep-scale or --gust-sigma",
        number(s, "crash_time").value_or(0), s.value("crash_reason", "unknown reason"));
  return fmt::format(
      "the pilot flew {:.4g} s of hover, sweeps and manoeuvres without a crash: {:g} rows of identification "
      "data that cover the manoeuvres",
      *seconds, *rows);
}

// pomdp-gridworld (Fig 4.5b): how close the policy PEGASUS picks comes to the best in the class as m grows,
// and how it compares with naive Monte Carlo's pick at the largest m both ran.
std::string pomdp_gridworld_verdict(const json& s) {
  const auto best = number(s, "best_in_class_value");
  const auto results = s.find("results");
  if (!best || results == s.end() || !results->is_array()) return {};
  // m -> exact value of the chosen policy, for one (model, estimator), in increasing m.
  const auto curve = [&](std::string_view estimator) {
    std::map<double, double> values;
    for (const json& r : *results)
      if (r.value("model", "") == "normal" && r.value("estimator", "") == estimator)
        if (const auto m = number(r, "m"), v = number(r, "mean_true_value"); m && v) values[*m] = *v;
    return values;
  };
  const std::map<double, double> pegasus = curve("pegasus"), montecarlo = curve("montecarlo");
  if (pegasus.empty()) return {};
  const auto& [m_first, v_first] = *pegasus.begin();
  const auto& [m_last, v_last] = *pegasus.rbegin();
  std::string text = fmt::format(
      "the policy PEGASUS picks with m = {:g} scenarios is worth {:.4g} (exact), {:.3g} below the best in "
      "the class ({:.4g})",
      m_last, v_last, *best - v_last, *best);
  if (m_first != m_last) text += fmt::format("; with m = {:g}, {:.3g} below", m_first, *best - v_first);
  for (auto it = montecarlo.rbegin(); it != montecarlo.rend(); ++it) {
    const auto p = pegasus.find(it->first);
    if (p == pegasus.end()) continue;
    const double difference = p->second - it->second;
    text += fmt::format("; at m = {:g} naive Monte Carlo's pick is worth {:.4g}, {:.3g} {} PEGASUS's",
                        it->first, it->second, std::abs(difference), difference >= 0 ? "below" : "above");
    break;
  }
  return text;
}

// log import: what was imported, what is wrong with the file, and whether the model identified on its first
// part predicts the rest better than holding the velocity (the baseline any useful model must beat).
std::string log_import_verdict(const json& s) {
  const auto seconds = number(s, "seconds"), rate = number(s, "rate_hz"), dropouts = number(s, "dropouts");
  if (!seconds || !rate || !dropouts) return {};
  std::string text = fmt::format("imported {:.3g} s at {:g} Hz", *seconds, *rate);
  if (s.contains("vehicle") && s["vehicle"].is_string()) text += " for " + s["vehicle"].get<std::string>();
  text += *dropouts == 0 ? ", no dropout"
                         : fmt::format(", {:g} dropout{} ({:.3g} ms)", *dropouts, *dropouts == 1 ? "" : "s",
                                       number(s, "dropout_total_ms").value_or(0));
  if (const auto at = number(s, "truncated_at_byte")) text += fmt::format(", the file cut at byte {:g}", *at);
  if (const auto constant = s.find("constant_controls");
      constant != s.end() && constant->is_array() && !constant->empty())
    text += fmt::format(", {} control{} never moved", constant->size(), constant->size() == 1 ? "" : "s");
  const json::json_pointer rmse_at("/prediction/rmse");
  if (!s.contains(rmse_at)) return text;
  const json& rmse = s.at(rmse_at);
  const json identified = rmse.value("identified", json::object());
  const json baseline = rmse.value("constant_velocity", json::object());
  // The longest horizon the identified model reached, compared variable by variable with the baseline.
  std::string horizon;
  std::size_t better = 0, variables = 0;
  for (const auto& [h, by_variable] : identified.items()) {
    if (!baseline.contains(h) || !by_variable.is_object()) continue;
    if (!horizon.empty() && std::stod(h) < std::stod(horizon)) continue;
    horizon = h;
    better = variables = 0;
    for (const auto& [variable, value] : by_variable.items()) {
      if (!value.is_number() || !baseline[h].contains(variable) || !baseline[h][variable].is_number())
        continue;
      ++variables;
      if (value.get<double>() < baseline[h][variable].get<double>()) ++better;
    }
  }
  if (variables == 0) return text + "; the identified model's fit turned singular before the first horizon";
  text += fmt::format(
      "; {} s ahead on the hold-out part the identified model beats a constant-velocity guess on {} of {} "
      "variables",
      horizon, better, variables);
  if (2 * better < variables) text += ": this log does not identify the aircraft's dynamics";
  if (const auto horizons = s.at("prediction").value("horizons_s", json::array());
      horizons.is_array() && identified.size() < horizons.size())
    text +=
        fmt::format(" (its fit turned singular before the {} longer horizon{})",
                    horizons.size() - identified.size(), horizons.size() - identified.size() == 1 ? "" : "s");
  return text;
}

// export: the C function written, its size, and the state a flight computer must keep for it.
std::string export_verdict(const json& s) {
  const auto observations = number(s, "observation_size"), actions = number(s, "action_size");
  if (!observations || !actions || !s.contains("act_function") || !s.contains("class")) return {};
  std::string text = fmt::format(
      "C99 code of the {} policy: {} maps {:g} observations to {:g} actions ({}, {}); compiled with "
      "-ffp-contract=off it gives the C++ policy's bits",
      s.value("class", ""), s.value("act_function", ""), *observations, *actions, s.value("header_file", ""),
      s.value("source_file", ""));
  text += s.contains("memory_type") ? fmt::format("; it keeps state in {}: call {} before each flight",
                                                  s.value("memory_type", ""), s.value("reset_function", ""))
                                    : "; it keeps no state";
  if (s.contains("vehicle_act_function") && s.contains("vehicle_observation_names"))
    text += fmt::format("; {} takes the time and {}'s own state fields ({} numbers)",
                        s.value("vehicle_act_function", ""), s.value("vehicle", "the vehicle"),
                        s["vehicle_observation_names"].size());
  return text;
}

const std::map<std::string, std::function<std::string(const json&)>, std::less<>>& verdicts() {
  static const std::map<std::string, std::function<std::string(const json&)>, std::less<>> table = {
      {"bicycle experiment", bicycle_experiment_verdict},
      {"bicycle ride", rides_verdict},
      {"bicycle train", bicycle_train_verdict},
      {"bicycle variance", bicycle_variance_verdict},
      {"heli fly", flights_verdict},
      {"heli hover", hover_verdict},
      {"heli identify", identify_verdict},
      {"heli maneuver", maneuver_verdict},
      {"heli maneuver-pilot", maneuver_pilot_verdict},
      {"heli pilot", pilot_verdict},
      {"heli pipeline", pipeline_verdict},
      // The vehicle commands without the heli prefix (pegasus fly --vehicle V.toml, ...) say the same.
      {"fly", flights_verdict},
      {"hover", hover_verdict},
      {"identify", identify_verdict},
      {"maneuver", maneuver_verdict},
      {"maneuver-pilot", maneuver_pilot_verdict},
      {"pilot", pilot_verdict},
      {"pipeline", pipeline_verdict},
      {"export", export_verdict},
      {"horizon", horizon_verdict},
      {"log import", log_import_verdict},
      {"mujoco rollout", mujoco_rollout_verdict},
      {"mujoco train", mujoco_train_verdict},
      {"pendulum train", pendulum_verdict},
      {"pomdp-gridworld", pomdp_gridworld_verdict},
      {"shaping audit", shaping_audit_verdict},
      {"shaping flags", shaping_learning_verdict},
      {"shaping gridworld", shaping_learning_verdict},
      {"shaping progress-bonus", progress_bonus_verdict},
  };
  return table;
}

}  // namespace

std::string verdict(std::string_view command, const json& summary) {
  const auto& table = verdicts();
  const auto it = table.find(command);
  if (it == table.end() || !summary.is_object()) return {};
  return it->second(summary);
}

bool has_verdict(std::string_view command) { return verdicts().contains(command); }

}  // namespace pegasus::report
