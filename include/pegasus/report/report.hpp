#pragma once
// The HTML report of a run directory (the last step of the data flow: run directory -> report).
//
// report.html is one self-contained file that works offline, at most 1.5 MB: the page skeleton (title,
// headline figures of summary.json, the resolved config.toml, run.json provenance) is plain HTML; the data of
// every chart is a JSON block in the page (gzip-compressed, base64-encoded), built from the run's CSV series;
// and the JavaScript that draws the charts
// (plotly.js), the 3-D flight replay (three.js) and the page code (web/src/report.js) is inlined from one
// bundle file, pegasus-report.js, that the build makes with `npm ci` from web/package-lock.json.
//
// What a report shows is what the run directory says of itself: the sections and charts of charts.json
// (runs/charts.hpp), which the command that wrote the series also wrote. The report knows no experiment:
// beyond charts.json it shows policy.json's parameters, any other CSV series against its first column, small
// CSV tables, links to the reports of runs inside this one and the list of files. A run directory written
// before charts.json existed gets only those generic parts; rerunning its command gives the full report.
//
//   const auto bundle = pegasus::report::find_bundle();        // std::runtime_error: not found
//   pegasus::report::write_report("runs/demo", bundle);        // InputError: not a readable run directory
#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace pegasus::report {

// The bundle file name, next to the `pegasus` executable in a build directory.
inline constexpr const char* kBundleName = "pegasus-report.js";
// The environment variable that names the bundle file explicitly.
inline constexpr const char* kBundleEnv = "PEGASUS_REPORT_BUNDLE";

// A report's largest size: 1.5 MB, the bundle (about 0.86 MB) included.
inline constexpr std::size_t kMaxReportBytes = 1'500'000;

struct ReportOptions {
  // Most rows of one series embedded in the page; longer series keep every k-th row (and the last). The
  // stride is recorded with the series. Numbers keep six significant digits.
  std::size_t max_points = 4000;
  // Most samples of one flight in the 3-D replay (1500: 25 Hz over a minute).
  std::size_t max_replay_points = 1500;
  // Most flights of flights.csv / pilot_flights.csv drawn (the first ones).
  std::size_t max_flights = 10;
  // The page's largest size in bytes (0: no limit). render_report and write_report thin every series and
  // replay further (fewer rows, down to 20) where the rows above would make the page longer.
  std::size_t max_bytes = kMaxReportBytes;
};

// Where the JavaScript bundle is, in this order: $PEGASUS_REPORT_BUNDLE; pegasus-report.js next to the
// running executable (a build directory); ../share/pegasus/pegasus-report.js from the executable's folder
// (an installed tree: bin/pegasus, share/pegasus/pegasus-report.js); from the Python module (a program that
// imports pegasus), the build tree's and the installed tree's places from the module's file.
// std::runtime_error naming the places looked at when none exists.
std::filesystem::path find_bundle();

// The data of the report (title, headline figures, sections, charts), as embedded in the page. InputError
// naming the file (and line) when `run_dir` is not a directory, has no readable summary.json, or holds a
// malformed CSV series.
nlohmann::json report_data(const std::filesystem::path& run_dir, const ReportOptions& options = {});

// The whole report.html text, at most options.max_bytes long; `bundle_js` is the text of pegasus-report.js.
// The charts' data is embedded as gzip-compressed, base64-encoded JSON (the bundle unpacks it). Errors as
// report_data.
std::string render_report(const std::filesystem::path& run_dir, std::string_view bundle_js,
                          const ReportOptions& options = {});

// Writes run_dir/report.html atomically (never half-written): everything is read and checked first.
// Returns the path written. Errors as report_data; a bundle that cannot be read is a std::runtime_error
// naming it.
std::filesystem::path write_report(const std::filesystem::path& run_dir, const std::filesystem::path& bundle,
                                   const ReportOptions& options = {});
// The same with the bundle of find_bundle(), looked for after the run directory was checked (so bad input
// is an InputError even where the bundle is missing).
std::filesystem::path write_report(const std::filesystem::path& run_dir, const ReportOptions& options = {});

// For the end of every run (the command runner calls it before committing the run directory): writes the
// report like write_report, but a failure of the report itself (a missing bundle, a chart it cannot draw)
// costs only the report: one line "pegasus: note: no report.html: ..." on `err`, and false. A refusal of
// the machine (EnvironmentError: a full disk; no memory) is thrown on: the run then fails with exit code 3
// and keeps DIR.partial for --resume, so a committed DIR always holds its report.
bool write_report_or_note(const std::filesystem::path& run_dir, std::ostream& err,
                          const ReportOptions& options = {});

}  // namespace pegasus::report
