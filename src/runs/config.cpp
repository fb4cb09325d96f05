#include "pegasus/runs/config.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "../io/toml_fields.hpp"
#include "config_values.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/core/untrusted_text.hpp"
#include "pegasus/io/atomic_file.hpp"

namespace pegasus {

namespace detail {

bool is_number_type(FieldType t) {
  return t == FieldType::kInt || t == FieldType::kDouble || t == FieldType::kIntList ||
         t == FieldType::kDoubleList;
}

bool is_int_type(FieldType t) { return t == FieldType::kInt || t == FieldType::kIntList; }

// TOML holds only UTF-8: other bytes (a path named `m\xff.json`) are stored as the text \xNN, so that
// config.toml always loads again; same_value compares strings in this stored form.
std::string toml_quoted(std::string_view raw) {
  const std::string s = with_invalid_bytes_escaped(raw);
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
          out += fmt::format("\\u{:04X}", static_cast<unsigned>(static_cast<unsigned char>(c)));
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

}  // namespace detail

namespace {

using detail::toml_quoted;

bool valid_field_name(std::string_view name) {
  bool segment_start = true;
  for (char c : name) {
    if (segment_start) {
      if (c < 'a' || c > 'z') return false;
      segment_start = false;
    } else if (c == '.') {
      segment_start = true;
    } else if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) {
      return false;
    }
  }
  return !name.empty() && !segment_start;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// A double as a TOML float: always with a '.', an exponent, or inf/nan, so it reads back as a float.
std::string toml_double(double x) {
  std::string s = format_double(x);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

bool same_value(const FieldValue& a, const FieldValue& b) {
  if (a.index() != b.index()) return false;
  // Doubles compare by bits: -0.0 and 0.0 may give different results.
  if (const double* x = std::get_if<double>(&a)) {
    return std::bit_cast<std::uint64_t>(*x) == std::bit_cast<std::uint64_t>(std::get<double>(b));
  }
  if (const auto* xs = std::get_if<std::vector<double>>(&a)) {
    const auto& ys = std::get<std::vector<double>>(b);
    return std::equal(xs->begin(), xs->end(), ys.begin(), ys.end(), [](double x, double y) {
      return std::bit_cast<std::uint64_t>(x) == std::bit_cast<std::uint64_t>(y);
    });
  }
  if (const auto* x = std::get_if<std::string>(&a)) {
    return with_invalid_bytes_escaped(*x) == with_invalid_bytes_escaped(std::get<std::string>(b));
  }
  if (const auto* xs = std::get_if<std::vector<std::string>>(&a)) {
    const auto& ys = std::get<std::vector<std::string>>(b);
    return std::equal(xs->begin(), xs->end(), ys.begin(), ys.end(),
                      [](const std::string& x, const std::string& y) {
                        return with_invalid_bytes_escaped(x) == with_invalid_bytes_escaped(y);
                      });
  }
  return a == b;
}

const char* type_name(FieldType t) {
  switch (t) {
    case FieldType::kInt:
      return "int";
    case FieldType::kDouble:
      return "double";
    case FieldType::kBool:
      return "bool";
    case FieldType::kString:
      return "string";
    case FieldType::kIntList:
      return "int list";
    case FieldType::kDoubleList:
      return "double list";
    case FieldType::kStringList:
      return "string list";
  }
  return "?";
}

// What a TOML node holds, for "got ..." in messages.
std::string describe(const toml::node& node) {
  if (const auto* s = node.as_string()) return "the string " + toml_quoted(s->get());
  if (const auto* i = node.as_integer()) return std::to_string(i->get());
  if (const auto* d = node.as_floating_point()) {
    // "the float 1.0", not "1": the message explains why an integer field refused it.
    const std::string text = format_double(d->get());
    const bool looks_integral = text.find_first_of(".eEna") == std::string::npos;
    return "the float " + text + (looks_integral ? ".0" : "");
  }
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  if (node.is_array()) return "an array";
  if (node.is_table()) return "a table";
  return "a date/time";
}

// A TOML array as a list of T, each element converted by `element`; nullopt when any does not fit.
template <class T, class Element>
std::optional<FieldValue> list_from_toml(const toml::node& node, Element element) {
  const auto* array = node.as_array();
  if (array == nullptr) return std::nullopt;
  std::vector<T> out;
  for (const auto& e : *array) {
    std::optional<T> x = element(e);
    if (!x) return std::nullopt;
    out.push_back(std::move(*x));
  }
  return FieldValue{std::move(out)};
}

// Converts a TOML node to a value of type `t`; nullopt when the TOML type does not fit.
std::optional<FieldValue> from_toml(const toml::node& node, FieldType t) {
  switch (t) {
    case FieldType::kInt:
      if (const auto* i = node.as_integer()) return FieldValue{i->get()};
      return std::nullopt;
    case FieldType::kDouble:
      if (const auto* d = node.as_floating_point()) return FieldValue{d->get()};
      if (const auto* i = node.as_integer()) return FieldValue{static_cast<double>(i->get())};
      return std::nullopt;
    case FieldType::kBool:
      if (const auto* b = node.as_boolean()) return FieldValue{b->get()};
      return std::nullopt;
    case FieldType::kString:
      if (const auto* s = node.as_string()) return FieldValue{s->get()};
      return std::nullopt;
    case FieldType::kIntList:
      return list_from_toml<std::int64_t>(node, [](const toml::node& e) -> std::optional<std::int64_t> {
        if (const auto* i = e.as_integer()) return i->get();
        return std::nullopt;
      });
    case FieldType::kDoubleList:
      return list_from_toml<double>(node, [](const toml::node& e) -> std::optional<double> {
        if (const auto* d = e.as_floating_point()) return d->get();
        if (const auto* i = e.as_integer()) return static_cast<double>(i->get());
        return std::nullopt;
      });
    case FieldType::kStringList:
      return list_from_toml<std::string>(node, [](const toml::node& e) -> std::optional<std::string> {
        if (const auto* s = e.as_string()) return s->get();
        return std::nullopt;
      });
  }
  return std::nullopt;
}

std::optional<bool> parse_bool(std::string_view text) {
  std::string s(trim(text));
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  if (s == "true" || s == "1" || s == "yes" || s == "on") return true;
  if (s == "false" || s == "0" || s == "no" || s == "off") return false;
  return std::nullopt;
}

template <class T, class Parse>
std::optional<std::vector<T>> parse_list(std::string_view text, Parse parse) {
  text = trim(text);
  if (text.size() >= 2 && text.front() == '[' && text.back() == ']')
    text = trim(text.substr(1, text.size() - 2));
  std::vector<T> out;
  if (text.empty()) return out;
  while (true) {
    std::size_t comma = text.find(',');
    std::optional<T> element = parse(text.substr(0, comma));
    if (!element) return std::nullopt;
    out.push_back(*element);
    if (comma == std::string_view::npos) break;
    text.remove_prefix(comma + 1);
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// ConfigSchema

ConfigField& ConfigSchema::add(std::string name, FieldType type, FieldValue default_value, std::string help) {
  if (!valid_field_name(name)) throw std::logic_error("config field name is not snake_case: " + name);
  for (const auto& f : fields_) {
    const std::string& other = f.name();
    auto nests = [](const std::string& outer, const std::string& inner) {
      return inner.size() > outer.size() && inner.compare(0, outer.size(), outer) == 0 &&
             inner[outer.size()] == '.';
    };
    if (other == name || nests(other, name) || nests(name, other)) {
      throw std::logic_error("config field declared twice or nested in another: " + name);
    }
  }
  fields_.emplace_back(std::move(name), type, default_value, std::move(help));
  values_.push_back(std::move(default_value));
  origins_.emplace_back("default");
  wheres_.push_back(fields_.back().name());
  return fields_.back();
}

ConfigField& ConfigSchema::add_int(std::string name, std::int64_t default_value, std::string help) {
  return add(std::move(name), FieldType::kInt, default_value, std::move(help));
}
ConfigField& ConfigSchema::add_double(std::string name, double default_value, std::string help) {
  return add(std::move(name), FieldType::kDouble, default_value, std::move(help));
}
ConfigField& ConfigSchema::add_bool(std::string name, bool default_value, std::string help) {
  return add(std::move(name), FieldType::kBool, default_value, std::move(help));
}
ConfigField& ConfigSchema::add_string(std::string name, std::string default_value, std::string help) {
  return add(std::move(name), FieldType::kString, std::move(default_value), std::move(help));
}
ConfigField& ConfigSchema::add_int_list(std::string name, std::vector<std::int64_t> default_value,
                                        std::string help) {
  return add(std::move(name), FieldType::kIntList, std::move(default_value), std::move(help));
}
ConfigField& ConfigSchema::add_double_list(std::string name, std::vector<double> default_value,
                                           std::string help) {
  return add(std::move(name), FieldType::kDoubleList, std::move(default_value), std::move(help));
}
ConfigField& ConfigSchema::add_string_list(std::string name, std::vector<std::string> default_value,
                                           std::string help) {
  return add(std::move(name), FieldType::kStringList, std::move(default_value), std::move(help));
}
void ConfigSchema::add_constraint(Constraint constraint) { constraints_.push_back(std::move(constraint)); }

const ConfigField* ConfigSchema::find(std::string_view name) const {
  for (const auto& f : fields_) {
    if (f.name() == name) return &f;
  }
  return nullptr;
}

std::size_t ConfigSchema::index_of(std::string_view name) const {
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    if (fields_[i].name() == name) return i;
  }
  throw std::logic_error("no config field named '" + std::string(name) + "'");
}

const ConfigField& ConfigSchema::field(std::string_view name) const { return fields_[index_of(name)]; }
const FieldValue& ConfigSchema::value(std::string_view name) const { return values_[index_of(name)]; }
const std::string& ConfigSchema::origin(std::string_view name) const { return origins_[index_of(name)]; }
const std::string& ConfigSchema::where(std::string_view name) const { return wheres_[index_of(name)]; }

void ConfigSchema::assign(std::size_t index, FieldValue value, const std::string& where,
                          const std::string& got) {
  std::string expected = fields_[index].check(value);
  if (!expected.empty()) throw InputError(fmt::format("{}: expected {}, got {}", where, expected, got));
  values_[index] = std::move(value);
}

void ConfigSchema::load_toml_file(const std::filesystem::path& file,
                                  const std::vector<std::string>& overridden) {
  std::string text;
  try {
    text = read_file(file, kMaxSettingsFileBytes);
  } catch (const std::exception& e) {
    const std::string reason = read_failure_reason(e);
    throw InputError(fmt::format("{}: cannot read config file: {}", file.string(), reason));
  }
  load_toml_string(text, file.string(), overridden);
}

void ConfigSchema::load_toml_string(std::string_view text, const std::string& source_name,
                                    const std::vector<std::string>& overridden) {
  load_toml(text, source_name, overridden, true);
}

void ConfigSchema::load_settings(std::string_view toml_text, const std::string& caller) {
  load_toml(toml_text, caller, {}, false);
}

void ConfigSchema::load_toml(std::string_view text, const std::string& source_name,
                             const std::vector<std::string>& overridden, bool lines) {
  const toml::table root = parse_toml_input(text, source_name);

  auto unknown = [&](const std::string& full, const toml::key& key) {
    std::string hint;
    std::size_t best = std::string::npos;
    for (const auto& f : fields_) {
      std::size_t d = edit_distance(full, f.name());
      if (d <= std::max<std::size_t>(2, full.size() / 3) && d < best) {
        best = d;
        hint = fmt::format(" (did you mean '{}'?)", f.name());
      }
    }
    if (hint.empty()) {
      hint = " (known keys:";
      for (std::size_t i = 0; i < fields_.size(); ++i) hint += (i ? ", " : " ") + fields_[i].name();
      hint += ")";
    }
    if (!lines)
      throw InputError(fmt::format("{}: unknown setting '{}'{}", source_name, printable(full), hint));
    throw InputError(fmt::format("{}:{}: unknown key '{}'{}", printable(source_name), key.source().begin.line,
                                 printable(full), hint));
  };

  std::function<void(const toml::table&, const std::string&)> walk = [&](const toml::table& table,
                                                                         const std::string& prefix) {
    for (const auto& [key, node] : table) {
      const std::string full =
          prefix.empty() ? std::string(key.str()) : prefix + "." + std::string(key.str());
      const ConfigField* f = find(full);
      if (f == nullptr) {
        const bool is_section = std::any_of(fields_.begin(), fields_.end(), [&](const ConfigField& g) {
          return g.name().size() > full.size() && g.name().compare(0, full.size(), full) == 0 &&
                 g.name()[full.size()] == '.';
        });
        if (is_section && node.is_table()) {
          walk(*node.as_table(), full);
          continue;
        }
        unknown(full, key);
      }
      std::size_t index = index_of(full);
      const auto line = node.source().begin.line != 0 ? node.source().begin.line : key.source().begin.line;
      const std::string where = lines ? fmt::format("{}:{}: key '{}'", source_name, line, full)
                                      : fmt::format("{}: setting '{}'", source_name, full);
      std::optional<FieldValue> value = from_toml(node, f->type());
      if (!value)
        throw InputError(fmt::format("{}: expected {}, got {}", where, f->expectation(), describe(node)));
      if (std::find(overridden.begin(), overridden.end(), full) != overridden.end()) continue;
      // Formatted before the move: the order in which a call's arguments are evaluated is unspecified
      // (GCC happened to format first, clang moves first).
      const std::string got = format_value(*value);
      assign(index, std::move(*value), where, got);
      origins_[index] =
          lines ? fmt::format("{}:{}", source_name, line) : fmt::format("{}: {}", source_name, full);
      wheres_[index] = where;
    }
  };
  walk(root, "");
}

void ConfigSchema::set_from_cli(std::string_view name, std::string_view text) {
  const std::size_t index = index_of(name);
  const ConfigField& f = fields_[index];
  const std::string where = option_name(name);
  const std::string got = text.empty() ? "an empty value" : "'" + std::string(text) + "'";
  std::optional<FieldValue> value;
  switch (f.type()) {
    case FieldType::kInt:
      if (auto x = parse_int(text)) value = *x;
      break;
    case FieldType::kDouble:
      if (auto x = parse_double(text)) value = *x;
      break;
    case FieldType::kBool:
      if (auto x = parse_bool(text)) value = *x;
      break;
    case FieldType::kString:
      value = std::string(text);
      break;
    case FieldType::kIntList:
      if (auto x = parse_list<std::int64_t>(text, parse_int)) value = std::move(*x);
      break;
    case FieldType::kDoubleList:
      if (auto x = parse_list<double>(text, parse_double)) value = std::move(*x);
      break;
    case FieldType::kStringList: {
      // "a.csv, b.csv" means two files, the second without its space; an empty string is refused.
      const auto element = [](std::string_view s) -> std::optional<std::string> {
        s = trim(s);
        if (s.empty()) return std::nullopt;
        return std::string(s);
      };
      if (auto x = parse_list<std::string>(text, element)) value = std::move(*x);
      break;
    }
  }
  if (!value) {
    std::string expected = f.expectation();
    // An integer beyond 64 bits: say where integers end when the field's own bound does not.
    const std::string_view digits = text.substr(!text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0);
    if (f.type() == FieldType::kInt && !f.has_upper_bound() && !digits.empty() &&
        digits.find_first_not_of("0123456789") == std::string_view::npos)
      expected += fmt::format(" and at most {}", std::numeric_limits<std::int64_t>::max());
    throw InputError(fmt::format("{}: expected {}, got {}", where, expected, got));
  }
  assign(index, std::move(*value), where, got);
  origins_[index] = where;
  wheres_[index] = where;
}

void ConfigSchema::set(std::string_view name, FieldValue value, const std::string& origin) {
  const std::size_t index = index_of(name);
  if (value.index() != fields_[index].default_value().index()) {
    throw std::logic_error(fmt::format("config field '{}' is a {}", name, type_name(fields_[index].type())));
  }
  const std::string got = format_value(value);
  const std::string where = origin.empty() ? std::string(name) : origin;
  assign(index, std::move(value), where, got);
  origins_[index] = where;
  wheres_[index] = where;
}

void ConfigSchema::validate() const {
  for (const auto& constraint : constraints_) {
    std::string message = constraint(*this);
    if (!message.empty()) throw InputError(message);
  }
}

std::string ConfigSchema::format_value(const FieldValue& value) {
  struct Visitor {
    std::string operator()(std::int64_t x) const { return std::to_string(x); }
    std::string operator()(double x) const { return toml_double(x); }
    std::string operator()(bool x) const { return x ? "true" : "false"; }
    std::string operator()(const std::string& x) const { return toml_quoted(x); }
    std::string operator()(const std::vector<std::int64_t>& xs) const {
      std::string out = "[";
      for (std::size_t i = 0; i < xs.size(); ++i) out += (i ? ", " : "") + std::to_string(xs[i]);
      return out + "]";
    }
    std::string operator()(const std::vector<double>& xs) const {
      std::string out = "[";
      for (std::size_t i = 0; i < xs.size(); ++i) out += (i ? ", " : "") + toml_double(xs[i]);
      return out + "]";
    }
    std::string operator()(const std::vector<std::string>& xs) const {
      std::string out = "[";
      for (std::size_t i = 0; i < xs.size(); ++i) out += (i ? ", " : "") + toml_quoted(xs[i]);
      return out + "]";
    }
  };
  return std::visit(Visitor{}, value);
}

std::string ConfigSchema::option_name(std::string_view field_name) {
  std::string out = "--";
  for (char c : field_name) out += c == '_' ? '-' : c;
  return out;
}

std::string ConfigSchema::to_toml() const {
  // Top-level keys first (TOML puts every key after a [table] header into that table), then one table per
  // section in order of first declaration.
  std::vector<std::string> sections;
  auto section_of = [](const std::string& name) {
    std::size_t dot = name.rfind('.');
    return dot == std::string::npos ? std::string() : name.substr(0, dot);
  };
  sections.emplace_back();
  for (const auto& f : fields_) {
    std::string s = section_of(f.name());
    if (std::find(sections.begin(), sections.end(), s) == sections.end()) sections.push_back(s);
  }
  std::string out = "# Resolved configuration (defaults, then config file, then command line).\n";
  for (const auto& section : sections) {
    bool header_written = section.empty();
    for (std::size_t i = 0; i < fields_.size(); ++i) {
      if (section_of(fields_[i].name()) != section) continue;
      if (!header_written) {
        out += fmt::format("\n[{}]\n", section);
        header_written = true;
      }
      const std::string key =
          section.empty() ? fields_[i].name() : fields_[i].name().substr(section.size() + 1);
      out += fmt::format("\n# {} [{}]\n{} = {}\n", fields_[i].help(), fields_[i].expectation(), key,
                         format_value(values_[i]));
    }
  }
  return out;
}

nlohmann::json ConfigSchema::to_json() const {
  nlohmann::json out = nlohmann::json::object();
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    nlohmann::json* node = &out;
    std::string_view name = fields_[i].name();
    for (std::size_t dot; (dot = name.find('.')) != std::string_view::npos; name.remove_prefix(dot + 1)) {
      node = &(*node)[std::string(name.substr(0, dot))];
    }
    std::visit([&](const auto& v) { (*node)[std::string(name)] = v; }, values_[i]);
  }
  return out;
}

ConfigSchema ConfigSchema::with_defaults() const {
  ConfigSchema copy = *this;
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    copy.values_[i] = fields_[i].default_value();
    copy.origins_[i] = "default";
    copy.wheres_[i] = fields_[i].name();
  }
  return copy;
}

std::optional<std::string> ConfigSchema::first_difference(const ConfigSchema& other) const {
  for (std::size_t i = 0; i < fields_.size(); ++i) {
    if (!fields_[i].affects_results()) continue;
    const ConfigField* g = other.find(fields_[i].name());
    if (g == nullptr || !same_value(values_[i], other.values_[other.index_of(g->name())]))
      return fields_[i].name();
  }
  for (const auto& g : other.fields_) {
    if (g.affects_results() && find(g.name()) == nullptr) return g.name();
  }
  return std::nullopt;
}

template <class T>
static const T& get_as(const std::vector<FieldValue>& values, const std::deque<ConfigField>& fields,
                       std::size_t index) {
  const T* x = std::get_if<T>(&values[index]);
  if (x == nullptr) {
    throw std::logic_error(
        fmt::format("config field '{}' is a {}", fields[index].name(), type_name(fields[index].type())));
  }
  return *x;
}

std::int64_t ConfigSchema::get_int(std::string_view name) const {
  return get_as<std::int64_t>(values_, fields_, index_of(name));
}
double ConfigSchema::get_double(std::string_view name) const {
  return get_as<double>(values_, fields_, index_of(name));
}
bool ConfigSchema::get_bool(std::string_view name) const {
  return get_as<bool>(values_, fields_, index_of(name));
}
const std::string& ConfigSchema::get_string(std::string_view name) const {
  return get_as<std::string>(values_, fields_, index_of(name));
}
const std::vector<std::int64_t>& ConfigSchema::get_int_list(std::string_view name) const {
  return get_as<std::vector<std::int64_t>>(values_, fields_, index_of(name));
}
const std::vector<double>& ConfigSchema::get_double_list(std::string_view name) const {
  return get_as<std::vector<double>>(values_, fields_, index_of(name));
}
const std::vector<std::string>& ConfigSchema::get_string_list(std::string_view name) const {
  return get_as<std::vector<std::string>>(values_, fields_, index_of(name));
}

}  // namespace pegasus
