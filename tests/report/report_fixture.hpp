#pragma once
// What the report's tests share (report_test.cpp: the page and its data; report_command_test.cpp: bad run
// directories, the bundle, and `pegasus report`): the fixture, a run's files, and the page's embedded data.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pegasus/io/json_csv.hpp"
#include "pegasus/report/report.hpp"
#include "pegasus/runs/charts.hpp"
#include "support/cli_runner.hpp"

namespace report_test {

namespace fs = std::filesystem;
using json = nlohmann::json;
using pegasus::test_support::read_text;

inline constexpr const char* kFakeBundle = "window.pegasusFakeBundle = 1; /* bundle */";

inline void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

// The bytes of base64 text.
inline std::string from_base64(const std::string& text) {
  const std::string alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned bits = 0;
  int count = 0;
  for (char c : text) {
    const auto v = alphabet.find(c);
    if (v == std::string::npos) continue;  // '=' padding
    bits = (bits << 6) | static_cast<unsigned>(v);
    if ((count += 6) >= 8) {
      count -= 8;
      out += static_cast<char>((bits >> count) & 0xff);
    }
  }
  return out;
}

// The text of gzip-compressed bytes.
inline std::string gunzip(const std::string& bytes) {
  z_stream z{};
  EXPECT_EQ(inflateInit2(&z, 15 + 16), Z_OK);
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  z.avail_in = static_cast<uInt>(bytes.size());
  std::string out;
  char buffer[65536];
  int status = Z_OK;
  while (status == Z_OK) {
    z.next_out = reinterpret_cast<Bytef*>(buffer);
    z.avail_out = sizeof buffer;
    status = inflate(&z, Z_NO_FLUSH);
    out.append(buffer, sizeof buffer - z.avail_out);
  }
  inflateEnd(&z);
  EXPECT_EQ(status, Z_STREAM_END);
  return out;
}

// The JSON block of a report page (gzip-compressed, base64-encoded).
inline json embedded_data(const std::string& html) {
  const std::string open =
      "<script type=\"application/gzip\" id=\"pegasus-data\" data-encoding=\"gzip+base64\">";
  const auto begin = html.find(open);
  EXPECT_NE(begin, std::string::npos);
  const auto start = begin + open.size();
  const auto end = html.find("</script>", start);
  return json::parse(gunzip(from_base64(html.substr(start, end - start))));
}

inline const json& chart_from(const json& data, const std::string& source,
                              const std::string& title_part = "") {
  for (const auto& c : data["charts"]) {
    if (c.value("source", "") == source && c.value("title", "").find(title_part) != std::string::npos)
      return c;
  }
  static const json none;
  ADD_FAILURE() << "no chart from " << source << " titled *" << title_part << "*";
  return none;
}

inline std::vector<double> doubles(const json& a) {
  std::vector<double> out;
  for (const auto& v : a) out.push_back(v.is_null() ? std::nan("") : v.get<double>());
  return out;
}

inline std::vector<double> column(const fs::path& csv, std::size_t c) {
  const auto rows = pegasus::parse_csv(read_text(csv));
  std::vector<double> out;
  for (std::size_t r = 1; r < rows.size(); ++r) out.push_back(std::stod(rows[r][c]));
  return out;
}

class Report : public pegasus::test_support::TempDirTest {
 protected:
  fs::path run_ = dir_ / "run";
  void SetUp() override {
    TempDirTest::SetUp();
    run_ = dir_ / "run";
    write(run_ / "summary.json",
          R"({"experiment": "shaping-gridworld", "runs": 3, "optimal_expected_steps": 22.0,
                                     "nested": {"a": 0.1}})");
    write(run_ / "config.toml", "# the resolved configuration\nsize = 10\n");
  }
  std::string render() const { return pegasus::report::render_report(run_, kFakeBundle); }
};

// The run's charts.json, written as commands write it.
inline void describe(const fs::path& run, const std::vector<pegasus::ChartSection>& sections) {
  write(run / "charts.json", pegasus::to_json(sections).dump());
}

inline pegasus::ChartSection one_chart(pegasus::Chart chart, std::string id = "s") {
  return {.id = std::move(id), .title = "Section", .intro = "intro", .charts = {std::move(chart)}};
}
}  // namespace report_test
