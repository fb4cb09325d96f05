#pragma once
// A command's configuration, declared once: every field has a name, a type, a default, a range or
// validator and a one-line help. Values come from the defaults, then a TOML file, then command-line
// overrides (later sources win); every value is checked when it is set, so a bad one is reported before
// any work starts, naming where it came from (`config.toml:3: key 'gamma': ...` or `--gamma: ...`).
// The resolved configuration is written back as TOML (with the help as comments) and loads back to
// exactly the same values (doubles round-trip bit for bit).
//
//   ConfigSchema s;
//   s.add_double("gamma", 0.99, "discount factor").range(0, 1);
//   s.add_int("scenarios", 30, "number of scenarios m").min(1);
//   s.add_string("variant", "plain", "scenario variant").choices({"plain", "antithetic"});
//   s.add_int_list("sizes", {1, 2, 4}, "scenario counts to sweep").min(1).min_size(1);
//   s.load_toml_file("run.toml");          // InputError naming file:line and key
//   s.set_from_cli("sizes", "1,2,8");      // InputError naming --sizes
//   double gamma = s.get_double("gamma");
//
// Field names are snake_case; a dotted name `section.key` lives in the TOML table [section] and becomes
// the option `--section.key`. All errors on user input are InputError with a one-line message; asking for
// an undeclared field or the wrong type is a programming error (std::logic_error).
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "pegasus/core/error.hpp"
#include "pegasus/core/number_setting.hpp"
#include "pegasus/io/json_csv.hpp"

namespace pegasus {

enum class FieldType { kInt, kDouble, kBool, kString, kIntList, kDoubleList, kStringList };

using FieldValue = std::variant<std::int64_t, double, bool, std::string, std::vector<std::int64_t>,
                                std::vector<double>, std::vector<std::string>>;

// Bad input about one config field that only a run can find (a set point under a vehicle's ground). Its
// message is "FIELD: what"; the command framework names the field as the user set it, as validation does:
// "--target: ...", "run.toml:3: key 'target': ...", "V.toml: hover.target: ...".
class ConfigFieldError : public InputError {
 public:
  ConfigFieldError(const std::string& field, const std::string& what)
      : InputError(field + ": " + what), field_(field), what_(what) {}
  const std::string& field() const { return field_; }
  const std::string& detail() const { return what_; }  // the message without the field

 private:
  std::string field_, what_;
};

// One declared field. Built through ConfigSchema::add_*; the chainable setters constrain it.
class ConfigField {
 public:
  // Returns an empty string when `value` is acceptable, else what was expected ("a prime number").
  using Validator = std::function<std::string(const FieldValue& value)>;

  ConfigField(std::string name, FieldType type, FieldValue default_value, std::string help);

  // Inclusive bounds for numbers, and for every element of a list.
  ConfigField& min(double lo);
  ConfigField& max(double hi);
  ConfigField& range(double lo, double hi) { return min(lo).max(hi); }
  // Exclusive bounds: greater_than(0) means (0, ...).
  ConfigField& greater_than(double lo);
  ConfigField& less_than(double hi);
  // The bounds a described setting states: (lower or [lower, and upper].
  ConfigField& bounds(const NumberSetting& setting);
  // Allowed values of a string field.
  ConfigField& choices(std::vector<std::string> allowed);
  // Smallest number of elements of a list.
  ConfigField& min_size(std::size_t n);
  // Exactly n elements ("a list of 3 numbers"), as a fixed-length setting (a NumberList) has.
  ConfigField& size(std::size_t n);
  // A custom check on top of the above.
  ConfigField& validate(Validator check);
  // Fields that cannot change a result (e.g. `threads`) may differ when a run is resumed.
  ConfigField& affects_results(bool yes);
  // A string field (or each string of a list) naming a file whose bytes shape the results (a log, a model, a
  // vehicle file): --resume refuses to continue when the file's contents changed since the run began
  // (RunDirectory: inputs.json). `digest` stands for the file's SHA-256 where more than its own bytes shape
  // the results (an MJCF model and the files it includes); it may throw InputError for a file the command
  // will refuse anyway.
  using Digest = std::function<std::string(const std::string& file)>;
  ConfigField& input_file(Digest digest = {});

  const std::string& name() const { return name_; }
  FieldType type() const { return type_; }
  const std::string& help() const { return help_; }
  const FieldValue& default_value() const { return default_; }
  const std::vector<std::string>& allowed_choices() const { return choices_; }
  bool affects_results() const { return affects_results_; }
  bool is_input_file() const { return input_file_; }
  const Digest& input_digest() const { return input_digest_; }  // empty: the file's own SHA-256
  // "a number in [0, 1]", "an integer >= 1", "one of \"plain\", \"antithetic\"", ...
  std::string expectation() const;
  bool has_upper_bound() const { return hi_.has_value(); }
  // Empty when `value` (already of this field's type) is acceptable, else what was expected.
  std::string check(const FieldValue& value) const;

