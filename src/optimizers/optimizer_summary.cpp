#include "pegasus/optimizers/optimizer_summary.hpp"

#include <fmt/format.h>

#include <bit>
#include <cstdint>

namespace pegasus {

std::string_view TerminationTypeName(TerminationType type) {
  switch (type) {
    case TerminationType::kConvergence:
      return "CONVERGENCE";
    case TerminationType::kMaxIterations:
      return "MAX_ITERATIONS";
    case TerminationType::kMaxEvaluations:
      return "MAX_EVALUATIONS";
    case TerminationType::kSearchComplete:
      return "SEARCH_COMPLETE";
    case TerminationType::kFailure:
      return "FAILURE";
    case TerminationType::kUserRequested:
      return "USER_REQUESTED";
  }
  return "UNKNOWN";
}

std::string OptimizerSummary::BriefReport() const {
  return fmt::format("{}: {}, {} iterations, {} evaluations, best U-hat {:.10g}, {:.3f} s", method,
                     TerminationTypeName(termination_type), iterations, evaluations, best_value,
                     wall_seconds);
}

std::string OptimizerSummary::FullReport() const {
  std::string report = fmt::format("Optimizer summary ({})\n", method);
  report += fmt::format("  termination       {}: {}\n", TerminationTypeName(termination_type), message);
  report += fmt::format("  iterations        {}\n", iterations);
  report += fmt::format("  evaluations       {}", evaluations);
  if (resumed) report += fmt::format(" (resumed; {} answered from the checkpoint log)", replayed_evaluations);
  report += "\n";
  report += fmt::format("  initial U-hat     {:.17g}\n", initial_value);
  report += fmt::format("  best U-hat        {:.17g}\n", best_value);
  if (final_step == final_step)
    report += fmt::format("  final step        {:.6g} (scaled units)\n", final_step);
  report += fmt::format("  wall time         {:.3f} s\n", wall_seconds);
  report += "  best theta\n";
  for (std::size_t i = 0; i < best_theta.size(); ++i) {
    const std::string name = i < parameter_names.size() ? parameter_names[i] : fmt::format("theta[{}]", i);
    report += fmt::format("    {:<20} {:.17g}\n", name, best_theta[i]);
  }
  return report;
}

namespace {

bool SameBits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b) || (a != a && b != b);
}

bool SameVector(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!SameBits(a[i], b[i])) return false;
  return true;
}

}  // namespace

bool SameOutcome(const OptimizerSummary& a, const OptimizerSummary& b, std::string* difference) {
  auto differ = [difference](std::string what) {
    if (difference) *difference = std::move(what);
    return false;
  };
  if (a.method != b.method) return differ(fmt::format("method: {} vs {}", a.method, b.method));
  if (a.termination_type != b.termination_type)
    return differ(fmt::format("termination: {} vs {}", TerminationTypeName(a.termination_type),
                              TerminationTypeName(b.termination_type)));
  if (a.message != b.message) return differ(fmt::format("message: \"{}\" vs \"{}\"", a.message, b.message));
  if (a.iterations != b.iterations)
    return differ(fmt::format("iterations: {} vs {}", a.iterations, b.iterations));
  if (a.evaluations != b.evaluations)
    return differ(fmt::format("evaluations: {} vs {}", a.evaluations, b.evaluations));
  if (!SameBits(a.best_value, b.best_value))
    return differ(fmt::format("best_value: {:.17g} vs {:.17g}", a.best_value, b.best_value));
  if (!SameVector(a.best_theta, b.best_theta)) return differ("best_theta differs");
  if (!SameBits(a.initial_value, b.initial_value))
    return differ(fmt::format("initial_value: {:.17g} vs {:.17g}", a.initial_value, b.initial_value));
  if (!SameBits(a.final_step, b.final_step))
    return differ(fmt::format("final_step: {:.17g} vs {:.17g}", a.final_step, b.final_step));
  if (a.history.size() != b.history.size())
    return differ(fmt::format("history length: {} vs {}", a.history.size(), b.history.size()));
  for (std::size_t k = 0; k < a.history.size(); ++k) {
    const auto& x = a.history[k];
    const auto& y = b.history[k];
    if (x.iteration != y.iteration || x.evaluations != y.evaluations || !SameBits(x.value, y.value))
      return differ(fmt::format("history row {} differs", k));
  }
  if (!SameVector(a.all_values, b.all_values)) return differ("all_values differ");
  return true;
}

}  // namespace pegasus
