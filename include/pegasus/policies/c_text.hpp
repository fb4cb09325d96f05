#pragma once
// The C text of a policy class: what the C export (codegen/c_policy.hpp) assembles into a header and a
// source, and the helpers that write C from C++ values. A policy class writes its own text beside its
// controller and registers both once (heli/policy_file.hpp: register_policy_class); codegen/ finds it there.
#include <fmt/format.h>

#include <cctype>
#include <string>
#include <utility>
#include <vector>

namespace pegasus::codegen {

// Text from the user's files (paths, the vehicle's names) as it may stand inside a C comment: printable
// ASCII, with "*/" and "/*" broken apart, so that no name can end the comment early or open a nested one
// (which -Werror=comment refuses).
inline std::string comment_text(const std::string& text) {
  std::string s;
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    const char kept = u >= 0x20 && u < 0x7f ? c : '_';
    if (!s.empty() && ((s.back() == '*' && kept == '/') || (s.back() == '/' && kept == '*'))) s += ' ';
    s += kept;
  }
  return s;
}

// A double as a C99 hexadecimal literal: exact, so the C reads the very bits the C++ holds.
inline std::string c_double(double x) { return fmt::format("{:a}", x); }

// `static const double NAME[n] = {...};` with each value's name and decimal value in a comment.
inline std::string c_table(const std::string& name, const std::vector<double>& values,
                           const std::vector<std::string>& names) {
  std::string s = fmt::format("static const double {}[{}] = {{\n", name, values.size());
  for (std::size_t i = 0; i < values.size(); ++i)
    s += fmt::format("    {},{} /* {}: {} */\n", c_double(values[i]), i + 1 < values.size() ? "" : " ",
                     i < names.size() ? comment_text(names[i]) : fmt::format("[{}]", i), values[i]);
  return s + "};\n";
}

inline std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Replaces every "@NAME@" of `text` by its value.
inline std::string fill(std::string text, const std::vector<std::pair<std::string, std::string>>& values) {
  for (const auto& [key, value] : values) {
    const std::string token = "@" + key + "@";
    for (std::size_t at = text.find(token); at != std::string::npos; at = text.find(token, at + value.size()))
      text.replace(at, token.size(), value);
  }
  return text;
}

inline std::string column_list(const std::vector<std::string>& names, const std::vector<std::string>& units) {
  std::string s;
  for (std::size_t i = 0; i < names.size(); ++i)
    s += fmt::format(" *   [{:2}] {:<11} {}\n", i, comment_text(names[i]), i < units.size() ? units[i] : "");
  return s;
}

struct ClassText {
  std::string class_name, description, safe;
  std::vector<std::string> observation_names, observation_units, action_names, action_units;
  std::string extra_declarations;  // more prototypes for the header
  std::string body;                // the source after its #include lines
  bool has_target = false;
  bool has_memory = false;  // PREFIX_memory, PREFIX_reset, and a memory argument first in PREFIX_act
};

// The parameters of PREFIX_act (and PREFIX_act_vehicle), and the memory argument to pass on.
inline std::string act_parameters(const ClassText& t) {
  return t.has_memory ? "@NAME@_memory* memory, const double* observation, double* action"
                      : "const double* observation, double* action";
}

}  // namespace pegasus::codegen
