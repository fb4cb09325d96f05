#include "pegasus/runs/run_directory.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <thread>

#include "pegasus/core/environment_error.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"
#include "pegasus/io/json_input.hpp"
#include "pegasus/io/sha256.hpp"
#include "pegasus/parallel/mpi.hpp"

namespace pegasus {

namespace fs = std::filesystem;

namespace {

constexpr const char* kConfigFile = "config.toml";
constexpr const char* kCheckpointFile = "checkpoint.json";
constexpr const char* kChartsFile = "charts.json";
constexpr const char* kInputsFile = "inputs.json";
// inputs.json: {"format", "version", "files": {FIELD: {"file", "sha256"[, "of"]}}}. Version 0 (before the
// file carried its format) is the object of files alone, and still resumes.
constexpr const char* kInputsFormat = "pegasus.run.inputs";
constexpr int kInputsVersion = 1;

bool exists_no_follow(const fs::path& p) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(p, ec));
}

// Temporary files of atomic writes that a kill interrupted.
void remove_stale_temporaries(const fs::path& dir) {
  std::error_code ec;
  std::vector<fs::path> stale;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() > 5 && name.front() == '.' && name.ends_with(".tmp") && it->is_regular_file(ec)) {
      stale.push_back(it->path());
    }
  }
  for (const auto& p : stale) fs::remove(p, ec);
}

// The SHA-256 of each input file the config names (ConfigField::input_file), by field; files that cannot be
// read are left to the command to report.
nlohmann::json input_digests(const ConfigSchema& config) {
  nlohmann::json digests = nlohmann::json::object();
  for (const ConfigField& field : config.fields()) {
    if (!field.is_input_file()) continue;
    // A list's files by "name[i]".
    std::vector<std::pair<std::string, std::string>> files;
    if (field.type() == FieldType::kStringList) {
      const auto& list = config.get_string_list(field.name());
      for (std::size_t i = 0; i < list.size(); ++i)
        files.emplace_back(fmt::format("{}[{}]", field.name(), i), list[i]);
    } else {
      files.emplace_back(field.name(), config.get_string(field.name()));
    }
    for (const auto& [key, file] : files) {
      std::error_code ec;
      const std::string found = path_under(config.base_directory(), file);  // recorded as named
      if (file.empty() || !fs::is_regular_file(found, ec)) continue;
      try {
        const ConfigField::Digest& digest = field.input_digest();
        digests[key] = {{"file", file}, {"sha256", digest ? digest(found) : file_sha256(found)}};
        if (digest) digests[key]["of"] = "the file and what it includes";
      } catch (const InputError&) {
        // unreadable: the command says so
      }
    }
  }
  return digests;
}

// What --resume continues was computed from the input files as they were: refuse when one changed since,
// and when the interrupted run left no record of them (a kill before inputs.json was written, or a
// DIR.partial made by hand), since nothing then shows the inputs are the same.
// The files an inputs.json records: its "files", or (version 0) the object itself.
const nlohmann::json& recorded_inputs(const nlohmann::json& stored, const fs::path& file) {
  if (!stored.contains("format") && !stored.contains("version")) return stored;
  json_format_header(stored, file.string(), kInputsFormat, kInputsVersion, "inputs.json of a run directory");
  const nlohmann::json& files = json_member(stored, "files", file.string(), "files");
  if (!files.is_object()) json_field_error(file.string(), "files", "an object", files);
  return files;
}

