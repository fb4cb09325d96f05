// The hover policy as it flies: the policy file (exact round trip, errors naming the file and the field, the
// class registry, the integral term), the control loop's lines and memory, and flights on the ground truth
// (the pilot's starts, consistent scores, the integral term in a steady wind).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "heli/hover_fixtures.hpp"
#include "pegasus/heli/control_loop.hpp"
#include "pegasus/heli/flights.hpp"
#include "pegasus/heli/hover_task.hpp"
#include "pegasus/heli/pilot.hpp"
#include "pegasus/heli/policy_file.hpp"
#include "support/input_error.hpp"

namespace pegasus::heli {
namespace {

using test_fixtures::small_model;
using test_fixtures::xcell_hover_file;
using test_support::input_error_message;

TEST(PolicyFile, RoundTripsExactlyAndFliesTheSameControls) {
  const HoverPolicy pi;
  Theta theta = pi.parameters().initial();
  theta[1] = 0.1 + 1e-17 * 3;  // bits that only an exact round trip keeps
  theta[0] = 1.0 / 3.0;
  const PolicyFile f = hover_policy_file(pi, theta, {1, 2, -12, 0.3}, {0.01, 0.03, 0.18, 0.19});
  const PolicyFile back = parse_policy_file(nlohmann::json::parse(policy_file_json(f).dump()), "p.json");
  EXPECT_EQ(back.values, f.values);
  EXPECT_EQ(back.names, f.names);
  EXPECT_EQ(back.target, f.target);
  EXPECT_EQ(back.trim, f.trim);
  const auto c = make_controller(back, "p.json");
  HeliObservation o;
  o.state = {1.5, 2, -12, 0, 0, 0.3, 0.1, 0, 0, 0, 0, 0};
  o.target = f.target;
  EXPECT_EQ(c->act(o.state, 0.0), pi.act(theta, o));
  EXPECT_EQ(c->target(7.0), f.target);
}

TEST(PolicyFile, BadFilesNameTheFileAndTheField) {
  const HoverPolicy pi;
  const nlohmann::json good = policy_file_json(hover_policy_file(pi, pi.parameters().initial(), {}, {}));
  auto message = [](const nlohmann::json& j) {
    return input_error_message([&] { make_controller(parse_policy_file(j, "p.json"), "p.json"); });
  };
  EXPECT_EQ(message(good), "(no error)");
  nlohmann::json j = good;
  j["format"] = "other";
  EXPECT_EQ(message(j), "p.json: format: expected \"pegasus-heli-policy\", got \"other\"");
  j = good;
  j.erase("target");
  EXPECT_EQ(message(j), "p.json: target: missing");
  j = good;
  j["parameters"][3]["value"] = "x";
  EXPECT_EQ(message(j), "p.json: parameters[3].value (a1.err_tanh_in): expected a number, got \"x\"");
  j = good;
  j["parameters"][2]["name"] = "a1.typo";
  EXPECT_EQ(message(j),
            "p.json: parameters[2].name: expected \"a1.err_tanh_gain\" (class hover), got \"a1.typo\"");
  j = good;
  j["parameters"].erase(33);
  EXPECT_EQ(message(j), "p.json: parameters: expected 34 parameters for class hover, got 33");
  j = good;
  j["class"] = "loop";
  EXPECT_NE(message(j).find("p.json: class: expected one of "), std::string::npos) << message(j);
  j = good;
  j["trim"]["a3"] = 1.5;
  EXPECT_EQ(message(j), "p.json: trim.a3: expected a control in [-1, 1], got 1.5");
  j = good;
  j["version"] = 2;
  EXPECT_EQ(message(j), "p.json: version: expected 1, got 2");
}

TEST(PolicyFile, RegistryTakesNewClasses) {
  register_policy_class("test-constant",
                        [](const PolicyFile& p, const std::string&) -> std::unique_ptr<HeliController> {
                          struct Constant final : HeliController {
                            Controls a;
                            SetPoint sp;
                            Controls act(const LoggedState&, double, ControllerMemory&) const override {
                              return a;
                            }
                            SetPoint target(double) const override { return sp; }
                          };
                          auto c = std::make_unique<Constant>();
                          c->a = p.trim;
                          c->sp = p.target;
                          return c;
                        });
  PolicyFile f;
  f.class_name = "test-constant";
  f.names = {"w"};
  f.values = {0};
  f.trim = {0.1, 0.2, 0.3, 0.4};
  EXPECT_EQ(make_controller(f, "c.json")->act({}, 0), f.trim);
  const auto names = policy_class_names();
  EXPECT_NE(std::find(names.begin(), names.end(), "hover"), names.end());
}

TEST(ControlLoop, ParsesTwelveThirteenAndSeventeenFields) {
  LoggedState s{};
  bool has_time = false;
  double t = 0;
  std::string why;
  EXPECT_TRUE(parse_state_line("1,2,-10,0,0,0.5,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_FALSE(has_time);
  EXPECT_EQ(s[5], 0.5);
  EXPECT_TRUE(parse_state_line(" 0.5, 1,2,-10,0,0,0.25,0,0,0,0,0,0\r", &s, &has_time, &t, &why));
  EXPECT_TRUE(has_time);
  EXPECT_EQ(t, 0.5);
  EXPECT_EQ(s[5], 0.25);
  EXPECT_TRUE(parse_state_line("0.5,1,2,-10,0,0,0.25,0,0,0,0,0,0,0.1,0.2,0.3,0.4", &s, &has_time, &t, &why));
  EXPECT_FALSE(parse_state_line("1,2,3", &s, &has_time, &t, &why));
  EXPECT_EQ(why, "expected 12, 13 or 17 fields, got 3");
  EXPECT_FALSE(parse_state_line("1,2,-10,0,0,nan,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_EQ(why, "field 6: expected a finite number, got 'nan'");
  EXPECT_FALSE(parse_state_line("1,2,,0,0,0,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_FALSE(parse_state_line("1,2,3x,0,0,0,0,0,0,0,0,0", &s, &has_time, &t, &why));
  EXPECT_FALSE(parse_state_line("", &s, &has_time, &t, &why));
}

TEST(Flights, PolicyAndPilotMeetTheSameStartsAndScoresAreConsistent) {
  AircraftParams p;
  p.conditions.start_pos_sigma = 1.0;
  p.conditions.start_vel_sigma = 0.3;
  const Aircraft aircraft(p);
  const auto model = small_model();
  const HoverPolicy pi = hover_policy_for(*model);
  const PolicyFile f = hover_policy_file(pi, pi.parameters().initial(), {0, 0, -10, 0}, {});
  const auto controller = make_controller(f, "f.json");
  FlightOptions fo;
  fo.flights = 3;
  fo.seconds = 4;
  fo.trace_flights = 2;
  ThreadPool pool(2);
  const auto flown = fly_controller(aircraft, *controller, fo, &pool);
  const auto again = fly_controller(aircraft, *controller, fo, nullptr);
  const auto pilot = fly_pilot_hover(aircraft, PilotOptions{}, {0, 0, -10, 0}, fo, &pool);
  ASSERT_EQ(flown.size(), 3u);
  EXPECT_EQ(flown[0].trace.size(), 200u);
  EXPECT_TRUE(flown[2].trace.empty());
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(flown[i].trace[0].truth, pilot[i].trace[0].truth) << i;  // same perturbed start
    EXPECT_EQ(flown[i].sum_sq_position, again[i].sum_sq_position);     // threads change nothing
  }
  EXPECT_NE(flown[0].trace[0].truth, flown[1].trace[0].truth);
  const FlightSummary s = summarize_flights(flown);
  EXPECT_EQ(s.flights, 3);
  double pos = 0;
  int steps = 0;
  for (const auto& r : flown) {
    pos += r.sum_sq_position;
    steps += r.steps;
  }
  EXPECT_NEAR(s.rms_position_m, std::sqrt(pos / steps), 1e-12);
  EXPECT_GT(s.rms_position_m, 0.0);
}

// The point of the term: in a steady wind the thesis's class holds a steady offset, the integral removes it.
TEST(Flights, IntegralTermRemovesTheSteadyOffsetOfASteadyWind) {
  AircraftParams p;
  p.conditions.mean_wind_W = Vec3(4, 2, 0);  // m/s from the south-west, no gusts, exact estimates
  p.conditions.gust_sigma = 0;
  p.conditions.est_sigma_pos = p.conditions.est_sigma_vel = p.conditions.est_sigma_angle =
      p.conditions.est_sigma_rate = 0;
  const Aircraft aircraft(p);
  FlightOptions fo;
  fo.flights = 1;
  fo.seconds = 60;
  fo.trace_flights = 1;
  // Mean distance to the set point over the last 10 s.
  const auto offset = [&](double integral_seconds) {
    const auto controller = make_controller(xcell_hover_file(aircraft, integral_seconds), "f.json");
    const auto flights = fly_controller(aircraft, *controller, fo, nullptr);
    EXPECT_FALSE(flights[0].crashed);
    double sum = 0;
    int n = 0;
    for (const FlightRow& row : flights[0].trace) {
      if (row.time < 50) continue;
      sum += std::hypot(row.truth[logged::x], row.truth[logged::y], row.truth[logged::z] + 10);
      ++n;
    }
    return sum / n;
  };
  const double without = offset(0), with = offset(5);
  std::printf("steady offset in a 4.5 m/s wind: %.4f m without the integral term, %.4f m with it\n", without,
              with);
  EXPECT_GT(without, 1.0);
  EXPECT_LT(with, 0.05);
}

TEST(PolicyFile, IntegralTermRoundTripsAndBadIntegratorsNameTheField) {
  const Aircraft aircraft;
  const PolicyFile f = xcell_hover_file(aircraft, 5);
  EXPECT_EQ(f.values.size(), 38u);
  const PolicyFile back = parse_policy_file(nlohmann::json::parse(policy_file_json(f).dump()), "p.json");
  EXPECT_EQ(hover_file_integrator(back, "p.json"), (ErrorIntegrator{.dt = 0.02}));
  EXPECT_EQ(back.values, f.values);
  auto message = [](const nlohmann::json& j) {
    return input_error_message([&] { make_controller(parse_policy_file(j, "p.json"), "p.json"); });
  };
  const nlohmann::json good = policy_file_json(f);
  EXPECT_EQ(message(good), "(no error)");
  nlohmann::json j = good;
  j["options"]["integral"].erase("dt");
  EXPECT_EQ(message(j), "p.json: options.integral.dt: missing");
  j = good;
  j["options"]["integral"]["limit_yaw"] = 0;
  EXPECT_EQ(message(j), "p.json: options.integral.limit_yaw: expected a number > 0, rad s, got 0");
  j = good;
  j["options"]["integral"] = 5;
  EXPECT_EQ(message(j),
            "p.json: options.integral: expected {\"dt\", \"limit_position\", \"limit_yaw\"}, got 5");
  j = good;
  j["options"].erase("integral");  // 38 weights without the integrator
  EXPECT_EQ(message(j), "p.json: parameters: expected 34 parameters for class hover, got 38");
  j = policy_file_json(xcell_hover_file(aircraft, 0));
  j["options"]["integral"] = good["options"]["integral"];  // an integrator without the weights
  EXPECT_EQ(message(j), "p.json: parameters: expected 38 parameters for class hover, got 34");
}

TEST(PolicyFile, CommandLimitsRoundTripBindTheControllerAndBadOnesNameTheField) {
  const Aircraft aircraft;
  PolicyFile f = xcell_hover_file(aircraft, 0);
  const HoverPolicy unlimited;
  const Theta theta = f.values;
  HoverPolicyInit init;
  init.command_lower = {-0.2, -1, -1, -0.1};
  init.command_upper = {0.2, 0.05, 1, 0.1};
  f = hover_policy_file(HoverPolicy(init), theta, f.target, f.trim);
  const nlohmann::json good = policy_file_json(f);
  const PolicyFile back = parse_policy_file(nlohmann::json::parse(good.dump()), "p.json");
  const HoverPolicyInit read = hover_file_command_limits(back, "p.json");
  EXPECT_EQ(read.command_lower, init.command_lower);
  EXPECT_EQ(read.command_upper, init.command_upper);
  // The controller clips where the unlimited policy would not, and nowhere else.
  const auto limited = make_controller(back, "p.json");
  const LoggedState far{8, -6, -4, 0.3, -0.2, 0.5, 2, -1, 1, 0.5, 0.3, -0.4};
  const Controls free = unlimited.act(theta, HeliObservation{far, f.target, {}});
  const Controls a = limited->act(far, 0);
  for (std::size_t c = 0; c < 4; ++c)
    EXPECT_EQ(a[c], std::clamp(free[c], init.command_lower[c], init.command_upper[c])) << c;
  EXPECT_NE(a, free);  // the state is far enough that some channel's limit binds
  // Without limits the file has no command_limits, and reads back as [-1, 1].
  EXPECT_FALSE(xcell_hover_file(aircraft, 0).options.contains("command_limits"));
  auto message = [](const nlohmann::json& j) {
    return input_error_message([&] { make_controller(parse_policy_file(j, "p.json"), "p.json"); });
  };
  EXPECT_EQ(message(good), "(no error)");
  nlohmann::json j = good;
  j["options"]["command_limits"]["lower"][1] = 0.1;  // above a2's upper 0.05
  EXPECT_EQ(message(j),
            "p.json: options.command_limits: a2: expected -1 <= lower <= upper <= 1, got [0.1, 0.05]");
  j = good;
  j["options"]["command_limits"]["upper"][2] = 1.5;
  EXPECT_EQ(message(j),
            "p.json: options.command_limits: a3: expected -1 <= lower <= upper <= 1, got [-1, 1.5]");
  j = good;
  j["options"]["command_limits"]["upper"] = {1, 1};
  EXPECT_EQ(message(j).rfind("p.json: options.command_limits.upper: expected", 0), 0u) << message(j);
  j = good;
  j["options"]["command_limits"].erase("lower");
  EXPECT_EQ(message(j), "p.json: options.command_limits.lower: missing");
  j = good;
  j["options"]["command_limits"] = "tight";
  EXPECT_EQ(message(j), "p.json: options.command_limits: expected {\"lower\", \"upper\"}, got \"tight\"");
}

// `heli control` serves one flight: the memory runs over its lines, and a malformed line leaves it alone.
TEST(ControlLoop, ControllerMemoryRunsOverTheLinesAndSkipsMalformedOnes) {
  const Aircraft aircraft;
  const auto controller = make_controller(xcell_hover_file(aircraft, 5), "f.json");
  const std::vector<LoggedState> states = {{1, 0, -10, 0, 0, 0, 0, 0, 0, 0, 0, 0},
                                           {1.5, -0.5, -9, 0, 0, 0.1, 0, 0, 0, 0, 0, 0},
                                           {2, -1, -9.5, 0.05, 0, 0.2, 0, 0, 0, 0, 0, 0}};
  std::string input;
  for (std::size_t i = 0; i < states.size(); ++i) {
    for (std::size_t k = 0; k < 12; ++k) input += fmt::format("{}{}", k ? "," : "", states[i][k]);
    input += "\n";
    if (i == 0) input += "1,2,x\n";
  }
  std::FILE* in = fmemopen(input.data(), input.size(), "r");
  char* out_text = nullptr;
  std::size_t out_size = 0;
  std::FILE* out = open_memstream(&out_text, &out_size);
  std::FILE* err = std::tmpfile();
  run_control_loop(*controller, {0, 0, 0, 0}, in, out, err);
  std::fclose(in);
  std::fclose(out);
  std::fclose(err);
  const std::string answers(out_text, out_size);
  std::free(out_text);
  ControllerMemory memory;
  std::string expected;
  for (std::size_t i = 0; i < states.size(); ++i) {
    const Controls a = controller->act(states[i], 0.02 * static_cast<double>(i), memory);
    expected += fmt::format("{},{},{},{}\n", a[0], a[1], a[2], a[3]);
    if (i == 0) expected += "0,0,0,0\n";
  }
  EXPECT_EQ(answers, expected);
  EXPECT_NE(memory.integral[0], 0.0);
  EXPECT_NE(controller->act(states[2], 0.04), controller->act(states[2], 0.04, memory));
}

}  // namespace
}  // namespace pegasus::heli