 private:
  struct Bound {
    double value;
    bool inclusive;
  };
  bool in_bounds(double x) const;

  std::string name_;
  FieldType type_;
  FieldValue default_;
  std::string help_;
  std::optional<Bound> lo_, hi_;
  std::vector<std::string> choices_;
  std::size_t min_size_ = 0;
  bool exact_size_ = false;  // size(): min_size_ elements, no more
  std::vector<Validator> validators_;
  bool affects_results_ = true;
  bool input_file_ = false;
  Digest input_digest_;
};

class ConfigSchema {
 public:
  // A check across several fields, run by validate(); returns an empty string or a one-line message
  // (use origin(name) to say where an offending value came from).
  using Constraint = std::function<std::string(const ConfigSchema&)>;

  ConfigField& add_int(std::string name, std::int64_t default_value, std::string help);
  ConfigField& add_double(std::string name, double default_value, std::string help);
  ConfigField& add_bool(std::string name, bool default_value, std::string help);
  ConfigField& add_string(std::string name, std::string default_value, std::string help);
  ConfigField& add_int_list(std::string name, std::vector<std::int64_t> default_value, std::string help);
  ConfigField& add_double_list(std::string name, std::vector<double> default_value, std::string help);
  // On the command line its strings are separated by commas ("a.csv,b.csv"); in TOML, an array of strings.
  ConfigField& add_string_list(std::string name, std::vector<std::string> default_value, std::string help);
  void add_constraint(Constraint constraint);

  // Reads a TOML file over the current values. Unknown keys, wrong types and out-of-range values are
  // InputError "file:line: key 'name': expected ..., got ..."; an unreadable file names the file. The
  // fields named in `overridden` (set on the command line after the file) keep their values: the file's
  // are only type-checked, so that an option can replace a file's value that is out of range.
  void load_toml_file(const std::filesystem::path& file, const std::vector<std::string>& overridden = {});
  // Same, from text; `source_name` stands for the file in messages.
  void load_toml_string(std::string_view text, const std::string& source_name,
                        const std::vector<std::string>& overridden = {});
  // Settings a program gives by name (call_command; Python's keyword arguments), as TOML text read as a file
  // is, with messages that name the setting and `caller` instead of a line the caller never wrote: "CALLER:
  // setting 'name': expected ..., got ...", "CALLER: unknown setting 'name' (did you mean ...?)".
  void load_settings(std::string_view toml_text, const std::string& caller);
  // Sets one field from its command-line text ("0.9", "1,2,4", "true"); errors name `--field-name`.
  void set_from_cli(std::string_view name, std::string_view text);
  // Sets one field directly (checked like any other value; errors name the field, or `origin` when given,
  // which origin() then reports).
  void set(std::string_view name, FieldValue value, const std::string& origin = {});
  // Runs the cross-field constraints. Values are checked one by one when they are set.
  void validate() const;

  // The resolved configuration as TOML: every field, its help as a comment, values exact.
  std::string to_toml() const;
  nlohmann::json to_json() const;

  // The same fields, all back at their defaults.
  ConfigSchema with_defaults() const;
  // The first field that affects results whose value differs from `other`'s, or nullopt.
  std::optional<std::string> first_difference(const ConfigSchema& other) const;

  bool has(std::string_view name) const { return find(name) != nullptr; }
  const std::deque<ConfigField>& fields() const { return fields_; }
  const ConfigField& field(std::string_view name) const;
  const FieldValue& value(std::string_view name) const;
  // Where the current value came from: "default", "config.toml:3" or "--gamma".
  const std::string& origin(std::string_view name) const;
  // How an error names the field as the user set it, as the checks of its value do: its name at the
  // default, "config.toml:3: key 'gamma'", "--gamma", or the origin given to set() ("V.toml: hover.target").
  const std::string& where(std::string_view name) const;

  std::int64_t get_int(std::string_view name) const;
  double get_double(std::string_view name) const;
  bool get_bool(std::string_view name) const;
  const std::string& get_string(std::string_view name) const;
  const std::vector<std::int64_t>& get_int_list(std::string_view name) const;
  const std::vector<double>& get_double_list(std::string_view name) const;
  const std::vector<std::string>& get_string_list(std::string_view name) const;

  // The file a string field (or each string of a list field) names, for the code that opens it: a relative
  // value is relative to the base directory when one is set (a pipeline's run directory, whose stages name
  // each other's files relative to it: `identify/model.json`), else to the working directory, as given. The
  // value itself, what config.toml records, stays as given; an empty value stays empty.
  std::string get_path(std::string_view name) const;
  std::vector<std::string> get_path_list(std::string_view name) const;
  // The folder relative values of file fields are relative to (empty: the working directory).
  void set_base_directory(std::filesystem::path base) { base_directory_ = std::move(base); }
  const std::filesystem::path& base_directory() const { return base_directory_; }

