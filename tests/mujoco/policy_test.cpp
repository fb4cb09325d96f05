// Policy classes for robots (mujoco/mujoco_policy.hpp): a phased policy is two policies of its class,
// switched by a raw observation number; its halves, names, switch and policy-file form.
#ifdef PEGASUS_HAVE_MUJOCO
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>

#include "pegasus/core/error.hpp"
#include "pegasus/mujoco/mujoco_policy.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;

TEST(MujocoPhasedPolicy, EachHalfActsOnItsSideOfTheRawObservationsThreshold) {
  // Observation (x, contact); one action. Below: a = 0.5 x; above: a = -0.25 x + 0.1.
  const auto policy =
      make_mujoco_policy("linear", 2, 1, {}, {.observation = "sensors.touch", .position = 1, .above = 3.0});
  const ParameterSpec& spec = policy->parameters();
  ASSERT_EQ(spec.size(), 6u);
  EXPECT_EQ(spec[0].name, "below.W[0][0]");
  EXPECT_EQ(spec[2].name, "below.b[0]");
  EXPECT_EQ(spec[3].name, "above.W[0][0]");
  EXPECT_EQ(spec[5].name, "above.b[0]");
  const Theta theta = {0.5, 0.0, 0.0, -0.25, 0.0, 0.1};
  std::array<double, 1> action{};
  // The switch reads the raw observation, not z: here z says the opposite side of the threshold.
  const std::array<double, 2> low = {1.0, 3.0}, low_z = {1.0, 9.0};
  policy->act(theta, low, low_z, action, {});
  EXPECT_DOUBLE_EQ(action[0], 0.5);  // 3 is not above 3
  const std::array<double, 2> high = {1.0, 3.5}, high_z = {1.0, -9.0};
  policy->act(theta, high, high_z, action, {});
  EXPECT_DOUBLE_EQ(action[0], -0.25 + 0.1);
  EXPECT_EQ(policy->describe(), nlohmann::json::parse(R"({"class": "linear", "hidden": [],
      "phase": {"observation": "sensors.touch", "above": 3.0}})"));
}

TEST(MujocoPhasedPolicy, APhasedMlpActsAsTheUnphasedMlpOfEachHalf) {
  const auto phased = make_mujoco_policy("mlp", 3, 2, {5, 4}, {.observation = "qpos.a", .position = 0});
  const auto plain = make_mujoco_policy("mlp", 3, 2, {5, 4});
  const std::size_t half = plain->parameters().size();
  ASSERT_EQ(phased->parameters().size(), 2 * half);
  EXPECT_EQ(phased->scratch_size(), plain->scratch_size());
  Theta theta(2 * half);
  for (std::size_t i = 0; i < theta.size(); ++i) theta[i] = 0.3 * std::sin(1.7 * static_cast<double>(i));
  std::vector<double> scratch(static_cast<std::size_t>(plain->scratch_size()));
  for (const double first : {-0.5, 0.0, 0.5}) {
    SCOPED_TRACE(first);
    const std::array<double, 3> o = {first, 0.2, -0.7};
    std::array<double, 2> got{}, want{};
    phased->act(theta, o, o, got, scratch);
    const std::span<const double> half_theta =
        std::span<const double>(theta).subspan(first > 0 ? half : 0, half);
    plain->act(half_theta, o, o, want, scratch);
    EXPECT_EQ(got, want);
  }
}

TEST(MujocoPhasedPolicy, AnUnresolvedOrOutOfRangeSwitchIsRefused) {
  EXPECT_THAT([] { make_mujoco_policy("linear", 2, 1, {}, {.observation = "sensors.touch"}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("phase_observation: \"sensors.touch\" is not "
                                                             "resolved in an observation of 2 numbers")));
  EXPECT_THROW(make_mujoco_policy("linear", 2, 1, {}, {.observation = "x", .position = 2}), InputError);
  EXPECT_THROW(make_mujoco_policy("linear", 2, 1, {}, {.observation = "x", .position = 0, .above = NAN}),
               InputError);
}

TEST(MujocoPolicyFile, ThePhaseRoundTripsAndAFileWithoutOneIsUnphased) {
  MujocoPolicyFile f{.model = "m.xml",
                     .task = "t.toml",
                     .model_digest = "model sha",
                     .task_digest = "task sha",
                     .task_content_digest = "content sha",
                     .policy_class = "linear",
                     .hidden = {},
                     .phase = {.observation = "sensors.foot_touch", .above = 0.5},
                     .theta = {1, 2, 3, 4},
                     .normalizer = ObservationNormalizer(1)};
  nlohmann::json j = mujoco_policy_file_json(f);
  EXPECT_EQ(parse_mujoco_policy_file(j, "p.json").phase, f.phase);
  // The digests round-trip, and a file written before them reads without them.
  EXPECT_EQ(parse_mujoco_policy_file(j, "p.json").model_digest, "model sha");
  EXPECT_EQ(parse_mujoco_policy_file(j, "p.json").task_digest, "task sha");
  EXPECT_EQ(parse_mujoco_policy_file(j, "p.json").task_content_digest, "content sha");
  nlohmann::json older = j;
  older.erase("model_digest");
  older.erase("task_digest");
  older.erase("task_content_digest");
  EXPECT_EQ(parse_mujoco_policy_file(older, "p.json").model_digest, "");
  EXPECT_EQ(parse_mujoco_policy_file(older, "p.json").task_content_digest, "");
  j.erase("phase");  // as written before phased policies
  EXPECT_FALSE(parse_mujoco_policy_file(j, "p.json").phase.phased());
  j["phase"] = nullptr;
  EXPECT_FALSE(parse_mujoco_policy_file(j, "p.json").phase.phased());
  j["phase"] = {{"observation", "sensors.foot_touch"}, {"above", "high"}};
  EXPECT_THAT([&] { parse_mujoco_policy_file(j, "p.json"); },
              ::testing::ThrowsMessage<InputError>(
                  HasSubstr("p.json: phase.above: expected a finite number, got \"high\"")));
  j["phase"] = {{"observation", ""}, {"above", 0}};
  EXPECT_THAT([&] { parse_mujoco_policy_file(j, "p.json"); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("p.json: phase.observation")));
}

}  // namespace
}  // namespace pegasus
#endif
