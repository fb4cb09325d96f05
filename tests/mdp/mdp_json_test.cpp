#include "pegasus/mdp/mdp_json.hpp"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "pegasus/core/error.hpp"
#include "pegasus/envs/flags.hpp"
#include "pegasus/mdp/random_mdp.hpp"
#include "support/input_error.hpp"

namespace pegasus {

using test_support::input_error_message;
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

void expect_same(const FiniteMdp& a, const FiniteMdp& b) {
  EXPECT_EQ(a.num_states, b.num_states);
  EXPECT_EQ(a.num_actions, b.num_actions);
  EXPECT_EQ(a.gamma, b.gamma);
  EXPECT_EQ(a.row_start, b.row_start);
  EXPECT_EQ(a.next_state, b.next_state);
  EXPECT_EQ(a.probability, b.probability);  // bit-exact: shortest round-trip decimals
  EXPECT_EQ(a.reward, b.reward);
  EXPECT_EQ(a.expected_reward, b.expected_reward);
  EXPECT_EQ(a.absorbing, b.absorbing);
  EXPECT_EQ(a.initial, b.initial);
}

json small_mdp_json() {
  return json::parse(R"({
    "format": "pegasus-mdp", "version": 1, "num_states": 3, "num_actions": 2, "gamma": 0.9,
    "absorbing": [2], "initial": [[0, 1.0]], "state_rewards": [1, 0, 0],
    "transitions": [
      {"state": 0, "action": 0, "reward": -1, "next": [[1, 0.8], [0, 0.2, 5.0]]},
      {"state": 0, "action": 1, "next": [[2, 1.0]]},
      {"state": 1, "action": 0, "next": [[2, 1.0]]},
      {"state": 1, "action": 1, "next": [[0, 0.5], [1, 0.5]]}
    ]})");
}

TEST(MdpJson, ReadsAllThreeRewardForms) {
  const FiniteMdp m = mdp_from_json(small_mdp_json(), "small.json");
  // R(0, 0, 1) = R(s) + R(s, a) = 1 - 1; R(0, 0, 0) = 1 - 1 + 5.
  EXPECT_DOUBLE_EQ(m.expected_reward[m.row(0, 0)], 0.8 * 0.0 + 0.2 * 5.0);
  EXPECT_DOUBLE_EQ(m.expected_reward[m.row(0, 1)], 1.0);
  EXPECT_TRUE(m.is_absorbing(2));
  EXPECT_EQ(m.initial[0], 1.0);
}

TEST(MdpJson, RoundTripsRandomMdpsAndGridworldsExactly) {
  UniformStream rng(3, 0);
  const auto dir = std::filesystem::temp_directory_path() / "pegasus_mdp_json_test";
  std::filesystem::create_directories(dir);
  for (int i = 0; i < 20; ++i) {
    RandomMdpOptions o;
    o.num_states = 2 + i;
    o.num_actions = 1 + i % 3;
    o.successors = 1 + i % 4;
    o.gamma = i % 2 ? 1.0 : 0.37;
    const FiniteMdp m = random_mdp(o, rng);
    const std::string path = (dir / fmt::format("m{}.json", i)).string();
    save_mdp(m, path);
    expect_same(load_mdp(path), m);
  }
  const FiniteMdp flags = to_finite_mdp(flags_5x5());
  expect_same(mdp_from_json(mdp_to_json(flags)), flags);
  std::filesystem::remove_all(dir);
}

TEST(MdpJson, ErrorsNameTheFileAndTheField) {
  auto with = [](const std::function<void(json&)>& edit) {
    json j = small_mdp_json();
    edit(j);
    return input_error_message([&] { mdp_from_json(j, "m.json"); });
  };
  EXPECT_THAT(with([](json& j) { j["format"] = "other"; }),
              HasSubstr("m.json: format: expected \"pegasus-mdp\""));
  EXPECT_THAT(with([](json& j) { j.erase("gamma"); }), HasSubstr("m.json: gamma: missing"));
  EXPECT_THAT(with([](json& j) { j["gamma"] = 1.5; }),
              HasSubstr("m.json: gamma: expected a number in [0, 1], got 1.5"));
  EXPECT_THAT(with([](json& j) { j["num_states"] = "three"; }),
              HasSubstr("m.json: num_states: expected an integer in [1, 2147483647], got \"three\""));
  EXPECT_THAT(with([](json& j) { j["transitions"][1]["next"][0][1] = 1.2; }),
              HasSubstr("m.json: transitions[1].next[0][1]: expected a number in [0, 1], got 1.2"));
  EXPECT_THAT(with([](json& j) { j["transitions"][0]["next"][0][1] = 0.7; }),
              HasSubstr("m.json: transitions[0].next: probabilities sum to 0.9"));
  EXPECT_THAT(with([](json& j) { j["transitions"][2]["next"][0][0] = 9; }),
              HasSubstr("m.json: transitions[2].next[0][0]: expected a successor in [0, 3), got 9"));
  EXPECT_THAT(with([](json& j) { j["transitions"].erase(3); }),
              HasSubstr("m.json: transitions: no entry for state 1 action 1"));
  EXPECT_THAT(with([](json& j) { j["transitions"].push_back(j["transitions"][0]); }),
              HasSubstr("m.json: transitions[4]: state 0 action 0 given twice"));
  EXPECT_THAT(with([](json& j) { j["absorbing"] = json::array({7}); }),
              HasSubstr("m.json: absorbing[0]: expected a state in [0, 3), got 7"));
  EXPECT_THAT(with([](json& j) {
                j["initial"] = json::array({json::array({0, 0.5})});
              }),
              HasSubstr("m.json: initial distribution sums to 0.5"));
  // gamma = 1 with a policy that loops forever between 0 and 1 (action 1 of state 1, action 0 of state 0
  // kept).
  EXPECT_THAT(with([](json& j) {
                j["gamma"] = 1.0;
                j["transitions"][0]["next"] = json::array({json::array({1, 1.0})});
              }),
              HasSubstr("m.json: gamma = 1 requires a proper MDP"));
  EXPECT_THAT(
      input_error_message([] { load_mdp("/nonexistent/m.json"); }),
      HasSubstr("/nonexistent/m.json: expected a readable MDP file, got 'No such file or directory'"));
  const auto bad = std::filesystem::temp_directory_path() / "pegasus_bad_mdp.json";
  std::ofstream(bad) << "{ not json";
  EXPECT_THAT(input_error_message([&] { load_mdp(bad.string()); }), HasSubstr("expected a JSON MDP file"));
  // A misspelt key would be ignored (a reward of 0), a key given twice would keep its last value: both
  // refused.
  EXPECT_THAT(with([](json& j) { j["transitions"][0]["rewrd"] = -1; }),
              HasSubstr("m.json: transitions[0].rewrd: unknown key (did you mean 'reward'?); expected one of "
                        "state, action, reward, next"));
  EXPECT_THAT(with([](json& j) { j["discount"] = 0.9; }),
              HasSubstr("m.json: discount: unknown key; expected one of"));
  std::string twice = mdp_to_json(mdp_from_json(small_mdp_json(), "m.json")).dump();
  twice.insert(1, "\"gamma\": 0.5, ");
  std::ofstream(bad, std::ios::trunc) << twice;
  EXPECT_EQ(input_error_message([&] { load_mdp(bad.string()); }),
            bad.string() + ": expected each key once in an object, got 'gamma' twice");
  std::filesystem::remove(bad);
}

}  // namespace
}  // namespace pegasus