  // `section.some_key` -> `--section.some-key`.
  static std::string option_name(std::string_view field_name);
  // A value as it is written in TOML (and in messages): 0.1, 3, true, "plain", [1, 2].
  static std::string format_value(const FieldValue& value);

 private:
  ConfigField& add(std::string name, FieldType type, FieldValue default_value, std::string help);
  const ConfigField* find(std::string_view name) const;
  std::size_t index_of(std::string_view name) const;
  void assign(std::size_t index, FieldValue value, const std::string& where, const std::string& got);
  // load_toml_string and load_settings: messages name a file and line (`lines`) or the caller and setting.
  void load_toml(std::string_view text, const std::string& source_name,
                 const std::vector<std::string>& overridden, bool lines);

  std::deque<ConfigField> fields_;  // a deque: add_* returns references that stay valid
  std::vector<FieldValue> values_;
  std::vector<std::string> origins_;
  std::vector<std::string> wheres_;  // where(), beside origins_
  std::vector<Constraint> constraints_;
  std::filesystem::path base_directory_;
};

// `file` (a value of a file field) as the code opening it finds it from `base` (empty: as given), and back:
// a path under `base` named relative to it again, any other as it is. Used by ConfigSchema::get_path and
// by RunSink::named, which names a file in a summary or a printed line as a config names it.
std::string path_under(const std::filesystem::path& base, const std::string& file);
std::string path_named_from(const std::filesystem::path& base, const std::string& path);

// For a settings struct whose VisitFields offers `setting(NumberSetting, &Options::member)` for each number
// (core/number_setting.hpp): each as an option KEY with the default's value, its bounds, and its help after
// `prefix` (only the one named `only` where given), its key after `key_prefix` (a section's
// "bandwidth_floor."); and each the schema declares read into its member.
namespace detail {
template <class Options>
struct DeclareNumbers {
  ConfigSchema& s;
  const Options& defaults;
  std::string_view only;
  const std::string& prefix;
  const std::string& key_prefix;
  template <class T>
  void setting(const NumberSetting& n, T Options::*member) {
    if (!only.empty() && only != n.key) return;
    if constexpr (NumberList<T>) {
      const T& d = defaults.*member;
      std::vector<double> values;
      for (decltype(d.size()) i = 0; i < d.size(); ++i) values.push_back(d[i]);
      s.add_double_list(key_prefix + n.key, values, prefix + n.help).bounds(n).size(values.size());
    } else if constexpr (std::is_integral_v<T>)
      s.add_int(key_prefix + n.key, defaults.*member, prefix + n.help).bounds(n);
    else
      s.add_double(key_prefix + n.key, defaults.*member, prefix + n.help).bounds(n);
  }
};
template <class Options>
struct ReadNumbers {
  const ConfigSchema& c;
  Options& o;
  const std::string& key_prefix;
  template <class T>
  void setting(const NumberSetting& n, T Options::*member) {
    const std::string key = key_prefix + n.key;
    if (!c.has(key)) return;  // a command that declares some of them (log import's identification)
    if constexpr (NumberList<T>) {
      const std::vector<double>& list = c.get_double_list(key);  // its length checked by size()
      for (std::size_t i = 0; i < list.size(); ++i)
        (o.*member)[static_cast<decltype((o.*member).size())>(i)] = list[i];
    } else if constexpr (std::is_integral_v<T>)
      o.*member = static_cast<T>(c.get_int(key));
    else
      o.*member = c.get_double(key);
  }
};
// The same for the switches of a struct's VisitFlags (core/number_setting.hpp: FlagSetting).
template <class Options>
struct DeclareFlags {
  ConfigSchema& s;
  const Options& defaults;
  void flag(const FlagSetting& f, bool Options::*member) { s.add_bool(f.key, defaults.*member, f.help); }
};
template <class Options>
struct ReadFlags {
  const ConfigSchema& c;
  Options& o;
  void flag(const FlagSetting& f, bool Options::*member) { o.*member = c.get_bool(f.key); }
};
}  // namespace detail

template <class Options>
void declare_numbers(ConfigSchema& s, const Options& defaults, std::string_view only = {},
                     const std::string& prefix = {}, const std::string& key_prefix = {}) {
  detail::DeclareNumbers<Options> v{s, defaults, only, prefix, key_prefix};
  Options::VisitFields(v);
}
template <class Options>
void read_numbers(const ConfigSchema& c, Options& o, const std::string& key_prefix = {}) {
  detail::ReadNumbers<Options> v{c, o, key_prefix};
  Options::VisitFields(v);
}
template <class Options>
void declare_flags(ConfigSchema& s, const Options& defaults) {
  detail::DeclareFlags<Options> v{s, defaults};
  Options::VisitFlags(v);
}
template <class Options>
void read_flags(const ConfigSchema& c, Options& o) {
  detail::ReadFlags<Options> v{c, o};
  Options::VisitFlags(v);
}

}  // namespace pegasus
