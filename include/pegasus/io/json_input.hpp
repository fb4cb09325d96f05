#pragma once
// Reading a JSON file a user gave (an MDP, a shaping table, a policy, a model): every failure, of the file
// system or of the JSON library, becomes an InputError of one line that names the file, so no reader can
// let a library's own exception (json.exception.out_of_range.406 for `1e999`, basic_filebuf::underflow for
// a directory) reach the user, and each reader's own checks then name the field.
//
//   const nlohmann::json j = read_json_input(path, "MDP");  // "m.json: expected a readable MDP file, ..."
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string_view>

namespace pegasus {

// The parsed file. InputError "FILE: expected a readable WHAT file, got ..." when it cannot be read (absent,
// a directory, no permission); "FILE: byte N: expected a JSON WHAT file, got ..." for a syntax error; "FILE:
// expected numbers within the range of a double, got ..." for a number too large for a double.
nlohmann::json read_json_input(const std::filesystem::path& file, std::string_view what);
// The same for text already read; `name` stands for the file in messages.
nlohmann::json parse_json_input(std::string_view text, std::string_view name, std::string_view what);

// "FILE: FIELD: expected EXPECTED, got VALUE" with VALUE as JSON text (shortened, bytes made printable):
// the one form of every JSON reader's field errors.
[[noreturn]] void json_field_error(std::string_view file, std::string_view field, std::string_view expected,
                                   const nlohmann::json& value);
// The member `name` of the object `j`: "FILE: FIELD: missing" when it is absent.
const nlohmann::json& json_member(const nlohmann::json& j, const char* name, std::string_view file,
                                  std::string_view field);
// A finite number: "FILE: FIELD: expected a number, got VALUE" (or "a finite number") otherwise.
double json_finite_number(const nlohmann::json& j, std::string_view file, std::string_view field);

}  // namespace pegasus