void check_inputs_unchanged(const fs::path& stored_file, const ConfigSchema& config) {
  if (!exists_no_follow(stored_file)) {
    const nlohmann::json now = input_digests(config);
    if (now.empty()) return;  // a run without input files
    const std::string field = now.begin().key();
    throw InputError(fmt::format(
        "--resume: {} holds no record of the input files (such as {}, {}), so the interrupted run cannot be "
        "checked against them; use --force to start over",
        stored_file.parent_path().string(), printable(now.begin().value().value("file", std::string("?"))),
        ConfigSchema::option_name(field.substr(0, field.find('[')))));
  }
  nlohmann::json stored;
  try {
    stored = read_json_file(stored_file);
  } catch (const std::exception& e) {
    throw InputError(fmt::format("--resume: cannot read {}: {}", stored_file.string(), e.what()));
  }
  if (!stored.is_object())
    throw InputError(
        fmt::format("--resume: {}: expected the object this program writes", stored_file.string()));
  const nlohmann::json now = input_digests(config);
  for (const auto& [field, recorded] : recorded_inputs(stored, stored_file).items()) {
    if (now.contains(field) && now[field] == recorded) continue;
    if (!recorded.is_object())
      throw InputError(fmt::format("--resume: {}: {}: expected the object this program writes",
                                   stored_file.string(), field));
    throw InputError(fmt::format(
        "--resume: {} ({}){} {} since the interrupted run began; use the same inputs, or --force to start "
        "over",
        printable(recorded.value("file", std::string("?"))),
        ConfigSchema::option_name(field.substr(0, field.find('['))),  // a list's file: "name[i]"
        recorded.contains("of") ? " or a file it includes" : "",
        now.contains(field) ? "changed" : "cannot be read"));
  }
}

// A DIR.partial whose run was killed while starting: a folder holding at most inputs.json and temporaries.
bool holds_nothing_but_a_start(const fs::path& staging) {
  std::error_code ec;
  if (!fs::is_directory(fs::symlink_status(staging, ec))) return false;
  for (auto it = fs::directory_iterator(staging, ec); !ec && it != fs::directory_iterator();
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const bool temporary = name.size() > 5 && name.front() == '.' && name.ends_with(".tmp");
    if (name != kInputsFile && !temporary) return false;
  }
  return !ec;
}

// A private folder for a shadow's direct writes, removed when the last copy of the pointer goes.
std::shared_ptr<const fs::path> make_scratch(int rank) {
  std::string pattern = (fs::temp_directory_path() / fmt::format("pegasus-rank{}-XXXXXX", rank)).string();
  if (::mkdtemp(pattern.data()) == nullptr)
    throw std::runtime_error(
        fmt::format("cannot create a scratch folder {}: {}", pattern, std::strerror(errno)));
  return std::shared_ptr<const fs::path>(new fs::path(pattern), [](const fs::path* p) {
    std::error_code ec;
    fs::remove_all(*p, ec);
    delete p;
  });
}

}  // namespace

// The lock of one run directory: an advisory flock on the file DIR.lock next to DIR, which holds the pid of
// its holder. Without it two runs on one DIR interleave their writes, removals and renames (issue 16: a
// --force beside a running run left a DIR without config.toml, and both runs reported success).
class RunDirectory::Lock {
 public:
  static std::shared_ptr<const Lock> acquire(const fs::path& final_dir) {
    fs::path file = final_dir;
    file += ".lock";
    for (;;) {
      const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
      if (fd < 0) {
        throw EnvironmentError(
            fmt::format("cannot create the lock file {}: {}", file.string(), std::strerror(errno)));
      }
      if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
        const int err = errno;
        const std::string holder = err == EWOULDBLOCK ? read_holder(fd) : std::string();
        ::close(fd);
        if (err != EWOULDBLOCK) {
          throw EnvironmentError(fmt::format("cannot lock {}: {}", file.string(), std::strerror(err)));
        }
        throw InputError(
            fmt::format("--out: '{}' is in use by another run ({}, holding {}); wait for it to "
                        "end or choose another directory",
                        final_dir.string(), holder, file.string()));
      }
      // A holder removes the file as it lets go: if that happened between our open and our flock, we hold
      // a lock on a file nobody else will ever open, so start again on the file now named DIR.lock.
      struct stat held {
      }, named{};
      if (::fstat(fd, &held) == 0 && ::stat(file.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
          held.st_ino == named.st_ino) {
        const std::string pid = std::to_string(::getpid()) + "\n";
        if (::ftruncate(fd, 0) != 0 ||
            ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
          const int err = errno;
          ::unlink(file.c_str());
          ::close(fd);
          throw EnvironmentError(
              fmt::format("cannot write the lock file {}: {}", file.string(), std::strerror(err)));
        }
        return std::shared_ptr<const Lock>(new Lock(std::move(file), fd));
      }
      ::close(fd);
    }
  }

