#pragma once
// Exhaustive search over a finite policy class (§4.6: the 4^8 gridworld policies were all tried on the m
// scenarios and the best kept).
//
// Every parameter must be integer-valued with finite bounds; parameter i takes the integers
// ceil(lower_i) .. floor(upper_i). Policies are enumerated in lexicographic order with the LAST parameter
// varying fastest (nested loops, first parameter outermost); a policy's enumeration index is its position
// in that order. Policies go to the objective in blocks through evaluate_batch, so the objective can
// parallelise across them. The result is the argmax of U-hat, ties going to the lowest index.
//
// An iteration is one block. Checkpoint state: {"next_index", "best_index"} plus "all_values" (those
// evaluated so far) when keep_all_values is set.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pegasus/optimizers/objective.hpp"
#include "pegasus/optimizers/optimizer_method.hpp"
#include "pegasus/optimizers/optimizer_summary.hpp"
#include "pegasus/optimizers/run_progress.hpp"

namespace pegasus {

struct ExhaustiveSearchOptions : OptimizerRunOptions {
  // Refuse a policy class with more members than this. >= 1.
  std::int64_t max_policies = 10'000'000;
  // Policies handed to one evaluate_batch call. Larger blocks give the objective more parallel work;
  // smaller blocks checkpoint more finely. >= 1.
  std::int64_t block_size = 4096;
  // Keep U-hat of every policy in OptimizerSummary::all_values (in enumeration order), e.g. for
  // experiments that compare the chosen policy with the whole class. Costs 8 bytes per policy, and the
  // values so far are written into every checkpoint.
  bool keep_all_values = false;

  // False, with "field: expected ..., got ..." in *error, when a field is out of range.
  bool IsValid(std::string* error) const;
  // One iteration is one block of policies.
  std::int64_t IterationLimit() const {
    return max_policies / block_size +
           (max_policies % block_size != 0 ? 1 : 0);  // no overflow near the limit
  }

  static constexpr OptimizerMethodInfo kMethod{
      .section = "exhaustive",
      .type_name = "ExhaustiveSearchOptions",
      .description = "Enumerates every policy of a class of whole-number parameters.",
      .method_names = {"exhaustive"},
      .integer_parameters = true};
  template <class Visitor>
  static void VisitFields(Visitor& v) {
    using O = ExhaustiveSearchOptions;
    v.integer("max_policies", &O::max_policies, "exhaustive search: refuse a larger policy class", 1);
    v.integer("block_size", &O::block_size, "exhaustive search: policies per parallel batch", 1);
    v.internal("keep_all_values", &O::keep_all_values,
               "Keep every policy's U-hat in OptimizerSummary.all_values (8 bytes per policy).");
  }
};

// Number of policies in the class described by spec. Throws InputError, naming the parameter, when one
// is not integer, has an infinite bound or an empty range, or when the count exceeds max_policies.
std::int64_t ExhaustiveSearchSize(const ParameterSpec& spec, std::int64_t max_policies);

// The policy with enumeration index `index` (0 <= index < ExhaustiveSearchSize) into *theta.
void ExhaustiveSearchTheta(const ParameterSpec& spec, std::int64_t index, Theta* theta);

// Evaluates every policy of the objective's class. The starting *theta is ignored (it may be empty); on
// return it holds the best policy. Throws InputError for invalid options, a class that cannot be
// enumerated, or a foreign checkpoint.
void Solve(const ExhaustiveSearchOptions& options, Objective& objective, Theta* theta,
           OptimizerSummary* summary);

}  // namespace pegasus
