#include "pegasus/io/csv_table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"

namespace pegasus {

namespace fs = std::filesystem;

std::optional<CsvTable> CsvTable::load(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return std::nullopt;
  CsvTable s;
  s.file_ = file;
  std::string text;
  try {
    text = read_file(file);
  } catch (const std::exception& e) {
    throw InputError(e.what());
  }
  auto rows = parse_csv(text);
  if (rows.empty())
    throw InputError(fmt::format("{}: empty file, expected a CSV header line", file.string()));
  s.header_ = std::move(rows.front());
  for (std::size_t i = 1; i < rows.size(); ++i) {
    if (rows[i].size() == 1 && rows[i][0].empty()) continue;  // a blank line
    if (rows[i].size() != s.header_.size()) {
      throw InputError(fmt::format("{}:{}: expected {} fields (as in the header), got {}", file.string(),
                                   i + 1, s.header_.size(), rows[i].size()));
    }
    s.lines_.push_back(i + 1);
    s.rows_.push_back(std::move(rows[i]));
  }
  return s;
}

const std::vector<double>& CsvTable::numbers(std::string_view column) const {
  const std::size_t c = require(column);
  if (auto it = parsed_.find(c); it != parsed_.end()) return it->second;
  std::vector<double> out;
  out.reserve(rows_.size());
  for (std::size_t i = 0; i < rows_.size(); ++i) {
    const std::string& cell = rows_[i][c];
    if (cell.empty()) {
      out.push_back(std::nan(""));
      continue;
    }
    const auto x = parse_double(cell);
    if (!x) {
      throw InputError(fmt::format("{}:{}: column '{}': expected a number, got '{}'", file_.string(),
                                   lines_[i], column, cell));
    }
    out.push_back(*x);
  }
  return parsed_.emplace(c, std::move(out)).first->second;
}

bool CsvTable::numeric(std::string_view column) const {
  const auto c = index(column);
  if (!c) return false;
  return std::all_of(rows_.begin(), rows_.end(),
                     [&](const auto& row) { return row[*c].empty() || parse_double(row[*c]).has_value(); });
}

std::vector<std::string> CsvTable::texts(std::string_view column) const {
  const std::size_t c = require(column);
  std::vector<std::string> out;
  out.reserve(rows_.size());
  for (const auto& row : rows_) out.push_back(row[c]);
  return out;
}

std::vector<std::pair<std::string, std::vector<std::size_t>>> CsvTable::groups(
    const std::vector<std::string>& keys, const std::map<std::string, std::string>& where) const {
  std::vector<std::size_t> columns;
  for (const auto& k : keys) {
    if (auto c = index(k)) columns.push_back(*c);
  }
  std::vector<std::pair<std::size_t, std::string>> filters;
  for (const auto& [column, value] : where) filters.emplace_back(require(column), value);
  std::vector<std::pair<std::string, std::vector<std::size_t>>> out;
  std::map<std::string, std::size_t> group_of;
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    if (!std::all_of(filters.begin(), filters.end(),
                     [&](const auto& f) { return rows_[r][f.first] == f.second; }))
      continue;
    std::string key;
    for (std::size_t c : columns) key += (key.empty() ? "" : " ") + rows_[r][c];
    auto [it, fresh] = group_of.try_emplace(key, out.size());
    if (fresh) out.push_back({key, {}});
    out[it->second].second.push_back(r);
  }
  return out;
}

std::optional<std::size_t> CsvTable::index(std::string_view column) const {
  for (std::size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == column) return i;
  }
  return std::nullopt;
}

std::size_t CsvTable::require(std::string_view column) const {
  if (auto i = index(column)) return *i;
  std::string columns;
  for (const auto& h : header_) columns += (columns.empty() ? "" : ",") + h;
  throw InputError(fmt::format("{}: expected a column '{}' (header: {})", file_.string(), column, columns));
}

}  // namespace pegasus
