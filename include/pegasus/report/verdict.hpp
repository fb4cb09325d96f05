#pragma once
// The verdict a run's report opens with (issue 50: reports lead with the answer): one sentence made from the
// command's summary.json, with its figures, e.g. "30 flights, no crash; 40% closer to the set point than the
// scripted pilot (RMS position 0.446 m against 0.739 m)". Each command's sentence is built in one place
// (src/report/verdict.cpp) from the summary alone, so a report rewritten later says the same.
//
//   pegasus::report::verdict("heli fly", read_json_file("runs/fly/summary.json"))
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace pegasus::report {

// The verdict of a run of `command` (run.json "command", e.g. "heli fly") from its summary; empty for a
// command that has none, or a summary without the figures its sentence needs.
std::string verdict(std::string_view command, const nlohmann::json& summary);

// Whether `command` has a verdict sentence at all (every command that writes a run directory should).
bool has_verdict(std::string_view command);

}  // namespace pegasus::report
