#include "pegasus/optimizers/exhaustive_search.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pegasus/core/error.hpp"

namespace pegasus {

using nlohmann::json;

bool ExhaustiveSearchOptions::IsValid(std::string* error) const {
  if (max_policies < 1) return RejectOption(error, "max_policies", ">= 1", static_cast<double>(max_policies));
  if (block_size < 1) return RejectOption(error, "block_size", ">= 1", static_cast<double>(block_size));
  return IsValidFor("exhaustive", error);
}

namespace {

// First value and number of values of each parameter's integer range.
struct IntegerRange {
  double first = 0.0;
  std::int64_t count = 0;
};

std::vector<IntegerRange> IntegerRanges(const ParameterSpec& spec) {
  std::vector<IntegerRange> ranges;
  for (const auto& p : spec.all()) {
    if (!p.integer)
      throw InputError(fmt::format("parameter {}: exhaustive search needs integer parameters", p.name));
    if (!std::isfinite(p.lower) || !std::isfinite(p.upper))
      throw InputError(fmt::format("parameter {}: exhaustive search needs finite bounds, got [{}, {}]",
                                   p.name, p.lower, p.upper));
    // At least one integer lies within: the spec holds a whole initial value there (ParameterSpec::add).
    const double first = std::ceil(p.lower);
    const double last = std::floor(p.upper);
    if (last - first >= 9.0e15)
      throw InputError(
          fmt::format("parameter {}: range [{}, {}] is too large to enumerate", p.name, first, last));
    ranges.push_back({first, static_cast<std::int64_t>(last - first) + 1});
  }
  return ranges;
}

std::int64_t CountPolicies(const std::vector<IntegerRange>& ranges, std::int64_t max_policies) {
  std::int64_t total = 1;
  for (const auto& range : ranges) {
    if (total > max_policies / range.count)
      throw InputError(fmt::format(
          "exhaustive search: the policy class has more than max_policies = {} members", max_policies));
    total *= range.count;
  }
  if (total > max_policies)
    throw InputError(
        fmt::format("exhaustive search: the policy class has {} members, more than max_policies = {}", total,
                    max_policies));
  return total;
}

// Writes the policy with enumeration index `index`; the last parameter varies fastest.
void Decode(const std::vector<IntegerRange>& ranges, std::int64_t index, Theta& theta) {
  for (std::size_t i = ranges.size(); i-- > 0;) {
    theta[i] = ranges[i].first + static_cast<double>(index % ranges[i].count);
    index /= ranges[i].count;
  }
}

// Steps theta to the next index in enumeration order (an odometer), avoiding a division per parameter.
void Advance(const std::vector<IntegerRange>& ranges, Theta& theta) {
  for (std::size_t i = ranges.size(); i-- > 0;) {
    if (theta[i] + 1.0 < ranges[i].first + static_cast<double>(ranges[i].count)) {
      theta[i] += 1.0;
      return;
    }
    theta[i] = ranges[i].first;
  }
}

}  // namespace

std::int64_t ExhaustiveSearchSize(const ParameterSpec& spec, std::int64_t max_policies) {
  return CountPolicies(IntegerRanges(spec), max_policies);
}

void ExhaustiveSearchTheta(const ParameterSpec& spec, std::int64_t index, Theta* theta) {
  const auto ranges = IntegerRanges(spec);
  const std::int64_t total = CountPolicies(ranges, std::numeric_limits<std::int64_t>::max());
  if (index < 0 || index >= total)
    throw InputError(fmt::format("exhaustive search: index {} outside [0, {})", index, total));
  theta->resize(spec.size());
  Decode(ranges, index, *theta);
}

void Solve(const ExhaustiveSearchOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("exhaustive search options: " + error);
  if (theta == nullptr || summary == nullptr)
    throw InputError("exhaustive search: theta and summary must be non-null");

  const ParameterSpec& spec = objective.parameters();
  const auto ranges = IntegerRanges(spec);
  const std::int64_t total = CountPolicies(ranges, options.max_policies);
  RunProgress run("exhaustive", spec, options.callbacks);

  std::int64_t next_index = 0;
  std::int64_t best_index = -1;
  std::vector<double> all_values;
  if (options.keep_all_values) all_values.reserve(static_cast<std::size_t>(total));
  if (options.resume_from) {
    const json& state = run.Resume(*options.resume_from);
    next_index = StateInteger(state, "next_index");
    best_index = StateInteger(state, "best_index");
    if (next_index < 0 || next_index > total || best_index >= next_index)
      throw InputError(fmt::format("checkpoint state.next_index: expected an index in [0, {}]", total));
    if (options.keep_all_values) {
      all_values = VectorFromJson(StateField(state, "all_values"), "state.all_values");
      if (static_cast<std::int64_t>(all_values.size()) != next_index)
        throw InputError("checkpoint state.all_values: expected one value per policy evaluated so far");
    }
  }

  const auto block_capacity =
      static_cast<std::size_t>(std::min(options.block_size, std::max<std::int64_t>(total, 1)));
  std::vector<Theta> block(block_capacity, Theta(spec.size()));
  std::vector<double> values(block_capacity);
  Theta cursor(spec.size());

  bool stopped_early = false;
  while (next_index < total) {
    const auto count =
        static_cast<std::size_t>(std::min<std::int64_t>(options.block_size, total - next_index));
    Decode(ranges, next_index, cursor);
    for (std::size_t k = 0; k < count; ++k) {
      std::copy(cursor.begin(), cursor.end(), block[k].begin());
      Advance(ranges, cursor);
    }
    objective.evaluate_batch(std::span<const Theta>(block.data(), count),
                             std::span<double>(values.data(), count));
    run.AddEvaluations(static_cast<std::int64_t>(count));
    // Scanning in index order with a strict comparison leaves ties with the lowest index.
    for (std::size_t k = 0; k < count; ++k)
      if (run.Offer(block[k], values[k])) best_index = next_index + static_cast<std::int64_t>(k);
    if (options.keep_all_values) all_values.insert(all_values.end(), values.begin(), values.begin() + count);
    next_index += static_cast<std::int64_t>(count);
    if (!run.EndIteration()) {
      stopped_early = true;
      break;
    }
    if (next_index < total && run.CheckpointDue(options.checkpoint_every)) {
      json state{{"next_index", next_index}, {"best_index", best_index}};
      if (options.keep_all_values) state["all_values"] = VectorToJson(all_values);
      options.on_checkpoint(run.Checkpoint(std::move(state)));
    }
  }

  if (stopped_early) {
    run.Finish(TerminationType::kUserRequested,
               fmt::format("an iteration callback asked to stop after {} of {} policies; the best has "
                           "enumeration index {}",
                           next_index, total, best_index),
               summary);
  } else {
    run.Finish(TerminationType::kSearchComplete,
               fmt::format("evaluated all {} policies; the best has enumeration index {}", total, best_index),
               summary);
  }
  summary->all_values = std::move(all_values);
  *theta = summary->best_theta;
}

}  // namespace pegasus
