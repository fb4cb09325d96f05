#pragma once
// What every summary.json key means, in one table (issue 50): for each command, its keys as the report lists
// them, each with its meaning in one line and its unit. The report shows them beside the raw keys, the
// manual's page docs/reference/_summary-keys-table.md is generated from it (`pegasus
// --help-summary-keys-markdown`, checked by the ctest docs.SummaryKeys), and the digest test fails when a
// shipped command writes a key it lacks
// (`pegasus --undescribed-summary-keys RUN_DIR...`).
//
// A key is a path of object keys joined by '.', as the report flattens a summary: scalars and short arrays of
// scalars to depth 2 ("pilot.rms_position_m"); an object deeper than that, an array of objects or a long
// array is one key of its own ("prediction.rmse", "results"). A pattern's component written <name> stands for
// any one component (an output, a horizon such as "0.5", a stage, a method).
//
//   const SummaryKey* key = describe_summary_key("heli fly", {"pilot", "rms_position_m"});
//   // key->meaning, key->unit
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace pegasus::report {

struct SummaryKey {
  std::string_view pattern;  // "rms_position_m", "pilot.<figure>", "noise_check.<output>"
  std::string_view unit;     // "m", "s", "rad", "" where it has none (a count, a name, a flag, a ratio)
  std::string_view meaning;  // one line
};

struct SummaryKeyGroup {
  std::vector<std::string_view> commands;  // run.json "command" of the runs that write these keys
  std::vector<SummaryKey> keys;
};

// Every command's keys, in the manual's order.
const std::vector<SummaryKeyGroup>& summary_key_groups();

// The description of one key of a summary written by `command`; nullptr when the table has none.
const SummaryKey* describe_summary_key(std::string_view command, const std::vector<std::string>& path);

// Visits the summary's keys as the report lists them (see above), in the summary's order: `scalar` is true
// where the value is a scalar or a short array of scalars (the report prints it), false where it is a
// structure.
void visit_summary_keys(const nlohmann::json& summary,
                        const std::function<void(const std::vector<std::string>& path,
                                                 const nlohmann::json& value, bool scalar)>& visit);

// The keys of a summary written by `command` that the table does not describe, '.'-joined.
std::vector<std::string> undescribed_summary_keys(std::string_view command, const nlohmann::json& summary);

}  // namespace pegasus::report
