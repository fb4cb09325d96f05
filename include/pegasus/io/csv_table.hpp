#pragma once
// A CSV file read whole, with its cells checked when a column is asked for: what charts and reports read
// run directories' series with. Every error is an InputError naming the file (and line and column).
//
//   auto table = CsvTable::load(dir / "progress.csv");      // nullopt when the file is absent
//   const std::vector<double>& y = table->numbers("objective");
#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace pegasus {

class CsvTable {
 public:
  // nullopt when the file is absent; InputError when it is empty or a row has another number of fields than
  // the header (blank lines are skipped).
  static std::optional<CsvTable> load(const std::filesystem::path& file);

  std::string name() const { return file_.filename().string(); }
  const std::filesystem::path& file() const { return file_; }
  const std::vector<std::string>& header() const { return header_; }
  std::size_t rows() const { return rows_.size(); }
  bool has(std::string_view column) const { return index(column).has_value(); }

  // The column as numbers (empty cells and "nan" are NaN); InputError naming file:line and column for a
  // cell that is not a number, or the header for a missing column. Parsed once per column.
  const std::vector<double>& numbers(std::string_view column) const;
  // True when every cell of the column is a number (or empty); false for a missing column.
  bool numeric(std::string_view column) const;
  std::vector<std::string> texts(std::string_view column) const;
  const std::vector<std::vector<std::string>>& cells() const { return rows_; }

  // Rows grouped by the values of `keys` (joined by " "), in order of first appearance; keys the table lacks
  // are left out, so no key gives one group "" of every row. Only rows whose cells equal `where` (column ->
  // text) are kept; InputError for a `where` column the table lacks.
  std::vector<std::pair<std::string, std::vector<std::size_t>>> groups(
      const std::vector<std::string>& keys, const std::map<std::string, std::string>& where = {}) const;

 private:
  std::optional<std::size_t> index(std::string_view column) const;
  std::size_t require(std::string_view column) const;

  std::filesystem::path file_;
  std::vector<std::string> header_;
  std::vector<std::vector<std::string>> rows_;
  std::vector<std::size_t> lines_;  // the file line of each row
  mutable std::map<std::size_t, std::vector<double>> parsed_;
};

}  // namespace pegasus
