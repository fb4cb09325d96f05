#pragma once
// Result files of a run: JSON (summary.json) and CSV series, with doubles written so that they read back
// to exactly the same bits (shortest round-trip text: 0.1 is written "0.1", not "0.10000000000000001").
//
//   CsvWriter csv({"m", "mean", "stderr"});
//   csv.add_row({std::int64_t{8}, 0.25, 0.01});
//   run_dir.write_csv("error_vs_m.csv", csv);
//
// JSON cannot hold NaN or infinities (nlohmann writes them as null); put such values in as strings.
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace pegasus {

// Parses a double exactly as written (shortest round-trip text reads back to the same bits); nullopt if
// `text` is not entirely a number.
std::optional<double> parse_double(std::string_view text);
std::optional<std::int64_t> parse_int(std::string_view text);
// Shortest text that reads back to exactly `x` ("0.1", "1e-300", "inf").
std::string format_double(double x);

// A finite number, or null for NaN and infinities (JSON has neither): for summary fields that may be
// undefined (a median of no rides, a time to a bar never reached).
nlohmann::json number_or_null(double x);

// Pretty-printed JSON text with a final newline; doubles round-trip exactly.
std::string json_text(const nlohmann::json& value);
// Parses a JSON file; std::runtime_error naming the file on failure.
nlohmann::json read_json_file(const std::filesystem::path& file);
// Text made safe inside markup (SVG, HTML) elements and quoted attributes: & < > " ' escaped.
std::string escape_markup(std::string_view text);

using CsvCell = std::variant<std::int64_t, double, std::string>;

// A table with a fixed header. Cells are integers, doubles (shortest exact text, "nan", "inf") or strings
// (quoted when they contain a comma, quote or line break, RFC 4180).
class CsvWriter {
 public:
  explicit CsvWriter(std::vector<std::string> header);

  // Throws std::logic_error when the row does not have one cell per column.
  CsvWriter& add_row(std::vector<CsvCell> row);

  const std::vector<std::string>& header() const { return header_; }
  std::size_t rows() const { return rows_; }
  std::string str() const { return text_; }
  // Writes atomically (write_file_atomic).
  void write(const std::filesystem::path& file) const;

 private:
  std::vector<std::string> header_;
  std::string text_;
  std::size_t rows_ = 0;
};

// Splits CSV text written by CsvWriter (or any RFC 4180 CSV) into rows of fields.
std::vector<std::vector<std::string>> parse_csv(const std::string& text);

}  // namespace pegasus
