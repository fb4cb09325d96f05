#include "pegasus/report/report.hpp"

#include <dlfcn.h>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>
#include <vector>

#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/csv_table.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/report/summary_keys.hpp"
#include "pegasus/report/verdict.hpp"
#include "pegasus/runs/charts.hpp"
#include "pegasus/runs/config.hpp"
#include "report_page.hpp"

namespace pegasus::report {

namespace fs = std::filesystem;
using json = nlohmann::json;
using namespace detail;

namespace {

// --- headline, configuration, provenance ------------------------------------------------------------------

// The summary's keys as the report lists them (summary_keys.hpp), its first 60 scalars, each with its value,
// unit and meaning (empty where the key table has none).
std::vector<std::vector<std::string>> headline_rows(const std::string& command, const json& summary) {
  std::vector<std::vector<std::string>> rows;
  visit_summary_keys(summary, [&](const std::vector<std::string>& path, const json& value, bool scalar) {
    if (!scalar || rows.size() >= 60) return;
    std::string text;
    if (value.is_array()) {
      for (const auto& v : value) {
        text += (text.empty() ? "" : ", ") + (v.is_number_float() ? format_number(v.get<double>())
                                              : v.is_string()     ? v.get<std::string>()
                                                                  : v.dump());
      }
      text = "[" + text + "]";
    } else {
      text = value.is_number_float() ? format_number(value.get<double>())
             : value.is_string()     ? value.get<std::string>()
                                     : value.dump();
    }
    const SummaryKey* key = describe_summary_key(command, path);
    rows.push_back({fmt::format("{}", fmt::join(path, ".")), text,
                    key ? std::string(key->unit) : std::string(),
                    key ? std::string(key->meaning) : std::string()});
  });
  return rows;
}

void add_policy(Page& page, const fs::path& dir) {
  const fs::path file = dir / "policy.json";
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return;
  json policy;
  try {
    policy = read_json_file(file);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (!policy.is_object() || !policy.contains("parameters")) return;
  const json& p = policy["parameters"];
  std::vector<std::vector<std::string>> rows;
  auto number = [](const json& v) { return v.is_number() ? format_double(v.get<double>()) : v.dump(); };
  if (p.is_object()) {
    for (const auto& [k, v] : p.items()) rows.push_back({k, number(v)});
  } else if (p.is_array()) {
    const json* names = policy.contains("names") && policy["names"].is_array() ? &policy["names"] : nullptr;
    for (std::size_t i = 0; i < p.size(); ++i) {
      if (p[i].is_object() && p[i].contains("name") && p[i].contains("value")) {
        rows.push_back({p[i]["name"].is_string() ? p[i]["name"].get<std::string>() : p[i]["name"].dump(),
                        number(p[i]["value"])});
      } else {
        const std::string name = names && i < names->size() && (*names)[i].is_string()
                                     ? (*names)[i].get<std::string>()
                                     : std::to_string(i);
        rows.push_back({name, number(p[i])});
      }
    }
  }
  if (rows.empty() || rows.size() > 500) return;
  page.section("policy", "Policy parameters", "(policy.json)",
               "<details><summary>" + std::to_string(rows.size()) + " parameters</summary>\n" +
                   table_html({"parameter", "value"}, rows) + "</details>\n");
}

std::string read_text_or_empty(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return {};
  return read_file(file);
}

constexpr const char* kStyle = R"(
:root { --fg: #1d2330; --muted: #5b6475; --line: #d8dde6; --bg: #ffffff; --panel: #f6f8fb; --accent: #1f77b4; }
* { box-sizing: border-box; }
body { margin: 0; font: 15px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; color: var(--fg); background: var(--bg); }
header { padding: 20px 32px 12px; border-bottom: 1px solid var(--line); background: var(--panel); }
header h1 { margin: 0 0 4px; font-size: 24px; }
header .meta { margin: 0; color: var(--muted); font-size: 13px; }
nav { padding: 8px 32px; border-bottom: 1px solid var(--line); font-size: 13px; }
nav a { margin-right: 14px; color: var(--accent); text-decoration: none; }
main { padding: 8px 32px 40px; max-width: 1500px; }
section { margin: 22px 0 30px; }
h2 { font-size: 19px; margin: 0 0 6px; border-bottom: 1px solid var(--line); padding-bottom: 4px; }
p.intro { margin: 4px 0 12px; color: var(--muted); max-width: 70em; }
table { border-collapse: collapse; font-size: 13px; margin: 6px 0; }
th, td { border: 1px solid var(--line); padding: 3px 9px; text-align: left; }
th { background: var(--panel); }
td.num { text-align: right; font-variant-numeric: tabular-nums; }
pre { background: var(--panel); border: 1px solid var(--line); padding: 10px; overflow: auto; max-height: 420px; font-size: 12.5px; }
details summary { cursor: pointer; color: var(--accent); margin: 6px 0; }
.grid { display: grid; grid-template-columns: repeat(auto-fit, minmax(460px, 1fr)); gap: 14px; }
.chart { min-height: 380px; border: 1px solid var(--line); border-radius: 6px; padding: 4px; background: #fff; }
.chart.small { min-height: 300px; height: 300px; }
.chart.wide { grid-column: 1 / -1; }
.chart.replay { min-height: 0; }
.replay-controls { display: flex; flex-wrap: wrap; align-items: center; gap: 12px; padding: 8px 4px; font-size: 13px; }
.replay-slider { flex: 1 1 300px; }
.replay-time { font-variant-numeric: tabular-nums; min-width: 8em; }
.replay-view canvas { display: block; width: 100%; border-radius: 4px; }
img.svg { max-width: 100%; border: 1px solid var(--line); border-radius: 6px; }
footer { padding: 12px 32px; color: var(--muted); font-size: 12px; border-top: 1px solid var(--line); }
p.verdict { font-size: 17px; font-weight: 600; margin: 6px 0 10px; }
pre.result { font-size: 14px; max-height: none; white-space: pre-wrap; }
ul.warnings { margin: 6px 0; padding: 8px 12px 8px 28px; background: #fff6e0; border: 1px solid #e7c766; border-radius: 4px; }
)";

// The file of the executable or shared object this code is linked into: the Python module (lib/python3/
// dist-packages/pegasus/_pegasus.so) when a program imports pegasus and runs a command (pegasus.pipeline).
fs::path this_object_file() {
  static const char anchor = 0;
  Dl_info info{};
  if (::dladdr(&anchor, &info) == 0 || info.dli_fname == nullptr) return {};
  std::error_code ec;
  const fs::path file = fs::canonical(info.dli_fname, ec);
  return ec ? fs::path() : file;
}

}  // namespace

fs::path find_bundle() {
  std::vector<fs::path> tried;
  if (const char* env = std::getenv(kBundleEnv); env != nullptr && *env != '\0') {
    fs::path p(env);
    std::error_code ec;
    if (fs::is_regular_file(p, ec)) return p;
    throw std::runtime_error(fmt::format(
        "report JavaScript bundle not found: ${} is '{}', which is not a file", kBundleEnv, p.string()));
  }
  std::error_code ec;
  std::vector<fs::path> candidates;
  if (const fs::path exe = fs::read_symlink("/proc/self/exe", ec); !ec)
    candidates = {exe.parent_path() / kBundleName,
                  exe.parent_path().parent_path() / "share" / "pegasus" / kBundleName};
  // From a shared object: the build tree's (build/python/pegasus/_pegasus.so, build/pegasus-report.js), or
  // the installed tree's (lib/python3*/dist-packages/pegasus/_pegasus.so, share/pegasus/pegasus-report.js).
  if (const fs::path object = this_object_file(); !object.empty() && object.extension() == ".so") {
    const fs::path above = object.parent_path().parent_path().parent_path();  // build, lib/python3*
    candidates.push_back(above / kBundleName);
    candidates.push_back(above.parent_path().parent_path() / "share" / "pegasus" / kBundleName);
  }
  for (const fs::path& p : candidates) {
    std::error_code e2;
    if (fs::is_regular_file(p, e2)) return p;
    tried.push_back(p);
  }
  std::string places;
  for (const auto& p : tried) places += (places.empty() ? "" : ", ") + p.string();
  throw std::runtime_error(fmt::format(
      "report JavaScript bundle {} not found (looked in {}): build the `report_bundle` target (it runs npm "
      "ci in "
      "web/) or set ${} to the file",
      kBundleName, places.empty() ? std::string("no place: the executable's path is unknown") : places,
      kBundleEnv));
}

namespace {

// The command of a run (run.json "command"), or "".
std::string command_of(const json& run) {
  return run.is_object() && run.contains("command") && run["command"].is_string()
             ? run["command"].get<std::string>()
             : std::string();
}

// The verdict of a run (verdict.hpp), as a paragraph; empty when its command has none.
std::string verdict_html(const json& run, const json& summary) {
  const std::string said = verdict(command_of(run), summary);
  return said.empty() ? std::string() : "<p class=\"verdict\">" + escape_markup(said) + "</p>\n";
}

// The lines a run printed (run.json "printed"), warnings first and marked; empty when it printed none.
std::string printed_result_html(const json& run) {
  if (!run.is_object()) return {};
  std::string html;
  if (const auto w = run.find("warnings"); w != run.end() && w->is_array() && !w->empty()) {
    html += "<ul class=\"warnings\">\n";
    for (const auto& line : *w)
      if (line.is_string()) html += "<li>" + escape_markup(line.get<std::string>()) + "</li>\n";
    html += "</ul>\n";
  }
  std::string text;
  if (const auto p = run.find("printed"); p != run.end() && p->is_array())
    for (const auto& line : *p)
      if (line.is_string() && !line.get<std::string>().starts_with("warning:"))
        text += escape_markup(line.get<std::string>()) + "\n";
  if (!text.empty()) html += "<pre class=\"result\">" + text + "</pre>\n";
  return html;
}

// The runs inside `run_dir` (the stages of a pipeline): its folders with a summary.json, in the order the
// summary's "stages" lists them, the others after them by name.
std::vector<fs::path> parts_of(const fs::path& run_dir, const json& summary) {
  std::vector<fs::path> parts;
  for (const auto& e : fs::directory_iterator(run_dir)) {
    std::error_code ec;
    if (e.is_directory(ec) && fs::is_regular_file(e.path() / "summary.json", ec)) parts.push_back(e.path());
  }
  std::sort(parts.begin(), parts.end());
  const json stages = summary.is_object() ? summary.value("stages", json::array()) : json::array();
  const auto rank = [&](const fs::path& p) {
    for (std::size_t i = 0; i < stages.size(); ++i)
      if (stages[i].is_string() && stages[i].get<std::string>() == p.filename().string()) return i;
    return stages.size();
  };
  std::stable_sort(parts.begin(), parts.end(),
                   [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
  return parts;
}

// The verdicts of the parts, one item each ("identify: the noise bands are ..."); empty when none has one.
std::string part_verdicts_html(const std::vector<fs::path>& parts) {
  std::string items;
  for (const auto& part : parts) {
    try {
      const std::string said =
          verdict(command_of(read_json_file(part / "run.json")), read_json_file(part / "summary.json"));
      if (!said.empty())
        items +=
            "<li><b>" + escape_markup(part.filename().string()) + "</b>: " + escape_markup(said) + "</li>\n";
    } catch (const std::exception&) {  // a part without a readable run.json has no verdict
    }
  }
  return items.empty() ? std::string() : "<ul class=\"stage-verdicts\">\n" + items + "</ul>\n";
}

// A run directory's summary.json (required) and run.json (an empty object without one).
struct RunFiles {
  json summary, run = json::object();
};

RunFiles read_run_files(const fs::path& run_dir) {
  std::error_code ec;
  if (!fs::exists(run_dir, ec)) {
    throw InputError(fmt::format("RUN_DIR '{}': no such directory", run_dir.string()));
  }
  if (!fs::is_directory(run_dir, ec)) {
    throw InputError(fmt::format("RUN_DIR '{}': expected a run directory, got a file", run_dir.string()));
  }
  const fs::path summary_file = run_dir / "summary.json";
  if (!fs::is_regular_file(summary_file, ec)) {
    throw InputError(fmt::format("{}: not found (expected a run directory written by a pegasus command)",
                                 summary_file.string()));
  }
  RunFiles files;
  try {
    files.summary = read_json_file(summary_file);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  if (fs::is_regular_file(run_dir / "run.json", ec)) {
    try {
      files.run = read_json_file(run_dir / "run.json");
    } catch (const std::exception& e) {
      throw InputError(e.what());
    }
  }
  return files;
}

// The run directory's name: a report written at the end of a run is written in DIR.partial, and names the
// run by its final name.
fs::path run_name(const fs::path& run_dir) {
  fs::path name = run_dir.lexically_normal();
  if (!name.has_filename()) name = name.parent_path();
  if (const std::string staged = name.filename().string(); staged.ends_with(".partial"))
    name.replace_filename(staged.substr(0, staged.size() - std::string_view(".partial").size()));
  return name;
}

// The page's title: the command, else the summary's experiment, else the directory's name.
std::string run_title(const fs::path& name, const json& run, const json& summary) {
  std::string title = name.filename().string();
  if (run.is_object() && run.contains("command") && run["command"].is_string()) {
    title = "pegasus " + run["command"].get<std::string>();
  } else if (summary.is_object() && summary.contains("experiment") && summary["experiment"].is_string()) {
    title = summary["experiment"].get<std::string>();
  }
  return title;
}

// The answer first: the verdict made from the summary, the run's warnings, and what it printed as its
// result (run.json, written by the command framework from the run's printed lines). A pipeline's stages say
// theirs below its own. Then the choices the run made from the data (summary.json's `choices`: model class,
// noise, control gains, start, optimizer), each with what it was chosen by.
void add_result_and_choices(Page& page, const json& run, const json& summary,
                            const std::vector<fs::path>& parts) {
  if (const std::string result =
          verdict_html(run, summary) + part_verdicts_html(parts) + printed_result_html(run);
      !result.empty())
    page.section("result", "Result", "The verdict, then what the run printed when it finished.", result);
  if (summary.is_object() && summary.contains("choices") && summary["choices"].is_object()) {
    std::vector<std::vector<std::string>> rows;
    for (const auto& [what, choice] : summary["choices"].items())
      rows.push_back({what, choice.is_string() ? choice.get<std::string>() : choice.dump()});
    page.section("choices", "Choices",
                 "What the run chose from the data, and by what (summary.json: choices).",
                 table_html({"choice", "value"}, rows, "choices"));
  }
}

// Headline figures and configuration.
void add_headline_and_config(Page& page, const fs::path& run_dir, const json& run, const json& summary) {
  const auto rows = headline_rows(command_of(run), summary);
  std::string head = rows.empty() ? std::string("<p>(no scalar figures)</p>\n")
                                  : table_html({"figure", "value", "unit", "meaning"}, rows, "headline");
  head += "<details><summary>summary.json</summary>\n<pre>" + escape_markup(summary.dump(2)) +
          "</pre></details>\n";
  page.section("headline", "Headline figures",
               "From summary.json, each key with its unit and meaning (the manual: summary.json keys).",
               head);
  const std::string config = read_text_or_empty(run_dir / "config.toml");
  std::string config_html =
      "<details open><summary>config.toml</summary>\n<pre>" + escape_markup(config) + "</pre></details>\n";
  if (run.is_object() && !run.empty()) {
    config_html += "<details><summary>run.json (provenance)</summary>\n<pre>" + escape_markup(run.dump(2)) +
                   "</pre></details>\n";
  }
  page.section("config", "Configuration",
               config.empty()
                   ? "No config.toml in the run directory."
                   : "The resolved configuration (defaults, then the config file, then the command line).",
               config_html);
}

// One stage's item: a link to its own report, its command, and what it printed.
std::string part_item_html(const fs::path& part) {
  const std::string n = part.filename().string();
  std::string command;
  try {
    const json r = read_json_file(part / "run.json");
    if (r.contains("command") && r["command"].is_string())
      command = "pegasus " + r["command"].get<std::string>();
  } catch (const std::exception&) {
  }
  std::string verdict;  // the stage's verdict and its own result lines
  try {
    const json part_run = read_json_file(part / "run.json");
    verdict = verdict_html(part_run, read_json_file(part / "summary.json")) + printed_result_html(part_run);
  } catch (const std::exception&) {
  }
  std::error_code e2;
  return fs::is_regular_file(part / "report.html", e2)
             ? fmt::format("<li><a href=\"{0}/report.html\">{0}</a> {1}{2}</li>\n", escape_markup(n),
                           escape_markup(command), verdict)
             : fmt::format("<li>{} {} (no report.html yet: pegasus report {}){}</li>\n", escape_markup(n),
                           escape_markup(command), escape_markup(part.string()), verdict);
}

// The files of the run directory.
void add_files(Page& page, const fs::path& run_dir) {
  std::vector<std::vector<std::string>> files;
  std::vector<fs::directory_entry> entries;
  for (const auto& e : fs::directory_iterator(run_dir)) entries.push_back(e);
  std::sort(entries.begin(), entries.end(), [](const auto& a, const auto& b) { return a.path() < b.path(); });
  for (const auto& e : entries) {
    const std::string n = e.path().filename().string();
    if (n == "report.html" || n.starts_with(".")) continue;
    std::error_code e2;
    const bool dir = e.is_directory(e2);
    files.push_back({n + (dir ? "/" : ""), dir ? std::string("") : std::to_string(e.file_size(e2))});
  }
  page.section("files", "Files", "The run directory this report was made from.",
               table_html({"file", "bytes"}, files));
}

}  // namespace

json report_data(const fs::path& run_dir, const ReportOptions& options) {
  const auto [summary, run] = read_run_files(run_dir);
  const fs::path name = run_name(run_dir);
  const std::string title = run_title(name, run, summary);

  Page page;
  page.consumed("report.html");
  const std::vector<fs::path> parts = parts_of(run_dir, summary);
  add_result_and_choices(page, run, summary, parts);
  add_headline_and_config(page, run_dir, run, summary);

  // The charts the run describes (charts.json), then whatever else it holds.
  add_chart_sections(page, run_dir, options);
  add_policy(page, run_dir);
  add_other_series(page, run_dir, options);

  // Runs inside this one (the stages of a pipeline): links to their own reports, with what each printed.
  if (!parts.empty()) {
    std::string list = "<ul class=\"parts\">\n";
    for (const auto& part : parts) list += part_item_html(part);
    page.section("parts", "Parts of this run",
                 "Each stage is a run directory of its own, with its own report.", list + "</ul>\n");
  }
  add_files(page, run_dir);

  return {{"title", title},    {"run_dir", name.filename().string()}, {"summary", summary},   {"run", run},
          {"body", page.body}, {"sections", page.sections},           {"charts", page.charts}};
}

namespace {

// The script text made safe to sit between <script> and </script>: "</script" would end the element early,
// "<!--" can start the parser's escaped-script state. In JavaScript strings and regular expressions (the
// only places these occur in a minified bundle) "<\/" and "<\!--" mean the same.
std::string script_safe(std::string_view js) {
  std::string out;
  out.reserve(js.size());
  for (std::size_t i = 0; i < js.size(); ++i) {
    if (js[i] == '<' && i + 1 < js.size() && js[i + 1] == '/' && i + 8 <= js.size()) {
      std::string word(js.substr(i + 2, 6));
      std::transform(word.begin(), word.end(), word.begin(), [](unsigned char c) { return std::tolower(c); });
      if (word == "script") {
        out += "<\\/";
        ++i;
        continue;
      }
    }
    if (js.substr(i, 4) == "<!--") {
      out += "<\\!--";
      i += 3;
      continue;
    }
    out += js[i];
  }
  return out;
}

// The JSON of the charts as the page embeds it: gzip-compressed and base64-encoded (the bundle's loader gives
// the page code pegasusInflate to unpack it). Base64 has no "<", so it cannot end its <script> early.
std::string embedded_block(const json& data) {
  const json embedded = {{"title", data["title"]}, {"charts", data["charts"]}};
  return detail::base64(detail::gzip(embedded.dump()));
}

// The page of `data`, the charts as embedded_block made them.
std::string render_data(const json& data, const std::string& block, std::string_view bundle_js) {
  const std::string title = data["title"];
  std::string meta = escape_markup(data["run_dir"].get<std::string>());
  const json& run = data["run"];
  if (run.contains("version"))
    meta +=
        " &middot; pegasus " +
        escape_markup(run["version"].is_string() ? run["version"].get<std::string>() : run["version"].dump());
  if (run.contains("wall_time_s") && run["wall_time_s"].is_number()) {
    meta += fmt::format(" &middot; {:.3g} s wall time", run["wall_time_s"].get<double>());
  }
  if (run.contains("resumed") && run["resumed"].is_boolean() && run["resumed"].get<bool>())
    meta += " &middot; resumed";
  std::string nav;
  for (const auto& s : data["sections"]) {
    nav += fmt::format("<a href=\"#{}\">{}</a>", s["id"].get<std::string>(),
                       escape_markup(s["title"].get<std::string>()));
  }
  std::string html;
  html.reserve(bundle_js.size() + block.size() + data["body"].get<std::string>().size() + 8192);
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<meta name=\"generator\" content=\"pegasus report\">\n";
  html += "<title>" + escape_markup(title) + " &middot; " +
          escape_markup(data["run_dir"].get<std::string>()) + "</title>\n";
  html += "<style>" + std::string(kStyle) + "</style>\n</head>\n<body>\n";
  html += "<header><h1>" + escape_markup(title) + "</h1><p class=\"meta\">" + meta + "</p></header>\n";
  html += "<nav>" + nav + "</nav>\n<main>\n" + data["body"].get<std::string>() + "</main>\n";
  html +=
      "<footer>Written by <code>pegasus report</code>. Charts drawn with plotly.js, the 3-D replay with "
      "three.js, "
      "both inlined: this file works offline.</footer>\n";
  html += "<script type=\"application/gzip\" id=\"pegasus-data\" data-encoding=\"gzip+base64\">" + block +
          "</script>\n";
  html += "<script>\n";
  html += script_safe(bundle_js);
  html += "\n</script>\n</body>\n</html>\n";
  return html;
}

// The page at most options.max_bytes long. Where the series as the options allow them make it longer, every
// series and replay keeps fewer rows (a larger stride, recorded with it) until it fits, or until they keep
// kFewestPoints rows. `data` is report_data(run_dir, options), read already.
std::string fitted_page(const fs::path& run_dir, json data, std::string_view bundle_js,
                        ReportOptions options) {
  constexpr std::size_t kFewestPoints = 20;
  constexpr std::size_t kUnlimited = 1'000'000;  // where an option sets no limit, shrinking starts here
  std::string block = embedded_block(data);
  std::string html = render_data(data, block, bundle_js);
  while (options.max_bytes > 0 && html.size() > options.max_bytes) {
    const auto size = [](std::size_t n) { return static_cast<double>(n); };
    const double room = size(options.max_bytes) - size(html.size() - block.size());
    const bool fewest = options.max_points != 0 && options.max_points <= kFewestPoints &&
                        options.max_replay_points != 0 && options.max_replay_points <= kFewestPoints;
    if (room <= 0 || fewest) break;  // the page without its charts is too long already, or nothing to thin
    // The compressed data shrinks about in proportion to the rows kept; 0.9 leaves room for the rest.
    const double share = std::min(0.9 * room / size(block.size()), 0.9);
    for (std::size_t* most : {&options.max_points, &options.max_replay_points}) {
      const double from = size(*most == 0 ? kUnlimited : *most);
      *most = std::min(*most == 0 ? kUnlimited : *most,
                       std::max(kFewestPoints, static_cast<std::size_t>(from * share)));
    }
    data = report_data(run_dir, options);
    block = embedded_block(data);
    html = render_data(data, block, bundle_js);
  }
  return html;
}

fs::path write_data(const fs::path& run_dir, json data, const fs::path& bundle,
                    const ReportOptions& options) {
  std::string bundle_js;
  try {
    bundle_js = read_file(bundle);
  } catch (const std::exception& e) {
    throw std::runtime_error(fmt::format("report JavaScript bundle: {}", e.what()));
  }
  fs::path out = run_dir / "report.html";
  write_file_atomic(out, fitted_page(run_dir, std::move(data), bundle_js, options));
  return out;
}

}  // namespace

std::string render_report(const fs::path& run_dir, std::string_view bundle_js, const ReportOptions& options) {
  return fitted_page(run_dir, report_data(run_dir, options), bundle_js, options);
}

fs::path write_report(const fs::path& run_dir, const fs::path& bundle, const ReportOptions& options) {
  return write_data(run_dir, report_data(run_dir, options), bundle, options);
}

fs::path write_report(const fs::path& run_dir, const ReportOptions& options) {
  json data = report_data(run_dir, options);  // bad input first: exit 2 even where the bundle is missing
  return write_data(run_dir, std::move(data), find_bundle(), options);
}

bool write_report_or_note(const fs::path& run_dir, std::ostream& err, const ReportOptions& options) {
  try {
    write_report(run_dir, options);
    return true;
  } catch (const EnvironmentError&) {
    throw;  // a full disk is the run's failure (exit 3, DIR.partial kept), not the report's alone
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    std::string line = e.what();
    std::replace(line.begin(), line.end(), '\n', ' ');
    err << "pegasus: note: no report.html: " << line << std::endl;
    return false;
  }
}

}  // namespace pegasus::report
