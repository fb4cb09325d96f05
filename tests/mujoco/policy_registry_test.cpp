// The MuJoCo policy-class registry (mujoco/mujoco_policy.hpp): a class registered here, in the test, is
// found by make_mujoco_policy, by policy.json's reader and writer, and by the `policy` option's choices and
// help, with no other edit; unknown names are refused with the registered names listed.
#ifdef PEGASUS_HAVE_MUJOCO
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

#include "pegasus/core/error.hpp"
#include "pegasus/core/or_list.hpp"
#include "pegasus/mujoco/mujoco_policy.hpp"
#include "pegasus/mujoco/runs/mujoco_config.hpp"

namespace pegasus {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// a = s / (1 + |s|), s = W z + b: a class the project does not ship (linear's parameters, a softsign).
class SoftsignLinearPolicy final : public MujocoPolicy {
 public:
  SoftsignLinearPolicy(int d, int nu) : d_(d), nu_(nu) {
    for (int k = 0; k < nu; ++k) {
      for (int f = 0; f < d; ++f) spec_.add({.name = "W" + std::to_string(k) + std::to_string(f)});
      spec_.add({.name = "b" + std::to_string(k)});
    }
  }
  const ParameterSpec& parameters() const override { return spec_; }
  void act(std::span<const double> theta, std::span<const double>, std::span<const double> z,
           std::span<double> action, std::span<double>) const override {
    for (int k = 0; k < nu_; ++k) {
      const double* w = theta.data() + static_cast<std::size_t>(k * (d_ + 1));
      double s = w[d_];
      for (int f = 0; f < d_; ++f) s += w[f] * z[static_cast<std::size_t>(f)];
      action[static_cast<std::size_t>(k)] = s / (1.0 + std::abs(s));
    }
  }
  nlohmann::json describe() const override {
    return {{"class", "softsign-linear"}, {"hidden", nlohmann::json::array()}};
  }

 private:
  int d_, nu_;
  ParameterSpec spec_;
};

void register_softsign() {
  register_mujoco_policy_class({.name = "softsign-linear",
                                .doc = "a = s / (1 + |s|), s = W z + b",
                                .hidden_layers = false,
                                .make = [](int d, int nu, const std::vector<int>&) {
                                  return std::make_unique<SoftsignLinearPolicy>(d, nu);
                                }});
}

TEST(MujocoPolicyRegistry, TheBuiltInsComeFirstAndAnUnknownClassIsRefusedWithTheRegisteredNames) {
  const std::vector<std::string> names = mujoco_policy_class_names();
  ASSERT_GE(names.size(), 2u);
  EXPECT_EQ(names[0], "linear");  // the option's default
  EXPECT_NE(std::find(names.begin(), names.end(), "mlp"), names.end());
  // With the built-ins linear and mlp alone this is `policy: expected linear or mlp, got "tanh"`.
  EXPECT_THAT([] { make_mujoco_policy("tanh", 2, 1, {}); },
              ThrowsMessage<InputError>(fmt::format("policy: expected {}, got \"tanh\"", or_list(names))));
  EXPECT_EQ(or_list({"linear", "mlp"}), "linear or mlp");
  EXPECT_THAT([] { make_mujoco_policy("mlp", 2, 1, {}); },
              ThrowsMessage<InputError>("hidden: expected at least one hidden layer for policy = mlp"));
}

TEST(MujocoPolicyRegistry, ARegisteredClassIsMadeWrittenReadAndOfferedByTheOption) {
  register_softsign();
  register_softsign();  // again: replaced in its place, not listed twice
  const std::vector<std::string> names = mujoco_policy_class_names();
  EXPECT_EQ(std::count(names.begin(), names.end(), "softsign-linear"), 1);
  EXPECT_EQ(names.back(), "softsign-linear");

  // make: hidden widths are ignored by a class without hidden layers; phased works as for any class.
  const auto policy = make_mujoco_policy("softsign-linear", 2, 1, {64, 64});
  ASSERT_EQ(policy->parameters().size(), 3u);
  const Theta theta = {2.0, -1.0, 0.5};
  const std::array<double, 2> z = {1.5, 0.5};
  std::array<double, 1> action{};
  policy->act(theta, z, z, action, {});
  EXPECT_DOUBLE_EQ(action[0], 3.0 / 4.0);  // s = 3 - 0.5 + 0.5 = 3
  const auto phased =
      make_mujoco_policy("softsign-linear", 2, 1, {}, {.observation = "sensors.t", .position = 1});
  EXPECT_EQ(phased->parameters().size(), 6u);
  EXPECT_EQ(phased->describe().at("class"), "softsign-linear");

  // policy.json: written with the class's describe(), read back; a hidden layer is refused by the class.
  MujocoPolicyFile f;
  f.model = "m.xml";
  f.task = "t.toml";
  f.policy_class = policy->describe().at("class");
  f.theta = theta;
  f.normalizer = ObservationNormalizer(2);
  nlohmann::json j = mujoco_policy_file_json(f);
  EXPECT_EQ(parse_mujoco_policy_file(j, "p.json").policy_class, "softsign-linear");
  EXPECT_EQ(parse_mujoco_policy_file(j, "p.json").theta, theta);
  j["hidden"] = {4};
  EXPECT_THAT([&] { parse_mujoco_policy_file(j, "p.json"); },
              ThrowsMessage<InputError>(HasSubstr(
                  "p.json: hidden: expected [] (a softsign-linear policy has no hidden layer), got [4]")));
  j["hidden"] = nlohmann::json::array();
  j["class"] = "nope";
  std::vector<std::string> quoted;
  for (const std::string& name : names) quoted.push_back("\"" + name + "\"");
  ASSERT_EQ(names.back(), "softsign-linear");
  EXPECT_THAT([&] { parse_mujoco_policy_file(j, "p.json"); },
              ThrowsMessage<InputError>(
                  HasSubstr(fmt::format("p.json: class: expected {}, got \"nope\"", or_list(quoted)))));
  EXPECT_THAT([&] { make_mujoco_policy("nope", 2, 1, {}); },
              ThrowsMessage<InputError>(fmt::format("policy: expected {}, got \"nope\"", or_list(names))));
  // The option: its choices and help are read from the registry when the command is declared.
  ConfigSchema s;
  declare_mujoco_train_config(s);
  EXPECT_EQ(s.field("policy").allowed_choices(), names);
  EXPECT_THAT(s.field("policy").help(), HasSubstr("softsign-linear: a = s / (1 + |s|), s = W z + b"));
  s.set_from_cli("policy", "softsign-linear");
  EXPECT_EQ(read_mujoco_train_config(s, 1).policy_class, "softsign-linear");
  EXPECT_THROW(s.set_from_cli("policy", "nope"), InputError);
}

}  // namespace
}  // namespace pegasus
#endif
