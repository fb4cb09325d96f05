#pragma once
// What every optimizer's Options struct says about itself, so that the dispatcher (optimizer.hpp), the
// config section (runs/optimizer_config.hpp), the training layer's seeds (training.hpp) and the Python module
// are written once over the list of methods instead of once per method. A method's Options struct holds
//
//   static constexpr OptimizerMethodInfo kMethod{...};    // names, section, seed domains
//   template <class Visitor> static void VisitFields(Visitor& v);
//   std::int64_t IterationLimit() const;                  // what a progress bar counts to
//   bool IsValid(std::string* error) const;
//   (deriving from OptimizerRunOptions, run_progress.hpp: checkpointing and iteration callbacks)
//
// and a free `void Solve(const Options&, Objective&, Theta*, OptimizerSummary*)`. VisitFields lists the
// fields a user sets, each once, with its help and the per-field range of IsValid (IsValid keeps the
// cross-field rules). A visitor offers
//
//   integer(name, &Options::field, help, lo, hi = the type's max)   // std::int64_t or int fields
//   real(name, &Options::field, help, lo, hi, exclusive_lo = false) // double fields
//   internal(name, &Options::field, help)  // set by the library or a program, not by a config: seeds
//
// Adding a method: its header and source, and in optimizer.hpp its OptimizerOptions member and its entry in
// kOptimizerMethods (for Python's type checkers, also its class in python/pegasus/_pegasus.pyi).
#include <array>
#include <cstdint>
#include <limits>
#include <string_view>

namespace pegasus {

// A real field's `hi` when only finiteness bounds it: an infinite step or tolerance is never what was meant.
inline constexpr double kNoUpperLimit = std::numeric_limits<double>::infinity();

struct OptimizerMethodInfo {
  // The OptimizerOptions member and the config section that hold the options: "hill_climbing".
  std::string_view section;
  // The type's name in Python and in messages: "HillClimbingOptions".
  std::string_view type_name;
  // One line on the method, for the Python class and listings.
  std::string_view description;
  // The values of OptimizerOptions::method that run it (NLopt runs four algorithms); the unused are empty.
  std::array<std::string_view, 4> method_names{};
  // Of method_names, those that need finite bounds on every parameter (NLopt's global crs2 and esch).
  std::array<std::string_view, 4> need_finite_bounds{};
  // Searches whole-number parameters (a finite class such as a table's actions); every other method moves
  // theta by real steps.
  bool integer_parameters = false;
  // Domains of the seed the training layer derives for the method's `seed` field: the first stage's and a
  // refinement stage's (training.hpp). 0: the method draws no random numbers and has no seed.
  std::uint32_t seed_domain = 0;
  std::uint32_t refine_seed_domain = 0;

  constexpr bool runs(std::string_view method) const {
    for (std::string_view name : method_names)
      if (!name.empty() && name == method) return true;
    return false;
  }
  constexpr bool needs_finite_bounds(std::string_view method) const {
    for (std::string_view name : need_finite_bounds)
      if (!name.empty() && name == method) return true;
    return false;
  }
};

}  // namespace pegasus
