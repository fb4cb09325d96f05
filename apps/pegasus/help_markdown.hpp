#pragma once
// `pegasus --help-markdown` (hidden): every command and option of the CLI as Markdown, from the CLI's own
// descriptions, defaults and types. docs/reference/cli.md is its output, checked in; the ctest
// docs.CommandReference fails when the two differ (regenerate: build/pegasus --help-markdown >
// docs/reference/cli.md).
#include <CLI/CLI.hpp>
#include <iosfwd>
#include <string>
#include <vector>

namespace pegasus::cli {

inline constexpr const char* kHelpMarkdownFlag = "--help-markdown";

// The reference page of `app` and every command under it, in declaration order.
std::string help_markdown(CLI::App& app);

// `pegasus --help-summary-keys-markdown` (hidden): the key table of summary.json (report/summary_keys.hpp) as
// Markdown; docs/reference/_summary-keys-table.md is its output, checked by the ctest docs.SummaryKeys.
inline constexpr const char* kSummaryKeysMarkdownFlag = "--help-summary-keys-markdown";
std::string summary_keys_markdown();

// `pegasus --undescribed-summary-keys RUN_DIR...` (hidden): every summary.json under the run directories,
// with the command of the run.json beside it, checked against the key table. Prints one line per key the
// table does not describe ("DIR/summary.json: key (command)"); exit 0 when there is none, 1 when there is, 2
// on bad input.
inline constexpr const char* kUndescribedSummaryKeysFlag = "--undescribed-summary-keys";
int undescribed_summary_keys_main(const std::vector<std::string>& run_dirs, std::ostream& out,
                                  std::ostream& err);

}  // namespace pegasus::cli
