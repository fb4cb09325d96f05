#pragma once
// Reading a JSON file a user gave (an MDP, a shaping table, a policy, a model): every failure, of the file
// system or of the JSON library, becomes an InputError of one line that names the file, so no reader can
// let a library's own exception (json.exception.out_of_range.406 for `1e999`, basic_filebuf::underflow for
// a directory) reach the user, and each reader's own checks then name the field.
//
//   const nlohmann::json j = read_json_input(path, "MDP");  // "m.json: expected a readable MDP file, ..."
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace pegasus {

// The parsed file. InputError "FILE: expected a readable WHAT file, got ..." when it cannot be read (absent,
// a directory, no permission); "FILE: byte N: expected a JSON WHAT file, got ..." for a syntax error; "FILE:
// expected numbers within the range of a double, got ..." for a number too large for a double; "FILE:
// expected each key once in an object, got 'KEY' twice" (the JSON library would keep the last silently).
nlohmann::json read_json_input(const std::filesystem::path& file, std::string_view what);
// The same for text already read; `name` stands for the file in messages.
nlohmann::json parse_json_input(std::string_view text, std::string_view name, std::string_view what);

// "FILE: FIELD: expected EXPECTED, got VALUE" with VALUE as JSON text (shortened, bytes made printable):
// the one form of every JSON reader's field errors.
[[noreturn]] void json_field_error(std::string_view file, std::string_view field, std::string_view expected,
                                   const nlohmann::json& value);
// "FILE: FIELD.KEY: unknown key (did you mean 'K'?); expected one of ..." for a member of the object `j` not
// among `known` (a misspelt optional key would otherwise be ignored). FIELD empty: the top level.
void json_only_keys(const nlohmann::json& j, std::initializer_list<std::string_view> known,
                    std::string_view file, std::string_view field);
// The member `name` of the object `j`: "FILE: FIELD: missing" when it is absent.
const nlohmann::json& json_member(const nlohmann::json& j, const char* name, std::string_view file,
                                  std::string_view field);
// A finite number: "FILE: FIELD: expected a number, got VALUE" (or "a finite number") otherwise.
double json_finite_number(const nlohmann::json& j, std::string_view file, std::string_view field);

// The header of a file the project writes: j is an object whose "format" is `format` and whose "version"
// is `version`; `made_by` (when given) tells the user which file that is ("policy.json of `pegasus ...`").
void json_format_header(const nlohmann::json& j, std::string_view file, std::string_view format, int version,
                        std::string_view made_by = {});

// The other field readers every JSON reader uses, so that each field error has json_field_error's form.
// A number in [lo, hi] ((lo, hi] when open_lo).
double json_number_in(const nlohmann::json& j, std::string_view file, std::string_view field, double lo,
                      double hi, bool open_lo = false);
// An integer in [lo, hi].
long long json_integer(const nlohmann::json& j, std::string_view file, std::string_view field, long long lo,
                       long long hi);
// An index into something of `count` elements: an integer in [0, count), "a WHAT in [0, COUNT)" otherwise.
int json_index(const nlohmann::json& j, std::string_view file, std::string_view field, int count,
               std::string_view what);
bool json_flag(const nlohmann::json& j, std::string_view file, std::string_view field);
std::string json_nonempty_string(const nlohmann::json& j, std::string_view file, std::string_view field);
// An array of finite numbers; of exactly `size` when size > 0.
std::vector<double> json_finite_numbers(const nlohmann::json& j, std::string_view file,
                                        std::string_view field, std::size_t size = 0);
// Optional members of an object: the fallback when `name` is absent, the checked value otherwise.
double json_number_or(const nlohmann::json& object, const char* name, double fallback, std::string_view file,
                      std::string_view field);
bool json_flag_or(const nlohmann::json& object, const char* name, bool fallback, std::string_view file,
                  std::string_view field);

}  // namespace pegasus
