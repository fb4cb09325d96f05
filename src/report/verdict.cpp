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

// The number at a '/'-separated path of `j` (e.g. "pilot/rms_position_m"), or nothing.
std::optional<double> number(const json& j, std::string_view path) {
  const json* at = &j;
  for (std::size_t start = 0; start <= path.size();) {
    const std::size_t end = std::min(path.find('/', start), path.size());
    const std::string key(path.substr(start, end - start));
    if (!at->is_object() || !at->contains(key)) return std::nullopt;
    at = &(*at)[key];
    start = end + 1;
  }
  if (!at->is_number()) return std::nullopt;
  return at->get<double>();
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

const std::map<std::string, std::function<std::string(const json&)>, std::less<>>& verdicts() {
  static const std::map<std::string, std::function<std::string(const json&)>, std::less<>> table = {
      {"heli fly", flights_verdict},          {"heli hover", hover_verdict},
      {"heli identify", identify_verdict},    {"heli pilot", pilot_verdict},
      {"heli pipeline", pipeline_verdict},    {"horizon", horizon_verdict},
      {"mujoco train", mujoco_train_verdict}, {"mujoco rollout", mujoco_rollout_verdict},
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

}  // namespace pegasus::report
