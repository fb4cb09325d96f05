#include "pegasus/optimizers/optimizer.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstddef>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {

// The number of members of an aggregate: the most initializers T{...} takes (each an AnyMember, which
// converts to any member's type; declared only, for the unevaluated check).
struct AnyMember {
  template <class T>
  operator T&() const&&;  // NOLINT(google-explicit-constructor): converting to every member is its purpose
};
template <class T, std::size_t... I>
constexpr bool BraceInitializableWith(std::index_sequence<I...> /*initializers*/) {
  return requires { T{(static_cast<void>(I), AnyMember{})...}; };
}
template <class T, std::size_t N = 0>
constexpr std::size_t AggregateMemberCount() {
  if constexpr (BraceInitializableWith<T>(std::make_index_sequence<N + 1>{})) {
    return AggregateMemberCount<T, N + 1>();
  } else {
    return N;
  }
}
// A method's options added to OptimizerOptions but not to kOptimizerMethods would compile and be invisible
// to the dispatcher, every command's config, the seeds and Python: `method` and one member per entry.
static_assert(AggregateMemberCount<OptimizerOptions>() == 1 + std::tuple_size_v<decltype(kOptimizerMethods)>,
              "every method's options member of OptimizerOptions must be listed in kOptimizerMethods");

// The options that run `method`: that method's Options as they are (no copy: an exhaustive search's
// checkpoint may hold every policy's value), or a copy with what the method name chooses (NLopt's algorithm).
template <class Options>
decltype(auto) OptionsFor(const Options& options, std::string_view method) {
  if constexpr (requires { options.ForMethod(method); }) {
    return options.ForMethod(method);
  } else {
    return (options);
  }
}

// Calls f(options of the method that runs options.method, its kMethod); false when no method runs it.
template <class Self, class F>
bool WithSelectedMethod(Self& options, F&& f) {
  bool found = false;
  ForEachOptimizerMethod([&](auto member) {
    using Options = OptimizerMethodOptions<decltype(member)>;
    if (!found && Options::kMethod.runs(options.method)) {
      found = true;
      f(options.*member, Options::kMethod);
    }
  });
  return found;
}

}  // namespace

std::span<const std::string_view> OptimizerMethodNames() {
  static const std::vector<std::string_view> names = [] {
    std::vector<std::string_view> all;
    ForEachOptimizerMethod([&](auto member) {
      for (std::string_view name : OptimizerMethodOptions<decltype(member)>::kMethod.method_names)
        if (!name.empty()) all.push_back(name);
    });
    return all;
  }();
  return names;
}

void OptimizerOptions::SetCheckpointing(std::int64_t checkpoint_every, CheckpointCallback on_checkpoint,
                                        std::optional<nlohmann::json> resume_from) {
  ForEachOptimizerMethod([&](auto member) {
    auto& o = this->*member;
    o.checkpoint_every = checkpoint_every;
    o.on_checkpoint = on_checkpoint;
    o.resume_from = resume_from;
  });
}

std::int64_t OptimizerOptions::IterationLimit() const {
  std::int64_t limit = 0;
  WithSelectedMethod(*this, [&](const auto& o, const OptimizerMethodInfo&) { limit = o.IterationLimit(); });
  return limit;
}

void OptimizerOptions::SetCallbacks(const IterationCallbacks& callbacks) {
  ForEachOptimizerMethod([&](auto member) { (this->*member).callbacks = callbacks; });
}

void OptimizerOptions::SetSeeds(std::uint64_t seed) {
  ForEachOptimizerMethod([&](auto member) {
    if constexpr (OptimizerMethodOptions<decltype(member)>::kMethod.seed_domain != 0)
      (this->*member).seed = seed;
  });
}

bool OptimizerOptions::IsValid(std::string* error) const {
  bool valid = false;
  const bool known = WithSelectedMethod(*this, [&](const auto& o, const OptimizerMethodInfo& info) {
    std::string inner;
    valid = OptionsFor(o, method).IsValid(&inner);
    if (!valid && error) *error = fmt::format("{}.{}", info.section, inner);
  });
  if (!known && error)
    *error = fmt::format("method: expected one of {}, got \"{}\"", fmt::join(OptimizerMethodNames(), ", "),
                         method);
  return known && valid;
}

void Solve(const OptimizerOptions& options, Objective& objective, Theta* theta, OptimizerSummary* summary) {
  std::string error;
  if (!options.IsValid(&error)) throw InputError("optimizer options: " + error);
  WithSelectedMethod(options, [&](const auto& o, const OptimizerMethodInfo& info) {
    // Only a method of whole-number parameters takes an integer parameter (a table's action): the others
    // move theta by real steps and would return a fraction.
    const ParameterSpec& spec = objective.parameters();
    if (const std::size_t i = spec.first_integer(); i < spec.size() && !info.integer_parameters) {
      std::vector<std::string_view> integer_methods;
      ForEachOptimizerMethod([&](auto member) {
        const OptimizerMethodInfo& other = OptimizerMethodOptions<decltype(member)>::kMethod;
        if (other.integer_parameters)
          for (std::string_view name : other.method_names)
            if (!name.empty()) integer_methods.push_back(name);
      });
      throw InputError(fmt::format(
          "optimizer method {}: searches real numbers, but parameter '{}' is an integer (a table entry); "
          "expected {}",
          options.method, spec[i].name, fmt::join(integer_methods, " or ")));
    }
    Solve(OptionsFor(o, options.method), objective, theta, summary);
  });
}

}  // namespace pegasus