  Lock(const Lock&) = delete;
  Lock& operator=(const Lock&) = delete;
  // Removed while still locked, so no later run can lock this file and believe it alone holds DIR.
  ~Lock() {
    ::unlink(file_.c_str());
    ::close(fd_);
  }

 private:
  Lock(fs::path file, int fd) : file_(std::move(file)), fd_(fd) {}

  // The holder writes its pid right after taking the lock; give it a moment to do so.
  static std::string read_holder(int fd) {
    for (int attempt = 0; attempt < 50; ++attempt) {
      char text[32] = {};
      const ssize_t n = ::pread(fd, text, sizeof text - 1, 0);
      if (n > 0 && text[n - 1] == '\n') return "pid " + std::string(text, static_cast<std::size_t>(n - 1));
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    return "pid unknown";
  }

  fs::path file_;
  int fd_;
};

RunDirectory RunDirectory::open(const fs::path& dir, const ConfigSchema& config,
                                RunDirectoryOptions options) {
  const mpi::Communicator ranks = options.ranks;
  if (ranks.size() == 1) return open_here(dir, config, options);
  // The first rank opens; every rank learns the outcome, so all go on or all throw the same error.
  std::optional<RunDirectory> opened;
  nlohmann::json outcome;
  if (ranks.rank() == 0) {
    try {
      opened.emplace(open_here(dir, config, options));
      outcome = {{"ok", true},
                 {"final", opened->final_.string()},
                 {"staging", opened->staging_.string()},
                 {"resumed", opened->resumed_}};
    } catch (const InputError& e) {
      outcome = {{"ok", false}, {"kind", "input"}, {"message", e.what()}};
    } catch (const EnvironmentError& e) {
      outcome = {{"ok", false}, {"kind", "environment"}, {"message", e.what()}};
    } catch (const std::exception& e) {
      outcome = {{"ok", false}, {"kind", "other"}, {"message", e.what()}};
    }
  }
  outcome = nlohmann::json::parse(mpi::broadcast_from_root(with_valid_utf8(outcome).dump()));
  if (!outcome.at("ok").get<bool>()) {
    const std::string message = outcome.at("message").get<std::string>();
    const std::string kind = outcome.at("kind").get<std::string>();
    if (kind == "input") throw InputError(message);
    if (kind == "environment") throw EnvironmentError(message);
    throw std::runtime_error(message);
  }
  if (opened) return std::move(*opened);
  RunDirectory run;
  run.ranks_ = ranks;
  run.shadow_ = true;
  run.final_ = outcome.at("final").get<std::string>();
  run.resumed_ = outcome.at("resumed").get<bool>();
  run.force_ = options.force;
  run.scratch_ = make_scratch(ranks.rank());
  run.staging_ = *run.scratch_;
  return run;
}

namespace {

// DIR as the final directory's path; InputError for a path that names no directory.
fs::path final_directory(const fs::path& dir) {
  fs::path final_dir = dir.lexically_normal();
  if (!final_dir.has_filename()) final_dir = final_dir.parent_path();
  const std::string name = final_dir.filename().string();
  if (name.empty() || name == "." || name == "..") {
    throw InputError(fmt::format("--out: expected a directory name, got '{}'", dir.string()));
  }
  if (final_dir.has_parent_path()) {
    std::error_code ec;
    fs::create_directories(final_dir.parent_path(), ec);
    if (ec) {
      throw EnvironmentError(
          fmt::format("cannot create {}: {}", final_dir.parent_path().string(), ec.message()));
    }
  }
  return final_dir;
}

// An interrupted run that --resume may continue: its stored configuration and inputs the same as now. Its
// stale temporaries are removed.
void check_resumable(const fs::path& staging, const ConfigSchema& config) {
  std::error_code ec;
  if (!fs::is_directory(staging, ec)) {
    throw InputError(fmt::format("--resume: '{}' is not a directory", staging.string()));
  }
  const fs::path stored_file = staging / kConfigFile;
  if (!exists_no_follow(stored_file)) {
    throw InputError(fmt::format(
        "--resume: '{}' holds no {}: it is not an interrupted run this program can check; use --force to "
        "start over",
        staging.string(), kConfigFile));
  }
  {
    ConfigSchema stored = config.with_defaults();
    try {
      stored.load_toml_file(stored_file);
    } catch (const InputError& e) {
      throw InputError(fmt::format("--resume: cannot use the stored configuration: {}", e.what()));
    }
    if (auto key = config.first_difference(stored)) {
      throw InputError(
          fmt::format("--resume: key '{}' is {} in the interrupted run ({}) but {} now; use the same "
                      "settings, or --force "
                      "to start over",
                      *key, ConfigSchema::format_value(stored.value(*key)), stored_file.string(),
                      ConfigSchema::format_value(config.value(*key))));
    }
  }
  check_inputs_unchanged(staging / kInputsFile, config);
  remove_stale_temporaries(staging);
}

// A fresh DIR.partial: an old one (--force without --resume, or a start that wrote nothing yet) removed.
void create_staging(const fs::path& staging, bool partial_exists) {
  if (partial_exists) {
    std::error_code ec;
    fs::remove_all(staging, ec);
    if (ec) throw EnvironmentError(fmt::format("cannot remove {}: {}", staging.string(), ec.message()));
  }
  std::error_code ec;
  if (!fs::create_directory(staging, ec) || ec) {
    throw EnvironmentError(fmt::format("cannot create {}: {}", staging.string(),
                                       ec ? ec.message() : std::string("it appeared meanwhile")));
  }
}

}  // namespace

RunDirectory RunDirectory::open_here(const fs::path& dir, const ConfigSchema& config,
                                     RunDirectoryOptions options) {
  const fs::path final_dir = final_directory(dir);
  fs::path staging = final_dir;
  staging += ".partial";
  // Everything below (the checks, the removal of an old DIR.partial, the commit) happens under the lock.
  std::shared_ptr<const Lock> lock = Lock::acquire(final_dir);

  if (exists_no_follow(final_dir) && !options.force) {
    throw InputError(
        fmt::format("--out: '{}' already exists (use --force to replace it)", final_dir.string()));
  }
  RunDirectory run;
  run.ranks_ = options.ranks;
  run.final_ = final_dir;
  run.staging_ = staging;
  run.force_ = options.force;
  run.lock_ = std::move(lock);

  const bool partial_exists = exists_no_follow(staging);
  if (partial_exists && !options.resume && !options.force) {
    throw InputError(fmt::format(
        "--out: '{}' holds an interrupted run (use --resume to continue it or --force to start over)",
        staging.string()));
  }
  // A run killed before it wrote config.toml (written last when a run starts) left nothing to continue:
  // --resume starts it over. Anything else there without config.toml cannot be checked, and is refused.
  const bool resume = partial_exists && options.resume && !holds_nothing_but_a_start(staging);
  if (resume) {
    check_resumable(staging, config);
    run.resumed_ = true;
  } else {
    create_staging(staging, partial_exists);
    run.created_ = true;
  }
  try {
    // inputs.json before config.toml: a DIR.partial with a config.toml always has the record of its inputs
    // (--resume refuses one without it).
    if (run.created_)
      if (const nlohmann::json digests = input_digests(config); !digests.empty())
        run.write_json(kInputsFile,
                       {{"format", kInputsFormat}, {"version", kInputsVersion}, {"files", digests}});
    run.write_text(kConfigFile, config.to_toml());
  } catch (...) {
    // A fresh DIR.partial without its config.toml (a full disk) is no interrupted run: remove it.
    run.abandon();
    throw;
  }
  return run;
}

fs::path RunDirectory::resolve(const fs::path& relative) const {
  if (committed_) throw std::logic_error("RunDirectory: write after commit()");
  const fs::path normal = relative.lexically_normal();
  if (normal.is_absolute() || normal.empty() || *normal.begin() == "..") {
    throw std::logic_error("RunDirectory: path must stay inside the run directory: " + relative.string());
  }
  return staging_ / normal;
}

void RunDirectory::write_text(const fs::path& relative, std::string_view content) const {
  const fs::path file = resolve(relative);
  if (!shadow_) write_file_atomic(file, content);
}

void RunDirectory::write_json(const fs::path& relative, const nlohmann::json& value) const {
  const fs::path file = resolve(relative);
  if (!shadow_) write_file_atomic(file, json_text(value));
}

void RunDirectory::write_csv(const fs::path& relative, const CsvWriter& csv) const {
  const fs::path file = resolve(relative);
  if (!shadow_) csv.write(file);
}

void RunDirectory::add_charts(const std::vector<ChartSection>& sections) const {
  if (shadow_) return;
  const fs::path file = resolve(kChartsFile);
  std::vector<ChartSection> all;
  std::error_code ec;
  if (fs::is_regular_file(file, ec)) all = charts_from_json(read_json_file(file), file.string());
  for (const auto& s : sections) {
    auto same = std::find_if(all.begin(), all.end(), [&](const ChartSection& a) { return a.id == s.id; });
    if (same == all.end()) {
      all.push_back(s);
    } else {
      *same = s;
    }
  }
  write_file_atomic(file, json_text(to_json(all)));
}

void RunDirectory::write_chart_svg(const fs::path& relative, const Chart& chart) const {
  if (!shadow_) write_text(relative, render_svg(chart, staging_));
}

void RunDirectory::save_checkpoint(const nlohmann::json& state) const { write_json(kCheckpointFile, state); }

std::optional<nlohmann::json> RunDirectory::load_checkpoint_here() const {
  const fs::path file = staging_ / kCheckpointFile;
  if (!exists_no_follow(file)) return std::nullopt;
  return read_json_file(file);
}

std::optional<nlohmann::json> RunDirectory::load_checkpoint() const {
  if (ranks_.size() == 1) return load_checkpoint_here();
  // The first rank reads; every rank gets its checkpoint, or its error.
  nlohmann::json outcome = {{"ok", true}};
  if (!shadow_) {
    try {
      if (auto state = load_checkpoint_here()) outcome["state"] = std::move(*state);
    } catch (const std::exception& e) {
      outcome = {{"ok", false}, {"message", e.what()}};
    }
  }
  outcome = nlohmann::json::parse(mpi::broadcast_from_root(with_valid_utf8(outcome).dump()));
  if (!outcome.at("ok").get<bool>()) throw std::runtime_error(outcome.at("message").get<std::string>());
  if (!outcome.contains("state")) return std::nullopt;
  return std::move(outcome.at("state"));
}

bool RunDirectory::resumable() const {
  return !shadow_ && !committed_ && exists_no_follow(staging_ / kConfigFile);
}

void RunDirectory::commit() {
  if (committed_) return;
  if (shadow_) {
    committed_ = true;
    scratch_.reset();
    return;
  }
  if (exists_no_follow(final_)) {
    if (!force_) {
      throw std::runtime_error(
          fmt::format("cannot commit: {} appeared while the run was going", final_.string()));
    }
    // Swap the two directories in one step, so DIR is never missing; then drop the old one.
    if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, final_.c_str(), RENAME_EXCHANGE) != 0) {
      // File systems without RENAME_EXCHANGE: move the old one aside first.
      fs::path old = final_;
      old += ".replaced";
      std::error_code ec;
      fs::remove_all(old, ec);
      fs::rename(final_, old);
      fs::rename(staging_, final_);
      fs::remove_all(old, ec);
    } else {
      std::error_code ec;
      fs::remove_all(staging_, ec);
    }
  } else {
    fs::rename(staging_, final_);
  }
  committed_ = true;
}

void RunDirectory::abandon() {
  if (shadow_) scratch_.reset();
  // An abandoned run is over: DIR is free for the next one, whatever stays of DIR.partial.
  struct ReleaseLock {
    std::shared_ptr<const Lock>& lock;
    ~ReleaseLock() { lock.reset(); }
  } release{lock_};
  if (!created_ || committed_) return;
  std::error_code ec;
  fs::remove_all(staging_, ec);
  created_ = false;
}

}  // namespace pegasus
