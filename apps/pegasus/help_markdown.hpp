#pragma once
// `pegasus --help-markdown` (hidden): every command and option of the CLI as Markdown, from the CLI's own
// descriptions, defaults and types. docs/reference/cli.md is its output, checked in; the ctest
// docs.CommandReference fails when the two differ (regenerate: build/pegasus --help-markdown >
// docs/reference/cli.md).
#include <CLI/CLI.hpp>
#include <string>

namespace pegasus::cli {

inline constexpr const char* kHelpMarkdownFlag = "--help-markdown";

// The reference page of `app` and every command under it, in declaration order.
std::string help_markdown(CLI::App& app);

}  // namespace pegasus::cli
