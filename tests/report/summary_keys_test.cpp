// The summary.json key table (include/pegasus/report/summary_keys.hpp): keys are listed as the report
// flattens a summary, patterns with placeholders match per-output and per-horizon keys, and a key the table
// lacks is reported.
#include "pegasus/report/summary_keys.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

namespace {

using json = nlohmann::json;
using pegasus::report::describe_summary_key;
using pegasus::report::undescribed_summary_keys;

std::vector<std::string> listed(const json& summary) {
  std::vector<std::string> keys;
  pegasus::report::visit_summary_keys(summary,
                                      [&](const std::vector<std::string>& path, const json&, bool scalar) {
                                        std::string key;
                                        for (const auto& p : path) key += (key.empty() ? "" : ".") + p;
                                        keys.push_back(key + (scalar ? "" : " (structure)"));
                                      });
  return keys;
}

TEST(SummaryKeys, KeysAreListedAsTheReportFlattensThem) {
  const json summary = {{"a", 1},
                        {"b", {{"c", 2.5}, {"d", {{"e", 1}}}, {"short", {1, 2}}}},
                        {"long", {1, 2, 3, 4, 5, 6, 7}},
                        {"rows", json::array({json{{"x", 1}}})},
                        {"none", nullptr}};
  EXPECT_EQ(listed(summary), (std::vector<std::string>{"a", "b.c", "b.d (structure)", "b.short",
                                                       "long (structure)", "none", "rows (structure)"}));
}

TEST(SummaryKeys, PlaceholdersStandForOneComponentOrPartOfOne) {
  // A horizon such as "0.5" is one component, dots and all.
  const auto* by_horizon = describe_summary_key("heli identify", {"outside_2sigma_by_horizon", "0.5"});
  ASSERT_NE(by_horizon, nullptr);
  EXPECT_EQ(by_horizon->pattern, "outside_2sigma_by_horizon.<seconds>");
  EXPECT_EQ(describe_summary_key("heli identify", {"outside_2sigma_by_horizon", "0.5", "x"}), nullptr);
  const auto* ablation = describe_summary_key("heli maneuver", {"rms_path_deviation_no_delay_m"});
  ASSERT_NE(ablation, nullptr);
  EXPECT_EQ(ablation->unit, "m");
  EXPECT_EQ(describe_summary_key("heli maneuver", {"rms_path_deviation__m"}), nullptr);  // not empty
  // The vehicle commands without the heli prefix share the heli commands' keys.
  const auto* rms = describe_summary_key("fly", {"pilot", "rms_position_m"});
  ASSERT_NE(rms, nullptr);
  EXPECT_EQ(rms->unit, "m");
  // A key is described for the commands that write it only.
  EXPECT_EQ(describe_summary_key("horizon", {"rms_position_m"}), nullptr);
  EXPECT_EQ(describe_summary_key("no such command", {"horizon"}), nullptr);
}

TEST(SummaryKeys, AKeyTheTableLacksIsReported) {
  const json fly = {{"flights", 30},         {"crashes", 0},
                    {"rms_position_m", 0.4}, {"pilot", {{"flights", 30}, {"rms_position_m", 0.7}}},
                    {"new_figure", 1},       {"better_than_pilot", {{"position", true}, {"altitude", true}}}};
  EXPECT_EQ(undescribed_summary_keys("heli fly", fly),
            (std::vector<std::string>{"better_than_pilot.altitude", "new_figure"}));
  EXPECT_EQ(undescribed_summary_keys("horizon", json{{"horizon", 51}}), std::vector<std::string>{});
}

TEST(SummaryKeys, EveryEntryHasAMeaningAndEachCommandOneGroup) {
  std::set<std::string> commands;
  for (const auto& group : pegasus::report::summary_key_groups()) {
    for (const auto command : group.commands)
      EXPECT_TRUE(commands.insert(std::string(command)).second) << command << " has two groups";
    std::set<std::string_view> patterns;
    for (const auto& key : group.keys) {
      EXPECT_FALSE(key.meaning.empty()) << key.pattern;
      EXPECT_TRUE(patterns.insert(key.pattern).second) << key.pattern << " twice";
    }
  }
}

}  // namespace
