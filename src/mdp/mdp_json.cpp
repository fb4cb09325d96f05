#include "pegasus/mdp/mdp_json.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "pegasus/core/error.hpp"
#include "pegasus/io/json_input.hpp"

namespace pegasus {

namespace {

using nlohmann::json;

[[noreturn]] void fail(const std::string& src, const std::string& field, const std::string& msg) {
  throw InputError(fmt::format("{}: {}: {}", src, field, msg));
}

const json& required(const json& j, const char* key, const std::string& src) {
  if (!j.contains(key)) fail(src, key, "missing required field");
  return j.at(key);
}

int as_int(const json& j, const std::string& src, const std::string& field) {
  if (!j.is_number_integer()) fail(src, field, fmt::format("expected an integer, got {}", j.dump()));
  const auto v = j.get<long long>();
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    fail(src, field, fmt::format("integer {} out of range", v));
  return static_cast<int>(v);
}

double as_number(const json& j, const std::string& src, const std::string& field) {
  if (!j.is_number()) fail(src, field, fmt::format("expected a number, got {}", j.dump()));
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(src, field, "expected a finite number");
  return v;
}

int as_index(const json& j, int limit, const std::string& src, const std::string& field, const char* what) {
  const int v = as_int(j, src, field);
  if (v < 0 || v >= limit) fail(src, field, fmt::format("{} {} outside [0, {})", what, v, limit));
  return v;
}

}  // namespace

FiniteMdp mdp_from_json(const json& j, const std::string& src) {
  if (!j.is_object()) fail(src, "(top level)", "expected a JSON object");
  const auto& fmt_field = required(j, "format", src);
  if (!fmt_field.is_string() || fmt_field.get<std::string>() != "pegasus-mdp")
    fail(src, "format", "expected \"pegasus-mdp\"");
  if (as_int(required(j, "version", src), src, "version") != 1) fail(src, "version", "expected 1");
  const int S = as_int(required(j, "num_states", src), src, "num_states");
  if (S < 1) fail(src, "num_states", "expected at least 1");
  const int A = as_int(required(j, "num_actions", src), src, "num_actions");
  if (A < 1) fail(src, "num_actions", "expected at least 1");
  const double gamma = as_number(required(j, "gamma", src), src, "gamma");
  if (!(gamma >= 0.0 && gamma <= 1.0)) fail(src, "gamma", fmt::format("{} outside [0, 1]", gamma));

  // Every state is listed as absorbing or has one transitions entry per action, so the sizes the file
  // declares are bounded by what it holds: checked before anything of size S*A is allocated (issue 16:
  // num_states 2147483647 gave std::bad_alloc).
  {
    const auto entries =
        j.contains("transitions") && j.at("transitions").is_array() ? j.at("transitions").size() : 0;
    const auto listed =
        j.contains("absorbing") && j.at("absorbing").is_array() ? j.at("absorbing").size() : 0;
    if (static_cast<std::size_t>(S) > entries + listed)
      fail(src, "num_states",
           fmt::format("expected at most {} (the states its transitions and absorbing list describe), got {}",
                       entries + listed, S));
    if (static_cast<std::size_t>(A) > std::max<std::size_t>(entries, 1))
      fail(src, "num_actions",
           fmt::format("expected at most {} (one transitions entry per state and action), got {}",
                       std::max<std::size_t>(entries, 1), A));
  }
  FiniteMdpBuilder b(S, A, gamma);
  std::vector<std::uint8_t> absorbing(static_cast<std::size_t>(S), 0);
  if (j.contains("absorbing")) {
    const auto& abs = j.at("absorbing");
    if (!abs.is_array()) fail(src, "absorbing", "expected an array of state indices");
    for (std::size_t i = 0; i < abs.size(); ++i) {
      const int s = as_index(abs[i], S, src, fmt::format("absorbing[{}]", i), "state");
      absorbing[static_cast<std::size_t>(s)] = 1;
      b.set_absorbing(s);
    }
  }
  if (j.contains("initial")) {
    const auto& init = j.at("initial");
    if (!init.is_array() || init.empty())
      fail(src, "initial", "expected a non-empty array of [state, probability]");
    for (std::size_t i = 0; i < init.size(); ++i) {
      const std::string f = fmt::format("initial[{}]", i);
      if (!init[i].is_array() || init[i].size() != 2) fail(src, f, "expected [state, probability]");
      const int s = as_index(init[i][0], S, src, f + "[0]", "state");
      const double p = as_number(init[i][1], src, f + "[1]");
      if (!(p >= 0.0 && p <= 1.0)) fail(src, f + "[1]", fmt::format("probability {} outside [0, 1]", p));
      b.set_initial(s, p);
    }
  }
  if (j.contains("state_rewards")) {
    const auto& sr = j.at("state_rewards");
    if (!sr.is_array() || sr.size() != static_cast<std::size_t>(S))
      fail(src, "state_rewards", fmt::format("expected an array of {} numbers", S));
    for (int s = 0; s < S; ++s) {
      const double r = as_number(sr[static_cast<std::size_t>(s)], src, fmt::format("state_rewards[{}]", s));
      if (!absorbing[static_cast<std::size_t>(s)])
        b.set_state_reward(s, r);
      else if (r != 0.0)
        fail(src, fmt::format("state_rewards[{}]", s), "absorbing states must have reward 0");
    }
  }
  const auto& tr = required(j, "transitions", src);
  if (!tr.is_array()) fail(src, "transitions", "expected an array");
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(S) * A, 0);
  for (std::size_t i = 0; i < tr.size(); ++i) {
    const std::string f = fmt::format("transitions[{}]", i);
    const auto& t = tr[i];
    if (!t.is_object()) fail(src, f, "expected an object with state, action, next");
    if (!t.contains("state")) fail(src, f + ".state", "missing required field");
    if (!t.contains("action")) fail(src, f + ".action", "missing required field");
    if (!t.contains("next")) fail(src, f + ".next", "missing required field");
    const int s = as_index(t.at("state"), S, src, f + ".state", "state");
    const int a = as_index(t.at("action"), A, src, f + ".action", "action");
    if (absorbing[static_cast<std::size_t>(s)])
      fail(src, f + ".state", fmt::format("state {} is absorbing and takes no transitions", s));
    auto& flag = seen[static_cast<std::size_t>(s) * A + a];
    if (flag) fail(src, f, fmt::format("state {} action {} given twice", s, a));
    flag = 1;
    if (t.contains("reward")) b.set_state_action_reward(s, a, as_number(t.at("reward"), src, f + ".reward"));
    const auto& next = t.at("next");
    if (!next.is_array() || next.empty())
      fail(src, f + ".next", "expected a non-empty array of [successor, probability(, reward)]");
    double sum = 0.0;
    for (std::size_t k = 0; k < next.size(); ++k) {
      const std::string fk = fmt::format("{}.next[{}]", f, k);
      const auto& e = next[k];
      if (!e.is_array() || (e.size() != 2 && e.size() != 3))
        fail(src, fk, "expected [successor, probability] or [successor, probability, reward]");
      const int n = as_index(e[0], S, src, fk + "[0]", "successor");
      const double p = as_number(e[1], src, fk + "[1]");
      if (!(p >= 0.0 && p <= 1.0)) fail(src, fk + "[1]", fmt::format("probability {} outside [0, 1]", p));
      const double r = e.size() == 3 ? as_number(e[2], src, fk + "[2]") : 0.0;
      sum += p;
      b.add_transition(s, a, n, p, r);
    }
    if (std::abs(sum - 1.0) > 1e-9)
      fail(src, f + ".next", fmt::format("probabilities sum to {:.12g}, expected 1 within 1e-9", sum));
  }
  for (int s = 0; s < S; ++s) {
    if (absorbing[static_cast<std::size_t>(s)]) continue;
    for (int a = 0; a < A; ++a)
      if (!seen[static_cast<std::size_t>(s) * A + a])
        fail(src, "transitions", fmt::format("no entry for state {} action {}", s, a));
  }
  try {
    return b.build();
  } catch (const InputError& e) {
    std::string msg = e.what();
    if (msg.rfind("mdp: ", 0) == 0) msg = msg.substr(5);
    throw InputError(fmt::format("{}: {}", src, msg));
  }
}

