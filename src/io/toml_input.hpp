#pragma once
// Reading a TOML file a user gave (a run config, a vehicle file, a MuJoCo task): what json_input is for JSON.
// Every failure becomes one InputError line naming the file (and the line where there is one), and the text
// is checked for UTF-8 before toml++ sees it: Debian's toml++ 3.3.0 reads past the end of its buffer on some
// invalid UTF-8 (fixed upstream later). Private to the libraries (toml++ is not a public dependency).
#include <toml++/toml.h>

#include <filesystem>
#include <string_view>

namespace pegasus {

// The parsed text; `name` stands for the file in messages: "NAME:LINE: expected UTF-8 text, got the byte
// 0xFF", "NAME:LINE: invalid TOML: ...".
toml::table parse_toml_input(std::string_view text, std::string_view name);
// The same for a file: "FILE: expected a readable WHAT file, got ..." when it cannot be read (absent, a
// directory, no permission).
toml::table read_toml_input(const std::filesystem::path& file, std::string_view what);

}  // namespace pegasus
