// The hover reward's typical sizes, described once (HoverReward::VisitFields, issue 49 item 1): each size
// reaches `hover`'s option reward.KEY, a vehicle file's [hover.reward] KEY and the weight it names
// (alpha = 1 / size^2), a size of 0 is taken exactly where the description allows it, and each option is
// refused beside reward.judged_cost in one line. A size added to the description is walked here too.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "logs/outside_aircraft.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/runs/heli_config.hpp"
#include "pegasus/heli/vehicle_file.hpp"
#include "support/cli_runner.hpp"
#include "support/input_error.hpp"

namespace pegasus::heli {
namespace {

using test_support::input_error_message;

// Every element of the field `name` of r, read through the description.
struct FieldReader {
  const HoverReward& r;
  std::string name;
  std::vector<double> out;
  void read(double x) { out = {x}; }
  template <std::size_t N>
  void read(const std::array<double, N>& a) {
    out.assign(a.begin(), a.end());
  }
  template <class T>
  void size(const HoverRewardSize& s, T HoverReward::*member, const char*) {
    if (name == s.field) read(r.*member);
  }
  template <class T>
  void weight(const char* field_name, T HoverReward::*member, const char*) {
    if (name == field_name) read(r.*member);
  }
  template <class T>
  void field(const char* field_name, T HoverReward::*member, const char*) {
    if (name == field_name) read(r.*member);
  }
};
std::vector<double> weight_of(const HoverReward& r, const std::string& field) {
  FieldReader reader{r, field, {}};
  HoverReward::VisitFields(reader);
  return reader.out;
}

ConfigSchema hover_schema() {
  ConfigSchema s;
  declare_hover_config(s);
  return s;
}

std::string option_of(const HoverRewardSize& size) { return std::string("reward.") + size.key; }

class HoverRewardConfig : public test_support::TempDirTest {
 protected:
  // A vehicle file (the outside helicopter) with `more` appended; its path.
  std::string vehicle(const std::string& name, const std::string& more) const {
    const std::filesystem::path file = dir_ / name;
    std::ofstream(file) << test_support::kOutsideVehicle << "\n" << more;
    return file.string();
  }
};

TEST_F(HoverRewardConfig, EverySizeIsAnOptionWithItsDefaultAndHelpReadAsOneOverItsSquare) {
  ASSERT_GE(HoverReward::sizes().size(), 6u);
  for (const HoverRewardSize& size : HoverReward::sizes()) {
    SCOPED_TRACE(size.key);
    ConfigSchema s = hover_schema();
    const ConfigField& f = s.field(option_of(size));
    EXPECT_EQ(std::get<double>(f.default_value()), size.typical);
    EXPECT_EQ(f.help(), size.help);
    s.set(option_of(size), 0.25, "--" + option_of(size));
    s.validate();
    const HoverReward r = read_hover_config(s, 7).training.reward;
    for (const double w : weight_of(r, size.field)) EXPECT_EQ(w, 16.0);
    // The other sizes keep their defaults' weights.
    for (const HoverRewardSize& other : HoverReward::sizes()) {
      if (std::string(other.key) == size.key) continue;
      for (const double w : weight_of(r, other.field))
        EXPECT_EQ(w, HoverReward::weight_of_typical(other.typical)) << other.key;
    }
  }
}

TEST_F(HoverRewardConfig, ASizeOfZeroLeavesATermOutOnlyWhereTheDescriptionAllowsIt) {
  int zero_allowed = 0;
  for (const HoverRewardSize& size : HoverReward::sizes()) {
    SCOPED_TRACE(size.key);
    ConfigSchema s = hover_schema();
    if (size.may_be_zero) {
      ++zero_allowed;
      s.set(option_of(size), 0.0, "--" + option_of(size));
      s.validate();
      for (const double w : weight_of(read_hover_config(s, 7).training.reward, size.field)) EXPECT_EQ(w, 0.0);
    } else {
      const std::string message = input_error_message([&] { s.set(option_of(size), 0.0); });
      EXPECT_NE(message.find(option_of(size)), std::string::npos) << message;
      EXPECT_NE(message.find(">= 1e-06"), std::string::npos) << message;
    }
    // Between 0 and the least size: refused either way (its weight would pass the largest).
    EXPECT_NE(input_error_message([&] { s.set(option_of(size), 1e-7); }), "(no error)");
  }
  EXPECT_GE(zero_allowed, 3);  // the action, attitude and rate terms at least
}

TEST_F(HoverRewardConfig, AVehicleFilesSizeReachesItsWeightAndZeroOnlyWhereAllowed) {
  for (const HoverRewardSize& size : HoverReward::sizes()) {
    SCOPED_TRACE(size.key);
    const std::string file = vehicle("v.toml", fmt::format("[hover.reward]\n{} = 0.5\n", size.key));
    const logs::Vehicle v = logs::read_vehicle(file);
    ASSERT_EQ(v.reward.size(), 1u);
    EXPECT_EQ(v.reward[0], (std::pair<std::string, double>(size.key, 0.5)));
    ConfigSchema s = hover_schema();
    s.set("vehicle", file, "--vehicle");
    resolve_hover_config(s);
    s.validate();
    EXPECT_EQ(s.origin(option_of(size)), file + ": hover.reward." + size.key);
    for (const double w : weight_of(read_hover_config(s, 7).training.reward, size.field)) EXPECT_EQ(w, 4.0);

    const std::string zero = vehicle("zero.toml", fmt::format("[hover.reward]\n{} = 0\n", size.key));
    const std::string message = input_error_message([&] { (void)logs::read_vehicle(zero); });
    if (size.may_be_zero)
      EXPECT_EQ(message, "(no error)");
    else
      EXPECT_NE(message.find(fmt::format("hover.reward.{}: expected a typical size of at least 1e-06, got 0",
                                         size.key)),
                std::string::npos)
          << message;
  }
}

TEST_F(HoverRewardConfig, EverySizeIsRefusedBesideTheJudgedCostInOneLine) {
  const std::string file = vehicle("cost.toml", "[cost]\nposition = [1, 1, 2]\ncrash = 1000\n");
  for (const HoverRewardSize& size : HoverReward::sizes()) {
    SCOPED_TRACE(size.key);
    ConfigSchema s = hover_schema();
    s.set("vehicle", file, "--vehicle");
    s.set(option_of(size), 0.5, "--reward.x");
    resolve_hover_config(s);
    s.validate();
    EXPECT_TRUE(s.get_bool("reward.judged_cost"));
    const std::string message = input_error_message([&] { (void)read_hover_config(s, 7); });
    EXPECT_EQ(message, option_of(size) +
                           " (--reward.x): the vehicle file's [cost] is the whole reward; expected no "
                           "reward.* option with it (or reward.judged_cost = false)");
  }
}

// The manual's row for [hover.reward] (docs/reference/vehicle-file.md) as the description makes it: every
// key, in order, and the terms a size of 0 leaves out.
std::string vehicle_page_row() {
  std::string keys, optional;
  std::vector<std::string> zero;
  for (const HoverRewardSize& size : HoverReward::sizes()) {
    keys += fmt::format("{}`{}`", keys.empty() ? "" : ", ", size.key);
    if (size.may_be_zero) zero.emplace_back(std::string(size.key).substr(0, std::string(size.key).find('_')));
  }
  for (std::size_t i = 0; i < zero.size(); ++i)
    optional += (i == 0 ? "" : i + 1 == zero.size() ? " or " : ", ") + zero[i];
  return fmt::format(
      "| `[hover.reward]` {} | the reward's typical sizes (alpha = 1 / size^2; 0 leaves the {} term out), to "
      "match the cost the aircraft is judged by: `hover --reward.*` |",
      keys, optional);
}

TEST_F(HoverRewardConfig, TheVehicleFilePageListsEverySize) {
  std::ifstream page(std::filesystem::path(PEGASUS_SOURCE_DIR) / "docs/reference/vehicle-file.md");
  const std::string row = vehicle_page_row();
  bool found = false;
  for (std::string line; std::getline(page, line);) found = found || line == row;
  EXPECT_TRUE(found) << "docs/reference/vehicle-file.md has no line\n" << row;
}

}  // namespace
}  // namespace pegasus::heli