json mdp_to_json(const FiniteMdp& m) {
  json j;
  j["format"] = "pegasus-mdp";
  j["version"] = 1;
  j["num_states"] = m.num_states;
  j["num_actions"] = m.num_actions;
  j["gamma"] = m.gamma;
  json abs = json::array();
  for (int s = 0; s < m.num_states; ++s)
    if (m.is_absorbing(s)) abs.push_back(s);
  j["absorbing"] = abs;
  json init = json::array();
  for (int s = 0; s < m.num_states; ++s)
    if (m.initial[static_cast<std::size_t>(s)] > 0.0)
      init.push_back(json::array({s, m.initial[static_cast<std::size_t>(s)]}));
  j["initial"] = init;
  json tr = json::array();
  for (int s = 0; s < m.num_states; ++s) {
    if (m.is_absorbing(s)) continue;
    for (int a = 0; a < m.num_actions; ++a) {
      const std::size_t r = m.row(s, a);
      const std::uint32_t b = m.row_start[r], e = m.row_start[r + 1];
      bool shared = true;
      for (std::uint32_t k = b; k < e; ++k) shared = shared && m.reward[k] == m.reward[b];
      json t;
      t["state"] = s;
      t["action"] = a;
      if (shared && e > b) t["reward"] = m.reward[b];
      json next = json::array();
      for (std::uint32_t k = b; k < e; ++k) {
        if (shared)
          next.push_back(json::array({m.next_state[k], m.probability[k]}));
        else
          next.push_back(json::array({m.next_state[k], m.probability[k], m.reward[k]}));
      }
      t["next"] = next;
      tr.push_back(std::move(t));
    }
  }
  j["transitions"] = tr;
  return j;
}

FiniteMdp load_mdp(const std::string& path) { return mdp_from_json(read_json_input(path, "MDP"), path); }

void save_mdp(const FiniteMdp& mdp, const std::string& path) {
  // Written to a temporary name and renamed, so a reader never sees half a file.
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw InputError(fmt::format("{}: cannot write MDP file", path));
    out << mdp_to_json(mdp).dump(1) << '\n';
    if (!out) throw InputError(fmt::format("{}: write failed", path));
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace pegasus
