#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <random>

#include "pegasus/io/atomic_file.hpp"
#include "pegasus/io/json_csv.hpp"

namespace pegasus {
namespace {

std::vector<double> awkward_doubles() {
  std::vector<double> xs = {0.1,  1.0 / 3.0, -2.5e-310, 5e-324,       1.7976931348623157e308,
                            -0.0, 0.0,       1e22,      123456789.125};
  std::mt19937_64 bits(7);
  while (xs.size() < 500) {
    const double x = std::bit_cast<double>(bits());
    if (std::isfinite(x)) xs.push_back(x);
  }
  return xs;
}

TEST(CsvWriter, DoublesReadBackBitForBit) {
  CsvWriter csv({"i", "x", "label"});
  const auto xs = awkward_doubles();
  for (std::size_t i = 0; i < xs.size(); ++i)
    csv.add_row({static_cast<std::int64_t>(i), xs[i], std::string("p")});
  const auto rows = parse_csv(csv.str());
  ASSERT_EQ(rows.size(), xs.size() + 1);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"i", "x", "label"}));
  for (std::size_t i = 0; i < xs.size(); ++i) {
    const double back = std::strtod(rows[i + 1][1].c_str(), nullptr);
    ASSERT_EQ(std::bit_cast<std::uint64_t>(back), std::bit_cast<std::uint64_t>(xs[i])) << rows[i + 1][1];
  }
  EXPECT_EQ(rows[1][1], "0.1");  // shortest text, not 0.10000000000000001
}

TEST(CsvWriter, QuotesFieldsThatNeedIt) {
  CsvWriter csv({"name", "value"});
  csv.add_row({std::string("a, \"b\"\nc"), std::numeric_limits<double>::infinity()});
  csv.add_row({std::string("plain"), std::nan("")});
  EXPECT_EQ(csv.str(), "name,value\n\"a, \"\"b\"\"\nc\",inf\nplain,nan\n");
  const auto rows = parse_csv(csv.str());
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[1][0], "a, \"b\"\nc");
  EXPECT_EQ(csv.rows(), 2u);
}

TEST(CsvWriter, RowOfTheWrongLengthIsALogicError) {
  CsvWriter csv({"a", "b"});
  EXPECT_THROW(csv.add_row({1.0}), std::logic_error);
  EXPECT_THROW(CsvWriter({}), std::logic_error);
}

TEST(JsonOutput, DoublesReadBackBitForBit) {
  const auto xs = awkward_doubles();
  const nlohmann::json j = {{"xs", xs}, {"name", "run"}};
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("pegasus_json_" + std::to_string(::getpid()) + ".json");
  write_file_atomic(file, json_text(j));
  const auto back = read_json_file(file)["xs"].get<std::vector<double>>();
  std::filesystem::remove(file);
  ASSERT_EQ(back.size(), xs.size());
  for (std::size_t i = 0; i < xs.size(); ++i) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(back[i]), std::bit_cast<std::uint64_t>(xs[i])) << xs[i];
  }
  EXPECT_NE(json_text(j).find("0.1,"), std::string::npos);
}

TEST(JsonOutput, UnreadableOrInvalidFileNamesTheFile) {
  EXPECT_THROW(read_json_file("/nonexistent/summary.json"), std::runtime_error);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("pegasus_badjson_" + std::to_string(::getpid()) + ".json");
  write_file_atomic(file, "{oops");
  try {
    read_json_file(file);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(file.string() + ": invalid JSON", 0), 0u);
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace pegasus

TEST(EscapeMarkup, EscapesEveryMarkupCharacterAndNothingElse) {
  EXPECT_EQ(pegasus::escape_markup("a<b> & \"c\" 'd' \u00e9"),
            "a&lt;b&gt; &amp; &quot;c&quot; &#39;d&#39; \u00e9");
  EXPECT_EQ(pegasus::escape_markup(""), "");
}
