#pragma once
// What the config's two files (config.cpp: the schema and its TOML; config_field.cpp: one field's checks)
// share; internal to src/runs.
#include <string>
#include <string_view>

#include "pegasus/runs/config.hpp"

namespace pegasus::detail {

bool is_number_type(FieldType t);
bool is_int_type(FieldType t);
// A TOML basic string holding `raw`: TOML holds only UTF-8, so other bytes (a path named `m\xff.json`) are
// stored as the text \xNN, so that config.toml always loads again.
std::string toml_quoted(std::string_view raw);

}  // namespace pegasus::detail
